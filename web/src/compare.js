// Bats side by side (issue 37, item 2): the bat above and the bats the user
// adds (catalogue presets, or copies of the bat above as it was), asked of
// POST /v1/compare in one request. Shown: their profiles to one scale, their
// exit-speed curves on one chart with a legend, and the deltas the API gives
// (variant minus the bat above). "Same batter" asks with the swing-weight
// speed model (swing.speed_model "swing_weight", Cross & Bower 2006) and says
// which speed each bat is swung at, from the answer. Nothing is computed here:
// every number is the API's, in the page's units (report_units).
import './compare.css';
import * as api from './api.js';
import { drawBat, outlineOf } from './bat.js';
import { PALETTE } from './charts.js';
import { downloadCsv, downloadSvg } from './export.js';
import { clearErrors, el, fmt, fmtDelta, showError } from './form.js';

const SVG = 'http://www.w3.org/2000/svg';
/** The value of the "add" list that copies the bat above. */
const CURRENT = '@current';
/** Points of each exit-speed curve, knob to tip (the bat section's count). */
const CURVE_SAMPLES = 121;
/** The outputs each bat is asked for. */
const OUTPUTS = ['max_exit_speed', 'center_of_percussion', 'exit_speed_curve'];
/** The most bats the list takes (the server's --max-variants default is 64). */
const MAX_BATS = 8;
/** The URL hash's keys: one `cmp.bat` per added bat, and the switch. */
const HASH_BAT = 'cmp.bat';
const HASH_SAME_BATTER = 'cmp.same_batter';

/** The trade unit's twin of an SI key, as the API names it with report_units "imperial". */
const TWINS = [
  ['_kg_m2', '_oz_in2', 'oz·in²', 'kg·m²'],
  ['_mps', '_mph', 'mph', 'm/s'],
  ['_kg', '_oz', 'oz', 'kg'],
  ['_m', '_in', 'in', 'm'],
];

function svgEl(tag, attrs = {}, text) {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attrs)) node.setAttribute(key, String(value));
  if (text !== undefined) node.textContent = text;
  return node;
}

/** Round steps for an axis over [lo, hi]: about `count` ticks. */
function ticks(lo, hi, count) {
  const span = hi - lo;
  if (!(span > 0)) return [lo];
  const raw = span / count;
  const power = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * power).find((s) => s >= raw) || 10 * power;
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(Number(v.toPrecision(12)));
  return out;
}

/**
 * The panel: its form (add, remove, the "same batter" switch), the request,
 * and the three views with their exports. `options`: `catalogue` (presets,
 * materials), `units()` (the page's switch), `current()` (the last bat the API
 * accepted: {bat, scene}), `onChange()` (the list or switch changed: the page
 * saves its URL).
 */
export class ComparePanel {
  constructor(section, { catalogue, units, current, onChange }) {
    this.section = section;
    this.catalogue = catalogue;
    this.units = units;
    this.current = current;
    this.onChange = onChange;
    this.form = section.querySelector('#bats-form');
    this.bats = []; // [{name, bat}]: the bats added, in order
    this.seq = 0;
    this.shown = null; // what the views show: {rows, names, units}
    this.populate();
    this.form.addEventListener('submit', (event) => {
      event.preventDefault();
      this.add(this.form.elements.bats_add.value);
    });
    this.form.elements.same_batter.addEventListener('change', () => {
      this.onChange();
      this.refresh();
    });
    this.section.querySelector('#bats-list').addEventListener('click', (event) => {
      const button = event.target.closest('button[data-remove]');
      if (button) this.remove(Number(button.dataset.remove));
    });
    for (const button of section.querySelectorAll('[data-bats-export]')) {
      button.addEventListener('click', () => this.export(button.dataset.batsExport));
    }
    new ResizeObserver(() => this.drawCurves()).observe(section.querySelector('#bats-curves'));
    // The profiles' text sizes follow the drawing's width: drawn again when the width changes.
    new ResizeObserver(() => {
      const width = section.querySelector('#bats-profiles').getBoundingClientRect().width;
      if (this.shown && width && Math.abs(width - (this.profilesWidthPx || 0)) > 1) this.drawProfiles();
    }).observe(section.querySelector('#bats-profiles'));
    this.renderList();
  }

  /** The "add" list: a copy of the bat above, then the catalogue's presets. */
  populate() {
    const select = this.form.elements.bats_add;
    select.replaceChildren(new Option('the bat above, as it is now (a copy)', CURRENT));
    for (const p of this.catalogue.presets.values()) select.append(new Option(`${p.name} (preset)`, p.name));
    const alloy = [...this.catalogue.presets.keys()].find((name) => /aluminium|alloy/.test(name));
    if (alloy) select.value = alloy;
  }

  /** `obj`'s value of the SI key `key` in the page's units (the API's twin, never converted here). */
  q(obj, key) {
    if (!obj) return undefined;
    if (this.units() !== 'imperial') return obj[key];
    const twin = TWINS.find(([si]) => key.endsWith(si));
    return twin ? obj[key.slice(0, -twin[0].length) + twin[1]] : obj[key];
  }

  /** The page's unit of the SI key `key` ('' when it has none). */
  u(key) {
    const twin = TWINS.find(([si]) => key.endsWith(si));
    if (!twin) return key.endsWith('_rad_s') ? 'rad/s' : '';
    return this.units() === 'imperial' ? twin[2] : twin[3];
  }

  /** The API's key of the SI key `key` in the page's units. */
  key(key) {
    if (this.units() !== 'imperial') return key;
    const twin = TWINS.find(([si]) => key.endsWith(si));
    return twin ? key.slice(0, -twin[0].length) + twin[1] : key;
  }

  /** A name no other bat has: `base`, else `base (2)`, … */
  uniqueName(base) {
    const taken = new Set(['baseline', ...this.bats.map((b) => b.name)]);
    if (!taken.has(base)) return base;
    for (let i = 2; ; ++i) if (!taken.has(`${base} (${i})`)) return `${base} (${i})`;
  }

  /** Adds a preset by name, or a copy of the bat above (CURRENT). */
  add(choice) {
    if (this.bats.length >= MAX_BATS) return;
    let entry;
    if (choice === CURRENT) {
      const bat = this.current()?.bat;
      if (!bat) return;
      const copy = JSON.parse(JSON.stringify(bat));
      const parts = [copy.preset || 'three-segment'];
      if (typeof copy.material === 'string') parts.push(copy.material);
      entry = { name: this.uniqueName(`copy: ${parts.join(', ')}`), bat: copy };
    } else if (this.catalogue.presets.has(choice)) {
      entry = { name: this.uniqueName(choice), bat: { preset: choice } };
    } else {
      return;
    }
    this.bats.push(entry);
    this.renderList();
    this.onChange();
    this.refresh();
  }

  remove(index) {
    this.bats.splice(index, 1);
    this.renderList();
    this.onChange();
    this.refresh();
    // Keep the keyboard where it was: the next remove button, or the add list.
    const buttons = this.section.querySelectorAll('#bats-list button[data-remove]');
    (buttons[Math.min(index, buttons.length - 1)] || this.form.elements.bats_add).focus();
  }

  /** The list of bats: the bat above first (not removable), then each added bat with its remove button. */
  renderList() {
    const list = this.section.querySelector('#bats-list');
    const swatch = (i) =>
      el('span', { class: 'swatch', style: `--series: ${PALETTE[i % PALETTE.length]}`, 'aria-hidden': 'true' });
    list.replaceChildren(
      el(
        'li',
        { dataset: { bat: 'baseline' } },
        swatch(0),
        el('span', { class: 'name', text: 'the bat above' }),
        el('small', { text: ' (the baseline of the deltas)' }),
      ),
      ...this.bats.map((b, i) =>
        el(
          'li',
          { dataset: { bat: b.name } },
          swatch(i + 1),
          el('span', { class: 'name', text: b.name }),
          el('button', {
            type: 'button',
            dataset: { remove: String(i) },
            'aria-label': `Remove ${b.name}`,
            text: 'Remove',
          }),
          el('output', { class: 'error', hidden: true, dataset: { errorFor: `bats:${i}` } }),
        ),
      ),
    );
    this.form.elements.bats_add.disabled = this.bats.length >= MAX_BATS;
    this.section.querySelector('#bats-add').disabled = this.bats.length >= MAX_BATS;
  }

  /** Writes the added bats and the switch into `params` (the URL's hash). */
  writeParams(params) {
    for (const b of this.bats) {
      const asPreset = b.bat.preset && Object.keys(b.bat).length === 1 && b.name === b.bat.preset;
      params.append(HASH_BAT, asPreset ? b.bat.preset : JSON.stringify(b));
    }
    if (this.form.elements.same_batter.checked) params.set(HASH_SAME_BATTER, 'on');
  }

  /** Restores what writeParams wrote (nothing named: no bats added, the switch off). */
  readParams(params) {
    this.bats = [];
    for (const value of params.getAll(HASH_BAT)) {
      if (value.startsWith('{')) {
        try {
          const b = JSON.parse(value);
          if (b && typeof b.name === 'string' && b.bat && typeof b.bat === 'object') {
            this.bats.push({ name: this.uniqueName(b.name), bat: b.bat });
          }
        } catch {
          // A hand-edited link: the bat it cannot read is left out.
        }
      } else if (value) {
        // A preset's name, sent as written (the API names an unknown one).
        this.bats.push({ name: this.uniqueName(value), bat: { preset: value } });
      }
    }
    this.bats = this.bats.slice(0, MAX_BATS);
    this.form.elements.same_batter.checked = params.get(HASH_SAME_BATTER) === 'on';
    this.renderList();
  }

  /** The request: the bat above as the baseline, the added bats as variants, the page's scene. */
  request() {
    const { bat, scene } = this.current();
    const sameBatter = this.form.elements.same_batter.checked;
    const swing = { ...(scene.swing || {}) };
    if (sameBatter) swing.speed_model = 'swing_weight';
    const body = {
      baseline: bat,
      variants: this.bats.map((b) => ({ name: b.name, bat: b.bat })),
      ...scene,
      outputs: OUTPUTS,
      options: { curve_samples: CURVE_SAMPLES },
      report_units: this.units(),
    };
    if (Object.keys(swing).length) body.swing = swing;
    return body;
  }

  /** Asks /v1/compare for the bats (after the bat above changed, or the list, or the switch). */
  async refresh() {
    const seq = ++this.seq;
    const state = this.section.querySelector('#bats-state');
    if (!this.current()) return;
    if (!this.bats.length) {
      clearErrors(this.form);
      this.shown = null;
      this.section.classList.remove('stale');
      this.section.dataset.bats = '1';
      for (const id of ['#bats-profiles', '#bats-table']) this.section.querySelector(id).replaceChildren();
      this.section.querySelector('#bats-curves').replaceChildren();
      this.section.querySelector('#bats-mode').textContent =
        'Add a bat (a preset, or a copy of the bat above before you change it) to see it beside the bat above.';
      this.section.querySelector('#bats-views').hidden = true;
      state.dataset.state = 'ready';
      state.dataset.revision = String(Number(state.dataset.revision || 0) + 1);
      return;
    }
    state.dataset.state = 'busy';
    const body = this.request();
    let answer;
    try {
      answer = await api.post('/v1/compare', body);
    } catch (error) {
      if (seq !== this.seq) return;
      clearErrors(this.form);
      showError(this.form, error, (field) =>
        field.replace(/^variants\[(\d+)\](\.bat)?/, (_, i) => `bats:${i}`).replace(/^baseline/, 'bat'),
      );
      this.section.classList.add('stale');
      state.dataset.state = 'error';
      return;
    }
    if (seq !== this.seq) return;
    clearErrors(this.form);
    this.section.classList.remove('stale');
    this.section.querySelector('#bats-views').hidden = false;
    const names = [`the bat above (${body.baseline.preset || 'three-segment'})`, ...this.bats.map((b) => b.name)];
    this.shown = {
      rows: answer.rows,
      names,
      bats: [body.baseline, ...body.variants.map((v) => v.bat)],
      units: this.units(),
    };
    this.section.dataset.bats = String(answer.rows.length);
    this.renderMode(answer.rows, body.swing?.speed_model === 'swing_weight');
    this.drawProfiles();
    this.drawCurves();
    this.renderTable();
    state.dataset.state = 'ready';
    state.dataset.revision = String(Number(state.dataset.revision || 0) + 1);
  }

  /** Says which mode is on and the speed each bat is swung at (the answer's `swing`). */
  renderMode(rows, sameBatter) {
    const mode = this.section.querySelector('#bats-mode');
    mode.dataset.mode = sameBatter ? 'same_batter' : 'same_bat_speed';
    const names = this.shown.names;
    const withSpeed = rows.every((r) => typeof r.swing?.bat_speed_mps === 'number');
    const speeds = rows.map((r, i) => {
      const value = withSpeed ? this.q(r.swing, 'bat_speed_mps') : r.swing?.angular_speed_rad_s;
      const unit = withSpeed ? this.u('bat_speed_mps') : 'rad/s';
      return el(
        'span',
        { class: 'speed', dataset: { batSpeed: String(value), name: names[i] } },
        i ? ', ' : '',
        `${names[i]} `,
        el('b', { text: fmt(value, 4) }),
        ` ${unit}`,
      );
    });
    const sw = rows[0]?.swing?.swing_weight;
    let text;
    if (sameBatter && sw) {
      const ref = sw.reference_bat ? `${sw.reference_bat}, ` : '';
      text =
        `swing.speed_model "swing_weight" (Cross & Bower 2006): the batter swings the reference bat ` +
        `(${ref}${fmt(this.q(sw, 'reference_moi_kg_m2'), 5)} ${this.u('reference_moi_kg_m2')} about the hands) at ` +
        `${fmt(this.q(sw, 'given_bat_speed_mps'), 4)} ${this.u('given_bat_speed_mps')}, and each bat at that speed × ` +
        `(its MOI about the hands / the reference's)^−${fmt(sw.exponent, 3)}. Bat speeds: `;
    } else if (withSpeed) {
      text = `swing.speed_model "fixed": every bat swung at the speed given, at ${fmt(
        this.q(rows[0].swing, 'bat_speed_from_tip_m'),
        3,
      )} ${this.u('bat_speed_from_tip_m')} from its tip. Bat speeds: `;
    } else {
      text = 'no bat speed given: every bat at the same angular speed. Angular speeds: ';
    }
    mode.replaceChildren(
      el('strong', { text: sameBatter ? 'Mode: same batter. ' : 'Mode: same bat speed. ' }),
      text,
      ...speeds,
      '.',
    );
  }

  /** The bats' profiles, one lane each, to one scale (1 unit = 1 mm along and across), knobs aligned. */
  drawProfiles() {
    const svg = this.section.querySelector('#bats-profiles');
    svg.replaceChildren();
    const { rows, names, bats } = this.shown;
    const outlines = bats.map((bat) => outlineOf(bat, this.catalogue));
    const drawn = outlines.filter(Boolean);
    if (!drawn.length) return;
    const pad = 10;
    const length = Math.max(...drawn.map((o) => o.knots[o.knots.length - 1].x_m)) * 1000;
    // The names and the axis's numbers at about 13 and 11 screen pixels whatever the width (a
    // phone draws the bats at under half a pixel per mm): text sizes in drawing units.
    const widthPx = svg.getBoundingClientRect().width || length + 2 * pad;
    const perPx = Math.max(1, (length + 2 * pad) / widthPx);
    const nameSize = 13 * perPx;
    const tickSize = 11 * perPx;
    const label = nameSize + 8; // room above each lane for its name
    let y = 0;
    outlines.forEach((outline, i) => {
      const lane = svgEl('g', { class: 'lane', 'data-bat': names[i] });
      const title = svgEl('text', { class: 'lane-name', x: 0, y: y + nameSize + 2 }, names[i]);
      title.style.setProperty('--series', PALETTE[i % PALETTE.length]);
      title.style.fontSize = `${nameSize}px`;
      lane.append(title);
      y += label;
      if (outline) {
        const inner = svgEl('svg', {});
        const position = rows[i]?.max_exit_speed?.position_from_knob_m;
        drawBat(inner, [{ ...outline, role: 'main' }], {
          axis: false,
          marks: [
            {
              key: 'max_exit_speed',
              label: 'max exit speed',
              short: 'max',
              position_m: position,
              at: this.q(rows[i]?.max_exit_speed, 'position_from_knob_m'),
            },
          ],
          axisUnit: this.units() === 'imperial' ? 'in' : 'm',
        });
        const box = inner.viewBox.baseVal;
        // The lane's own box, placed 1:1 in the outer drawing: the same scale for every bat.
        inner.setAttribute('x', String(box.x));
        inner.setAttribute('y', String(y));
        inner.setAttribute('width', String(box.width));
        inner.setAttribute('height', String(box.height));
        lane.dataset.lengthM = inner.dataset.lengthM;
        lane.dataset.maxExitSpeedM = String(position);
        lane.append(inner);
        y += box.height;
      } else {
        lane.append(svgEl('text', { class: 'lane-note', x: 0, y: y + 12 }, '(no outline to draw for this bat)'));
        y += 20;
      }
      svg.append(lane);
    });
    // One axis under the lanes: every 4 in, or every 0.1 m (the drawing's scale; no number converted).
    const inches = this.units() === 'imperial';
    const axis = svgEl('g', { class: 'axis' });
    const top = y + 4;
    axis.append(svgEl('line', { x1: 0, x2: length, y1: top, y2: top }));
    const step = inches ? 4 * 25.4 : 100;
    for (let i = 0; i * step <= length + 1e-6; ++i) {
      axis.append(svgEl('line', { x1: i * step, x2: i * step, y1: top, y2: top + 5 }));
      axis.append(
        svgEl(
          'text',
          { x: i * step, y: top + 8 + tickSize, 'text-anchor': 'middle' },
          inches ? String(4 * i) : (i / 10).toFixed(1),
        ),
      );
    }
    axis.append(
      svgEl(
        'text',
        { x: length, y: top + 12 + 2 * tickSize, 'text-anchor': 'end' },
        `${inches ? 'in' : 'm'} from the knob`,
      ),
    );
    for (const text of axis.querySelectorAll('text')) text.style.fontSize = `${tickSize}px`;
    svg.append(axis);
    svg.setAttribute('viewBox', `${-pad} 0 ${length + 2 * pad} ${top + 18 + 2 * tickSize}`);
    this.profilesWidthPx = widthPx;
    svg.dataset.lanes = String(outlines.length);
  }

  /** The curves' table: the x column and one column per bat, in the page's units (the API's numbers). */
  curveTable() {
    const { rows, names, units } = this.shown;
    const imperial = units === 'imperial';
    const xKey = imperial ? 'position_from_knob_in' : 'position_from_knob_m';
    const yKey = imperial ? 'exit_speed_mph' : 'exit_speed_mps';
    const unitX = imperial ? 'in' : 'm';
    const unitY = imperial ? 'mph' : 'm/s';
    const xs = [...new Set(rows.flatMap((r) => r.exit_speed_curve.map((p) => p[xKey])))].sort((a, b) => a - b);
    const columns = rows.map((r) => new Map(r.exit_speed_curve.map((p) => [p[xKey], p[yKey]])));
    return {
      xKey,
      yKey,
      xLabel: `position from the knob (${unitX})`,
      yLabel: `exit speed (${unitY})`,
      header: [`position from the knob (${unitX})`, ...names.map((n) => `${n}: exit speed (${unitY})`)],
      rows: xs.map((x) => [x, ...columns.map((c) => (c.has(x) ? c.get(x) : null))]),
    };
  }

  /** The exit-speed curves on one chart (SVG, drawn at the box's width), with a legend and each bat's maximum. */
  drawCurves() {
    const box = this.section.querySelector('#bats-curves');
    if (!this.shown) return;
    const { rows, names } = this.shown;
    const width = Math.max(280, Math.floor(box.getBoundingClientRect().width || 600));
    const table = this.curveTable();
    const left = 56;
    const right = 14;
    const top = 12;
    const plotH = 220;
    const legendTop = top + plotH + 44;
    // A narrow chart (a phone) gives each bat two legend lines, so that no text passes its edge.
    const narrow = width < 600;
    const lineH = 16;
    const itemH = narrow ? 2 * lineH + 4 : lineH + 2;
    const height = legendTop + rows.length * itemH + 4;
    const xs = table.rows.map((r) => r[0]);
    const ys = table.rows.flatMap((r) => r.slice(1)).filter((v) => typeof v === 'number');
    const [x0, x1] = [Math.min(...xs), Math.max(...xs)];
    const [y0, y1] = [Math.min(...ys), Math.max(...ys)];
    const yPad = (y1 - y0) * 0.05 || 1;
    const [ylo, yhi] = [y0 - yPad, y1 + yPad];
    const px = (x) => left + ((x - x0) / (x1 - x0 || 1)) * (width - left - right);
    const py = (y) => top + (1 - (y - ylo) / (yhi - ylo)) * plotH;
    const svg = svgEl('svg', {
      id: 'bats-curves-svg',
      viewBox: `0 0 ${width} ${height}`,
      width,
      height,
      role: 'img',
      'aria-label': `Exit speed along each bat: ${names.join(', ')}`,
    });
    const grid = svgEl('g', { class: 'grid' });
    for (const t of ticks(x0, x1, Math.max(4, Math.floor(width / 80)))) {
      grid.append(svgEl('line', { x1: px(t), x2: px(t), y1: top, y2: top + plotH }));
      grid.append(svgEl('text', { x: px(t), y: top + plotH + 16, 'text-anchor': 'middle' }, fmt(t, 4)));
    }
    for (const t of ticks(ylo, yhi, 5)) {
      grid.append(svgEl('line', { x1: left, x2: width - right, y1: py(t), y2: py(t) }));
      grid.append(svgEl('text', { x: left - 6, y: py(t) + 4, 'text-anchor': 'end' }, fmt(t, 4)));
    }
    grid.append(
      svgEl(
        'text',
        { class: 'label', x: (left + width - right) / 2, y: top + plotH + 34, 'text-anchor': 'middle' },
        table.xLabel,
      ),
    );
    const yLabel = svgEl(
      'text',
      {
        class: 'label',
        x: 0,
        y: 0,
        'text-anchor': 'middle',
        transform: `translate(14 ${top + plotH / 2}) rotate(-90)`,
      },
      table.yLabel,
    );
    grid.append(yLabel);
    grid.append(svgEl('rect', { class: 'frame', x: left, y: top, width: width - left - right, height: plotH }));
    svg.append(grid);
    rows.forEach((row, i) => {
      const color = PALETTE[i % PALETTE.length];
      const points = row.exit_speed_curve.map((p) => `${px(p[table.xKey]).toFixed(2)},${py(p[table.yKey]).toFixed(2)}`);
      const series = svgEl('g', { class: 'series', 'data-bat': names[i] });
      series.append(
        svgEl('polyline', {
          points: points.join(' '),
          fill: 'none',
          stroke: color,
          'stroke-width': 2,
          'stroke-dasharray': i ? '6 3' : 'none',
        }),
      );
      const m = row.max_exit_speed;
      const mx = this.q(m, 'position_from_knob_m');
      const my = this.q(m, 'exit_speed_mps');
      if (Number.isFinite(mx) && Number.isFinite(my)) {
        const dot = svgEl('circle', {
          class: 'peak',
          cx: px(mx),
          cy: py(my),
          r: 4,
          fill: color,
          'data-x': mx,
          'data-y': my,
        });
        dot.append(
          svgEl(
            'title',
            {},
            `${names[i]}: max ${fmt(my, 4)} ${this.u('exit_speed_mps')} at ${fmt(mx, 4)} ${this.u('position_from_knob_m')} from the knob`,
          ),
        );
        series.append(dot);
      }
      svg.append(series);
      const legend = svgEl('g', { class: 'legend-item', 'data-bat': names[i] });
      const ly = legendTop + i * itemH;
      const lx = narrow ? 4 : left;
      legend.append(
        svgEl('line', {
          x1: lx,
          x2: lx + 28,
          y1: ly - 4,
          y2: ly - 4,
          stroke: color,
          'stroke-width': 3,
          'stroke-dasharray': i ? '6 3' : 'none',
        }),
      );
      const peak = `max ${fmt(my, 4)} ${this.u('exit_speed_mps')} at ${fmt(mx, 4)} ${this.u('position_from_knob_m')} from the knob`;
      if (narrow) {
        legend.append(svgEl('text', { x: lx + 36, y: ly }, names[i]));
        legend.append(svgEl('text', { x: lx + 36, y: ly + lineH }, peak));
      } else {
        legend.append(svgEl('text', { x: lx + 36, y: ly }, `${names[i]}: ${peak}`));
      }
      svg.append(legend);
    });
    box.replaceChildren(svg);
  }

  /** The numbers side by side: each bat's value and its delta from the bat above, as the API gives them. */
  tableRows() {
    const { rows } = this.shown;
    const k = (key) => this.key(key);
    const lines = [
      [
        'bat_speed',
        'Bat speed',
        this.u('bat_speed_mps'),
        (r) => this.q(r.swing, 'bat_speed_mps'),
        `swing.${k('bat_speed_mps')}`,
        'bat_speed_mps',
      ],
      [
        'angular_speed',
        'Angular speed',
        'rad/s',
        (r) => r.swing?.angular_speed_rad_s,
        'swing.angular_speed_rad_s',
        'angular_speed_rad_s',
      ],
      [
        'max_exit_speed',
        'Max exit speed',
        this.u('exit_speed_mps'),
        (r) => this.q(r.max_exit_speed, 'exit_speed_mps'),
        `max_exit_speed.${k('exit_speed_mps')}`,
        'max_exit_speed_mps',
      ],
      [
        'max_exit_speed_position',
        '… at (from the knob)',
        this.u('position_from_knob_m'),
        (r) => this.q(r.max_exit_speed, 'position_from_knob_m'),
        `max_exit_speed.${k('position_from_knob_m')}`,
        'max_exit_speed_position_m',
      ],
      [
        'center_of_percussion',
        'Centre of percussion',
        this.u('position_from_knob_m'),
        (r) => this.q(r.center_of_percussion, 'position_from_knob_m'),
        `center_of_percussion.${k('position_from_knob_m')}`,
        'center_of_percussion_m',
      ],
      [
        'length',
        'Length',
        this.u('length_m'),
        (r) => this.q(r.properties, 'length_m'),
        `properties.${k('length_m')}`,
        null,
      ],
      [
        'mass',
        'Mass',
        this.u('mass_kg'),
        (r) => this.q(r.properties, 'mass_kg'),
        `properties.${k('mass_kg')}`,
        'mass_kg',
      ],
      [
        'balance_point',
        'Balance point',
        this.u('balance_point_m'),
        (r) => this.q(r.properties, 'balance_point_m'),
        `properties.${k('balance_point_m')}`,
        'balance_point_m',
      ],
      [
        'moi_six_inch',
        'MOI about 6 in (swing weight)',
        this.u('moi_six_inch_kg_m2'),
        (r) => this.q(r.properties, 'moi_six_inch_kg_m2'),
        `properties.${k('moi_six_inch_kg_m2')}`,
        'moi_six_inch_kg_m2',
      ],
      [
        'moi_knob',
        'MOI about the knob',
        this.u('moi_knob_kg_m2'),
        (r) => this.q(r.properties, 'moi_knob_kg_m2'),
        `properties.${k('moi_knob_kg_m2')}`,
        'moi_knob_kg_m2',
      ],
      ['cor', 'COR', '', (r) => r.cor, 'cor', null],
    ];
    return lines
      .filter(([, , , pick]) => rows.some((r) => typeof pick(r) === 'number'))
      .map(([key, label, unit, pick, path, delta]) => ({
        key,
        label,
        unit,
        path,
        deltaPath: delta ? `deltas.${k(delta)}` : null,
        values: rows.map(pick),
        deltas: rows.map((r) => (delta && r.deltas ? this.q(r.deltas, delta) : undefined)),
      }));
  }

  renderTable() {
    const { names } = this.shown;
    const table = this.section.querySelector('#bats-table');
    const lines = this.tableRows();
    table.replaceChildren(
      el(
        'thead',
        {},
        el(
          'tr',
          {},
          el('th', { scope: 'col', text: '' }),
          ...names.map((n, i) =>
            el('th', { scope: 'col', dataset: { bat: n }, style: `--series: ${PALETTE[i % PALETTE.length]}`, text: n }),
          ),
        ),
      ),
      el(
        'tbody',
        {},
        ...lines.map((line) =>
          el(
            'tr',
            { dataset: { key: line.key, path: line.path, deltaPath: line.deltaPath || '' } },
            el('th', { scope: 'row' }, line.label, line.unit ? el('small', { text: ` ${line.unit}` }) : ''),
            ...line.values.map((value, i) =>
              el(
                'td',
                {
                  dataset: {
                    bat: names[i],
                    value: value === undefined ? '' : String(value),
                    delta: line.deltas[i] === undefined ? '' : String(line.deltas[i]),
                  },
                },
                fmt(value, 4),
                line.deltas[i] === undefined
                  ? ''
                  : el('small', { class: 'delta', text: ` ${fmtDelta(line.deltas[i], 3)}` }),
              ),
            ),
          ),
        ),
      ),
    );
  }

  /** The table's CSV: one row per bat, each quantity's value and delta (the API's, unrounded). */
  numbersTable() {
    const { names } = this.shown;
    const lines = this.tableRows();
    const header = ['bat'];
    for (const line of lines) {
      const unit = line.unit ? ` (${line.unit})` : '';
      header.push(`${line.label}${unit}`);
      if (line.deltaPath) header.push(`${line.label}: delta from the bat above${unit}`);
    }
    const out = names.map((name, i) => {
      const row = [name];
      for (const line of lines) {
        row.push(line.values[i]);
        if (line.deltaPath) row.push(line.deltas[i]);
      }
      return row;
    });
    return [header, ...out];
  }

  /** The profiles' CSV: each bat's knots as drawn (m; a preset's knots as GET /v1/presets gives them). */
  profilesTable() {
    const { names, bats } = this.shown;
    const rows = [['bat', 'knot', 'x from the knob (m)', 'radius (m)', 'wall (m; 0: solid)']];
    bats.forEach((bat, i) => {
      const outline = outlineOf(bat, this.catalogue);
      outline?.knots.forEach((knot, j) => rows.push([names[i], j, knot.x_m, knot.radius_m, outline.wall_m]));
    });
    return rows;
  }

  /** The export buttons: what each view shows, as files. */
  export(kind) {
    if (!this.shown) return;
    const stem = `bats-${this.form.elements.same_batter.checked ? 'same-batter' : 'same-bat-speed'}`;
    const units = this.shown.units;
    const actions = {
      'profiles-svg': () => downloadSvg(`${stem}-profiles.svg`, this.section.querySelector('#bats-profiles')),
      'profiles-csv': () => downloadCsv(`${stem}-profiles.csv`, this.profilesTable()),
      'curves-svg': () =>
        downloadSvg(`${stem}-exit-speed-${units}.svg`, this.section.querySelector('#bats-curves-svg')),
      'curves-csv': () => {
        const t = this.curveTable();
        downloadCsv(`${stem}-exit-speed-${units}.csv`, [t.header, ...t.rows]);
      },
      'table-csv': () => downloadCsv(`${stem}-deltas-${units}.csv`, this.numbersTable()),
    };
    actions[kind]?.();
  }
}
