// Exports of what a chart shows: CSV of its numbers (the API's, unrounded)
// and SVG of a drawing (its styles inlined, so the file stands alone).

/** A CSV field: quoted when it holds a comma, a quote or a line break. */
function csvField(value) {
  if (value === null || value === undefined) return '';
  const text = String(value);
  return /[",\n\r]/.test(text) ? `"${text.replaceAll('"', '""')}"` : text;
}

/** `table` ([header, ...rows]) as CSV text (RFC 4180, CRLF line ends). */
export function toCsv(table) {
  return `${table.map((row) => row.map(csvField).join(',')).join('\r\n')}\r\n`;
}

/** Offers `text` as a file called `name` (a link with `download`, clicked). */
function offer(name, type, text) {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const link = document.createElement('a');
  link.href = url;
  link.download = name;
  link.hidden = true;
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

/** Downloads `table` as `name` (CSV). */
export function downloadCsv(name, table) {
  offer(name, 'text/csv;charset=utf-8', toCsv(table));
}

const STYLED = ['fill', 'stroke', 'stroke-width', 'stroke-dasharray', 'opacity', 'font-size', 'font-family'];

/** `svg` as a standalone SVG document (computed styles inlined). */
export function toSvg(svg) {
  const clone = svg.cloneNode(true);
  const from = [svg, ...svg.querySelectorAll('*')];
  const to = [clone, ...clone.querySelectorAll('*')];
  from.forEach((node, i) => {
    const style = getComputedStyle(node);
    to[i].setAttribute('style', STYLED.map((p) => `${p}:${style.getPropertyValue(p)}`).join(';'));
  });
  for (const mark of clone.querySelectorAll('.cursor')) mark.remove(); // the keyboard's cursor is no part of the figure
  clone.setAttribute('xmlns', 'http://www.w3.org/2000/svg');
  const box = svg.viewBox.baseVal;
  if (box) {
    clone.setAttribute('width', String(Math.round(box.width * 1.5)));
    clone.setAttribute('height', String(Math.round(box.height * 1.5)));
  }
  return `<?xml version="1.0" encoding="UTF-8"?>\n${new XMLSerializer().serializeToString(clone)}\n`;
}

/** Downloads the drawing `svg` as `name`. */
export function downloadSvg(name, svg) {
  offer(name, 'image/svg+xml', toSvg(svg));
}
