// Small SVG helpers for the flight views and the frontier (drawn as SVG so that the
// export's SVG button saves exactly what is shown). Geometry only: no number
// shown here is computed, every value comes from an API answer.

const SVG = 'http://www.w3.org/2000/svg';

/** An SVG element with attributes (`text`: its text; `title`: a hover tooltip). */
export function svgEl(tag, attrs = {}, ...children) {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attrs)) {
    if (value === undefined || value === null || value === false) continue;
    if (key === 'text') node.textContent = value;
    else if (key === 'dataset') Object.assign(node.dataset, value);
    else if (key === 'title') node.append(svgEl('title', { text: value }));
    else node.setAttribute(key, String(value));
  }
  for (const child of children.flat()) if (child) node.append(child);
  return node;
}

/** "Nice" tick values covering [lo, hi] (about `count` of them). */
export function ticks(lo, hi, count = 5) {
  if (!(hi > lo)) return [lo];
  const raw = (hi - lo) / count;
  const power = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * power).find((s) => s >= raw) || raw;
  const out = [];
  for (let v = Math.ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) {
    out.push(Math.abs(v) < step * 1e-9 ? 0 : Number(v.toPrecision(12)));
  }
  return out;
}

/** A tick's label: no trailing noise ("0.25", "30"). */
export function tickLabel(v) {
  return String(Number(v.toPrecision(6)));
}

/** A linear map from [d0, d1] onto [r0, r1]. */
export function scale(d0, d1, r0, r1) {
  const k = d1 === d0 ? 0 : (r1 - r0) / (d1 - d0);
  return (v) => r0 + (v - d0) * k;
}

/**
 * Axes of a plot: the frame, ticks and labels. `box` {left, top, width, height},
 * `x`, `y` the maps, `xr`, `yr` the domains, labels under and beside.
 */
export function axes(box, x, y, xr, yr, xLabel, yLabel) {
  const g = svgEl('g', { class: 'axis' });
  const bottom = box.top + box.height;
  g.append(svgEl('rect', { x: box.left, y: box.top, width: box.width, height: box.height, class: 'frame' }));
  for (const v of ticks(xr[0], xr[1], Math.max(2, Math.round(box.width / 80)))) {
    const px = x(v);
    g.append(svgEl('line', { x1: px, x2: px, y1: bottom, y2: bottom + 4 }));
    g.append(svgEl('text', { x: px, y: bottom + 16, 'text-anchor': 'middle', text: tickLabel(v) }));
  }
  for (const v of ticks(yr[0], yr[1], Math.max(2, Math.round(box.height / 50)))) {
    const py = y(v);
    g.append(svgEl('line', { x1: box.left - 4, x2: box.left, y1: py, y2: py }));
    g.append(svgEl('text', { x: box.left - 7, y: py + 4, 'text-anchor': 'end', text: tickLabel(v) }));
  }
  const middle = box.left + box.width / 2;
  g.append(svgEl('text', { x: middle, y: bottom + 34, 'text-anchor': 'middle', class: 'label', text: xLabel }));
  g.append(
    svgEl('text', {
      x: 14,
      y: box.top + box.height / 2,
      'text-anchor': 'middle',
      class: 'label',
      transform: `rotate(-90 14 ${box.top + box.height / 2})`,
      text: yLabel,
    }),
  );
  return g;
}

/** The drawing width for `svg`: its box's width in CSS pixels (so text keeps its size), 320 to 640. */
export function widthFor(svg) {
  const box = svg.parentElement?.getBoundingClientRect().width || 640;
  return Math.round(Math.max(320, Math.min(640, box)));
}

/** Calls `redraw` when `svg`'s drawing width changes (a phone turned, a window resized). */
export function redrawOnResize(svg, redraw) {
  let last = 0;
  new ResizeObserver(() => {
    const width = widthFor(svg);
    if (last && width !== last) redraw();
    last = width;
  }).observe(svg.parentElement);
}
