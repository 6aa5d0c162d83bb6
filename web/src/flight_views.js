// The batted ball from above over a generic field, and the carry map as a heat map
// (issue 37, item 3; docs/explorer.md). Every number shown is the API's: the top view
// draws /v1/flight's trajectory and landing (with the spray angle typed here), the heat
// map /v1/sweet-spot's carry_map and distance_sweet_spot, both with report_units set to
// the page's switch. The field outline is a drawing, not data: a generic park.
import * as api from './api.js';
import { downloadCsv, downloadSvg } from './export.js';
import { clearErrors, el, fmt, readValue, showError } from './form.js';
import { axes, redrawOnResize, scale, svgEl, tickLabel, ticks, widthFor } from './svg.js';

const $ = (selector) => document.querySelector(selector);

/** Metres per foot (exact): only to draw the generic field in metres, never a number shown from the API. */
const M_PER_FT = 0.3048;

/**
 * A generic field in feet (x toward right field, y toward centre field, home plate at 0):
 * fence distances at angles from centre field (deg, + toward right field), 330 ft down the
 * lines, 375 ft in the alleys, 400 ft to centre; 90-ft bases, the mound at 60.5 ft, the
 * infield's edge 95 ft from the mound.
 */
const FENCE_FT = [
  [-45, 330],
  [-22.5, 375],
  [0, 400],
  [22.5, 375],
  [45, 330],
];
const BASE_FT = 90;
const MOUND_FT = 60.5;
const INFIELD_ARC_FT = 95;

function fenceAt(deg) {
  for (let i = 1; i < FENCE_FT.length; ++i) {
    const [a0, r0] = FENCE_FT[i - 1];
    const [a1, r1] = FENCE_FT[i];
    if (deg <= a1) {
      const t = (deg - a0) / (a1 - a0);
      const s = (1 - Math.cos(Math.PI * t)) / 2; // smooth between the marked distances
      return r0 + (r1 - r0) * s;
    }
  }
  return FENCE_FT[FENCE_FT.length - 1][1];
}

/** The field's lines in `unit` ("ft" or "m"): {fence, lines, diamond, arc, mound, labels}. */
function fieldShape(unit) {
  const k = unit === 'ft' ? 1 : M_PER_FT;
  const polar = (deg, r) => [r * k * Math.sin((deg * Math.PI) / 180), r * k * Math.cos((deg * Math.PI) / 180)];
  const fence = [];
  for (let deg = -45; deg <= 45; deg += 1.5) fence.push(polar(deg, fenceAt(deg)));
  const half = (BASE_FT * Math.SQRT1_2 * k);
  const diamond = [
    [0, 0],
    [half, half],
    [0, 2 * half],
    [-half, half],
  ];
  const arc = [];
  for (let a = -90; a <= 90; a += 3) {
    const x = INFIELD_ARC_FT * k * Math.sin((a * Math.PI) / 180);
    const y = MOUND_FT * k + INFIELD_ARC_FT * k * Math.cos((a * Math.PI) / 180);
    if (Math.abs(x) <= y) arc.push([x, y]);
  }
  const label = (ft) => (unit === 'ft' ? `${ft} ft` : `${fmt(ft * M_PER_FT, 4)} m`);
  return {
    fence,
    lines: [polar(-45, FENCE_FT[0][1]), polar(45, FENCE_FT[4][1])],
    diamond,
    arc,
    mound: [0, MOUND_FT * k],
    moundRadius: 9 * k,
    labels: FENCE_FT.filter(([deg]) => deg !== -22.5 && deg !== 22.5).map(([deg, r]) => ({
      at: polar(deg, r + 14),
      text: label(r),
    })),
  };
}

/** True while the page's bat is refused: the views then show the last valid bat's answers, dimmed. */
const refusedBat = () => document.body.dataset.state === 'error';

/** Viridis, five stops: the heat map's colour of t in [0, 1]. */
const VIRIDIS = ['#440154', '#3b528b', '#21918c', '#5ec962', '#fde725'];
function colour(t) {
  const x = Math.min(1, Math.max(0, t)) * (VIRIDIS.length - 1);
  const i = Math.min(VIRIDIS.length - 2, Math.floor(x));
  const f = x - i;
  const rgb = (hex) => [1, 3, 5].map((j) => parseInt(hex.slice(j, j + 2), 16));
  const a = rgb(VIRIDIS[i]);
  const b = rgb(VIRIDIS[i + 1]);
  return `rgb(${a.map((v, j) => Math.round(v + (b[j] - v) * f)).join(',')})`;
}

/** The flight views of the page: from above, and the carry map. */
export class FlightViews {
  /** `ctx`: {units() 'imperial'|'si', saveState(), stem() the files' name stem}. */
  constructor(ctx) {
    this.ctx = ctx;
    this.good = null;
    this.topSeq = 0;
    this.carrySeq = 0;
    this.top = null; // {answer, unit, x, y}
    this.carry = null; // the carry_map table shown
    let topTimer = 0;
    let carryTimer = 0;
    const topForm = $('#flight-top-form');
    topForm.addEventListener('submit', (e) => e.preventDefault());
    topForm.addEventListener('input', () => {
      clearTimeout(topTimer);
      topTimer = setTimeout(() => this.refreshTop(), 300);
    });
    topForm.addEventListener('change', () => {
      clearTimeout(topTimer);
      this.ctx.saveState();
      this.refreshTop();
    });
    const carryForm = $('#carry-form');
    carryForm.addEventListener('submit', (e) => e.preventDefault());
    carryForm.addEventListener('input', () => {
      clearTimeout(carryTimer);
      carryTimer = setTimeout(() => this.refreshCarry(), 400);
    });
    carryForm.addEventListener('change', () => {
      clearTimeout(carryTimer);
      this.ctx.saveState();
      this.refreshCarry();
    });
    // The heat map by keyboard: the arrows move a cursor cell by cell (left/right along the
    // bat, up/down in undercut), Home back to the distance sweet spot's cell; the cell's
    // numbers are read out in #carry-cell.
    $('#carry-map').addEventListener('keydown', (e) => {
      if (!this.carry) return;
      const moves = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowDown: [0, -1], ArrowUp: [0, 1] };
      if (e.key === 'Home') {
        this.moveCursor(this.carry.home.i, this.carry.home.j);
      } else if (moves[e.key]) {
        this.moveCursor(this.carry.cursor.i + moves[e.key][0], this.carry.cursor.j + moves[e.key][1]);
      } else {
        return;
      }
      e.preventDefault();
    });
    const stem = () => this.ctx.stem();
    const actions = {
      'flight-top-svg': () => downloadSvg(`${stem()}-flight-above-${this.ctx.units()}.svg`, $('#flight-top')),
      'flight-top-csv': () => downloadCsv(`${stem()}-flight-above-${this.ctx.units()}.csv`, this.topTable()),
      'carry-map-svg': () => downloadSvg(`${stem()}-carry-map-${this.ctx.units()}.svg`, $('#carry-map')),
      'carry-map-csv': () => downloadCsv(`${stem()}-carry-map-${this.ctx.units()}.csv`, this.carryTable()),
    };
    for (const [key, action] of Object.entries(actions)) {
      $(`[data-export="${key}"]`).addEventListener('click', action);
    }
    // A bat the API refused: the views keep the last valid bat's answers, dimmed (as the page's).
    new MutationObserver(() => {
      for (const id of ['#flight-top-section', '#carry-section']) $(id).classList.toggle('stale', refusedBat());
    }).observe(document.body, { attributes: true, attributeFilter: ['data-state'] });
    redrawOnResize($('#flight-top'), () => this.top && this.drawTop());
    redrawOnResize($('#carry-map'), () => this.carryAnswer && this.drawCarry(...this.carryAnswer));
  }

  /** The bat the API last accepted ({bat, scene, sweet}): both views follow it. */
  update(good) {
    this.good = good;
    this.refreshTop();
    this.refreshCarry();
  }

  // ---- from above -----------------------------------------------------------

  async refreshTop() {
    const battedBall = this.good?.sweet?.batted_ball;
    if (!battedBall) return;
    const seq = ++this.topSeq;
    const form = $('#flight-top-form');
    const launch = {
      exit_speed_mps: battedBall.exit_speed_mps,
      launch_angle_deg: battedBall.launch_angle_deg,
      backspin_rpm: battedBall.backspin_rpm,
      sidespin_rpm: battedBall.sidespin_rpm,
    };
    const spray = readValue(form.elements.spray_angle_deg);
    if (spray !== undefined) launch.spray_angle_deg = spray;
    const units = this.ctx.units();
    let answer;
    try {
      answer = await api.post('/v1/flight', { launch, outputs: ['trajectory'], report_units: units });
    } catch (error) {
      if (seq !== this.topSeq) return;
      clearErrors(form);
      showError(form, error);
      $('#flight-top-section').classList.add('stale');
      return;
    }
    if (seq !== this.topSeq) return;
    clearErrors(form);
    $('#flight-top-section').classList.toggle('stale', refusedBat());
    const imperial = units === 'imperial';
    const unit = imperial ? 'ft' : 'm';
    const key = (name) => `${name}_${unit}`;
    this.top = { answer, unit, x: key('x'), y: key('y') };
    this.drawTop();
    const landing = answer.landing;
    $('#flight-top-about').textContent =
      `Lands ${fmt(answer[key('distance')], 4)} ${unit} from home plate at ` +
      `${fmt(landing[key('x')], 4)} ${unit} toward right field, ${fmt(landing[key('y')], 4)} ${unit} toward centre ` +
      `(bearing ${fmt(answer.bearing_deg, 3)}°, + toward right field; ` +
      `spray angle ${fmt(launch.spray_angle_deg ?? 0, 3)}°, ` +
      `sidespin ${fmt(answer.sidespin_rpm, 4)} rpm).`;
  }

  drawTop() {
    const { answer, unit, x: xKey, y: yKey } = this.top;
    const svg = $('#flight-top');
    const field = fieldShape(unit);
    const path = answer.trajectory.map((p) => [p[xKey], p[yKey]]);
    const landing = [answer.landing[xKey], answer.landing[yKey]];
    const all = [...field.fence, ...field.lines, [0, 0], ...path, landing, ...field.labels.map((l) => l.at)];
    const pad = unit === 'ft' ? 40 : 40 * M_PER_FT; // room for the fence's labels
    const xmin = Math.min(...all.map((p) => p[0])) - pad;
    const xmax = Math.max(...all.map((p) => p[0])) + pad;
    const ymin = Math.min(...all.map((p) => p[1])) - pad;
    const ymax = Math.max(...all.map((p) => p[1])) + pad;
    const W = widthFor(svg);
    const k = W / (xmax - xmin); // one scale both ways: to scale
    const H = Math.round((ymax - ymin) * k);
    const px = (p) => [((p[0] - xmin) * k).toFixed(2), ((ymax - p[1]) * k).toFixed(2)];
    const points = (list) => list.map((p) => px(p).join(',')).join(' ');
    svg.setAttribute('viewBox', `0 0 ${W} ${H}`);
    const [hx, hy] = px([0, 0]);
    const [lx, ly] = px(landing);
    const [mx, my] = px(field.mound);
    const fair = [[0, 0], field.lines[0], ...field.fence, field.lines[1]];
    svg.replaceChildren(
      svgEl('polygon', { class: 'grass', points: points(fair) }),
      svgEl('polyline', { class: 'fence', points: points(field.fence) }),
      svgEl('polyline', { class: 'foul', points: points([field.lines[0], [0, 0], field.lines[1]]) }),
      svgEl('polyline', { class: 'infield-arc', points: points(field.arc) }),
      svgEl('polygon', { class: 'diamond', points: points(field.diamond) }),
      svgEl('circle', { class: 'mound', cx: mx, cy: my, r: (field.moundRadius * k).toFixed(2) }),
      ...field.labels.map((l) => {
        const [tx, ty] = px(l.at);
        return svgEl('text', { class: 'fence-label', x: tx, y: ty, 'text-anchor': 'middle', text: l.text });
      }),
      svgEl('polyline', { class: 'path', points: points(path) }),
      svgEl('circle', { class: 'home', cx: hx, cy: hy, r: 3 }),
      svgEl(
        'g',
        {
          class: 'landing',
          dataset: { x: String(landing[0]), y: String(landing[1]), distance: String(answer[`distance_${unit}`]) },
          title:
            `landing: ${fmt(landing[0], 4)} ${unit} toward right field, ` +
            `${fmt(landing[1], 4)} ${unit} toward centre field`,
        },
        svgEl('circle', { cx: lx, cy: ly, r: 6 }),
        svgEl('line', { x1: Number(lx) - 9, x2: Number(lx) + 9, y1: ly, y2: ly }),
        svgEl('line', { x1: lx, x2: lx, y1: Number(ly) - 9, y2: Number(ly) + 9 }),
      ),
      svgEl('text', { class: 'note', x: 8, y: H - 8, text: `generic field outline (330/375/400 ft), ${unit}` }),
    );
    svg.dataset.points = String(path.length);
    svg.dataset.unit = unit;
  }

  /** The path as shown: time, across, toward centre field (the API's numbers). */
  topTable() {
    if (!this.top) return [[]];
    const { answer, unit, x, y } = this.top;
    return [
      ['t (s)', `toward right field (${unit})`, `toward centre field (${unit})`],
      ...answer.trajectory.map((p) => [p.t_s, p[x], p[y]]),
    ];
  }

  // ---- the carry map ----------------------------------------------------------

  async refreshCarry() {
    if (!this.good) return;
    const seq = ++this.carrySeq;
    const form = $('#carry-form');
    const distance = {};
    for (const name of ['map_positions', 'map_undercuts']) {
      const value = readValue(form.elements[name]);
      if (value !== undefined) distance[name] = value;
    }
    const units = this.ctx.units();
    const body = {
      bat: this.good.bat,
      ...this.good.scene,
      outputs: ['distance_sweet_spot', 'carry_map'],
      options: { distance },
      report_units: units,
    };
    const section = $('#carry-section');
    section.dataset.state = 'busy';
    let answer;
    try {
      answer = await api.post('/v1/sweet-spot', body);
    } catch (error) {
      if (seq !== this.carrySeq) return;
      clearErrors(form);
      showError(form, error);
      section.classList.add('stale');
      section.dataset.state = 'error';
      return;
    }
    if (seq !== this.carrySeq) return;
    clearErrors(form);
    section.classList.toggle('stale', refusedBat());
    this.drawCarry(answer, units === 'imperial');
    section.dataset.state = 'ready';
  }

  drawCarry(answer, imperial) {
    const map = answer.carry_map;
    const spot = answer.distance_sweet_spot;
    const len = imperial ? 'in' : 'm';
    const far = imperial ? 'ft' : 'm';
    const xs = map.positions.map((row) => row[`position_from_knob_${len}`]);
    const us = map[`undercuts_${len}`];
    const cells = map.positions.map((row) => row[`distance_${far}`]);
    const values = cells.flat().filter((v) => typeof v === 'number');
    const lo = Math.min(...values);
    const hi = Math.max(...values);
    // The cell nearest the distance sweet spot: where the keyboard's cursor starts (and Home).
    const nearest = (list, v) =>
      list.reduce((best, w, k) => (Math.abs(w - v) < Math.abs(list[best] - v) ? k : best), 0);
    const home = {
      i: nearest(xs, answer.distance_sweet_spot[`position_from_knob_${len}`]),
      j: nearest(us, answer.distance_sweet_spot[`undercut_${len}`]),
    };
    this.carry = { xs, us, cells, len, far, home, cursor: { ...home } };
    this.carryAnswer = [answer, imperial];

    const svg = $('#carry-map');
    const W = widthFor(svg);
    const H = Math.round(Math.min(340, W * 0.62));
    const box = { left: 58, top: 10, width: W - 58 - 86, height: H - 10 - 46 };
    const edges = (list) => {
      const mids = list.slice(1).map((v, i) => (v + list[i]) / 2);
      const first = list.length > 1 ? list[0] - (list[1] - list[0]) / 2 : list[0] - 0.5;
      const n = list.length;
      const last = n > 1 ? list[n - 1] + (list[n - 1] - list[n - 2]) / 2 : list[0] + 0.5;
      return [first, ...mids, last];
    };
    const xe = edges(xs);
    const ue = edges(us);
    const xr = [xe[0], xe[xe.length - 1]];
    const ur = [ue[0], ue[ue.length - 1]];
    const x = scale(xr[0], xr[1], box.left, box.left + box.width);
    const y = scale(ur[0], ur[1], box.top + box.height, box.top);
    const t = (v) => (hi > lo ? (v - lo) / (hi - lo) : 0.5);
    const rects = [];
    cells.forEach((row, i) =>
      row.forEach((v, j) => {
        const x0 = x(xe[i]);
        const x1 = x(xe[i + 1]);
        const y0 = y(ue[j + 1]);
        const y1 = y(ue[j]);
        rects.push(
          svgEl('rect', {
            class: typeof v === 'number' ? 'cell' : 'cell none',
            x: x0.toFixed(2),
            y: y0.toFixed(2),
            width: (x1 - x0 + 0.4).toFixed(2),
            height: (y1 - y0 + 0.4).toFixed(2),
            fill: typeof v === 'number' ? colour(t(v)) : undefined,
            dataset: { i: String(i), j: String(j), value: v === null ? '' : String(v) },
            title:
              `${fmt(xs[i], 4)} ${len} from the knob, undercut ${fmt(us[j], 3)} ${len}: ` +
              (typeof v === 'number' ? `${fmt(v, 4)} ${far}` : 'no carry'),
          }),
        );
      }),
    );
    const sx = x(spot[`position_from_knob_${len}`]);
    const sy = y(spot[`undercut_${len}`]);
    const marker = svgEl(
      'g',
      {
        class: 'spot',
        dataset: {
          position: String(spot[`position_from_knob_${len}`]),
          undercut: String(spot[`undercut_${len}`]),
          distance: String(spot[`distance_${far}`]),
        },
        title: `distance sweet spot: ${fmt(spot[`distance_${far}`], 4)} ${far}`,
      },
      svgEl('circle', { cx: sx.toFixed(2), cy: sy.toFixed(2), r: 7 }),
      svgEl('line', { x1: (sx - 11).toFixed(2), x2: (sx + 11).toFixed(2), y1: sy.toFixed(2), y2: sy.toFixed(2) }),
      svgEl('line', { x1: sx.toFixed(2), x2: sx.toFixed(2), y1: (sy - 11).toFixed(2), y2: (sy + 11).toFixed(2) }),
    );
    // The legend: the colour scale from the smallest to the largest carry of the map.
    const legend = svgEl('g', { class: 'legend', dataset: { min: String(lo), max: String(hi), unit: far } });
    const lx = box.left + box.width + 18;
    const ly = scale(lo, hi, box.top + box.height, box.top);
    const gradient = svgEl(
      'linearGradient',
      { id: 'carry-scale', x1: 0, y1: 1, x2: 0, y2: 0 },
      ...VIRIDIS.map((c, i) => svgEl('stop', { offset: `${(i / (VIRIDIS.length - 1)) * 100}%`, 'stop-color': c })),
    );
    legend.append(
      svgEl('defs', {}, gradient),
      svgEl('rect', { x: lx, y: box.top, width: 14, height: box.height, fill: 'url(#carry-scale)', class: 'bar' }),
      svgEl('text', {
        x: lx + 7,
        y: box.top + box.height + 30,
        'text-anchor': 'middle',
        class: 'label',
        text: `carry (${far})`,
      }),
    );
    for (const v of hi > lo ? ticks(lo, hi, 5) : [lo]) {
      legend.append(
        svgEl('line', { x1: lx + 14, x2: lx + 18, y1: ly(v), y2: ly(v) }),
        svgEl('text', { x: lx + 21, y: ly(v) + 4, text: tickLabel(v) }),
      );
    }
    svg.setAttribute('viewBox', `0 0 ${W} ${H}`);
    svg.replaceChildren(
      svgEl('g', { class: 'cells' }, rects),
      axes(box, x, y, xr, ur, `position from the knob (${len})`, `undercut (${len})`),
      marker,
      legend,
    );
    this.moveCursor(home.i, home.j);
    svg.dataset.positions = String(xs.length);
    svg.dataset.undercuts = String(us.length);
    svg.dataset.unit = far;
    const best = map.best;
    $('#carry-about').replaceChildren(
      el('b', { text: 'Distance sweet spot ' }),
      `(the ring): ${fmt(spot[`distance_${far}`], 4)} ${far} at ` +
        `${fmt(spot[`position_from_knob_${len}`], 4)} ${len} from the knob`,
      imperial ? ` (${fmt(spot.position_from_tip_in, 3)} in from the tip)` : '',
      `, ${fmt(spot[`undercut_${len}`], 3)} ${len} undercut, launched at ${fmt(spot.launch_angle_deg, 3)}° with ` +
        `${fmt(spot.backspin_rpm, 4)} rpm. The grid's largest: ${fmt(best[`distance_${far}`], 4)} ${far}. ` +
        `Grey: no carry (the ball misses, grazes or is driven back). ${map.positions.length} × ${us.length} points, ` +
        `${map.normal_law.replaceAll('_', ' ')} normal law.`,
    );
  }

  /** Puts the keyboard's cursor on cell (i, j) (clamped to the grid) and reads it out. */
  moveCursor(i, j) {
    const { xs, us, cells, len, far } = this.carry;
    const ci = Math.max(0, Math.min(xs.length - 1, i));
    const cj = Math.max(0, Math.min(us.length - 1, j));
    this.carry.cursor = { i: ci, j: cj };
    const svg = $('#carry-map');
    for (const old of svg.querySelectorAll('rect.cursor')) old.remove();
    const cell = svg.querySelector(`rect.cell[data-i="${ci}"][data-j="${cj}"]`);
    if (cell) {
      // An outline over the cell, drawn last so that it is on top (the cells keep their order).
      const geometry = Object.fromEntries(['x', 'y', 'width', 'height'].map((k) => [k, cell.getAttribute(k)]));
      svg.append(svgEl('rect', { class: 'cursor', ...geometry, dataset: { i: String(ci), j: String(cj) } }));
    }
    const v = cells[ci][cj];
    const out = $('#carry-cell');
    out.dataset.i = String(ci);
    out.dataset.j = String(cj);
    out.dataset.value = v === null || v === undefined ? '' : String(v);
    out.textContent =
      `${fmt(xs[ci], 4)} ${len} from the knob, undercut ${fmt(us[cj], 3)} ${len}: ` +
      (typeof v === 'number' ? `${fmt(v, 4)} ${far}` : 'no carry');
  }

  /** The map as shown, one row per cell: position, undercut, carry ('' for none). */
  carryTable() {
    if (!this.carry) return [[]];
    const { xs, us, cells, len, far } = this.carry;
    const rows = [];
    cells.forEach((row, i) => row.forEach((v, j) => rows.push([xs[i], us[j], v ?? ''])));
    return [[`position from the knob (${len})`, `undercut (${len})`, `carry (${far})`], ...rows];
  }
}
