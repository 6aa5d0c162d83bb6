// The design explorer: one page over the public API (docs/explorer.md).
// Nothing shown is computed here: the page builds requests from the inputs,
// draws what the API answers, and shows the API's own error messages.
import './style.css';
import * as api from './api.js';
import { BatForm, drawBat, outlineOf } from './bat.js';
import { CurveChart, FlightChart, ModesChart, PALETTE, VariantsChart } from './charts.js';
import { ComparePanel } from './compare.js';
import { downloadCsv, downloadSvg } from './export.js';
import { FlightViews } from './flight_views.js';
import { Frontier } from './frontier.js';
import { clearErrors, el, fmt, fmtDelta, readFields, readValue, showError } from './form.js';
import { resetControls, restoreParams, stateParams, switchInputs } from './units.js';

const $ = (selector) => document.querySelector(selector);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/** The outputs the bat section asks /v1/sweet-spot for. */
const SWEET_SPOT_OUTPUTS = [
  'max_exit_speed',
  'center_of_percussion',
  'vibration_node',
  'sweet_zone',
  'exit_speed_curve',
  'bbcor',
  'barrel',
  'batted_ball',
];
/** Points of the exit-speed curve, knob to tip. */
const CURVE_SAMPLES = 121;
/** Job states after which nothing changes. */
const FINAL_STATES = new Set(['done', 'failed', 'cancelled']);

const page = {
  catalogue: null, // {presets, materials}: name -> the API's object
  batForm: null,
  curve: null,
  modes: null,
  variantsChart: null,
  refreshSeq: 0,
  flightSeq: 0,
  flight: null,
  compareSeq: 0,
  good: null, // the last bat the API accepted, with its answers
  job: null, // the optimisation job being watched
  units: 'imperial', // the unit switch: 'imperial' (in, oz, mph) or 'si'
};

/** The trade unit's twin of an SI key, as the API names it with report_units "imperial". */
const TWINS = [
  ['_kg_m2', '_oz_in2', 'oz·in²', 'kg·m²'],
  ['_mps', '_mph', 'mph', 'm/s'],
  ['_kg', '_oz', 'oz', 'kg'],
  ['_m', '_in', 'in', 'm'],
];

/** `obj`'s value of the SI key `key` in the page's units (the API's twin, never converted here). */
function q(obj, key) {
  if (!obj) return undefined;
  if (page.units !== 'imperial') return obj[key];
  const twin = TWINS.find(([si]) => key.endsWith(si));
  return twin ? obj[key.slice(0, -twin[0].length) + twin[1]] : obj[key];
}

/** The unit shown for the SI key `key` in the page's units. */
function u(key) {
  const twin = TWINS.find(([si]) => key.endsWith(si));
  if (!twin) return '';
  return page.units === 'imperial' ? twin[2] : twin[3];
}

/** The number with its unit ("31.2 in"), `digits` significant digits. */
function qu(obj, key, digits = 4) {
  return `${fmt(q(obj, key), digits)} ${u(key)}`;
}

function setStatus(text, kind = '') {
  const status = $('#status');
  status.textContent = text;
  status.dataset.kind = kind;
}

// ---- token ---------------------------------------------------------------

let tokenWaiters = [];
function askForToken(error) {
  const form = $('#token-form');
  form.hidden = false;
  clearErrors(form);
  if (api.token()) showError(form, { message: error.message, code: error.code });
  setStatus('This server needs a token.', 'error');
  return new Promise((resolve) => tokenWaiters.push(resolve));
}

function setupTokenForm() {
  $('#token-form').addEventListener('submit', (event) => {
    event.preventDefault();
    api.setToken($('#token').value.trim());
    $('#token-form').hidden = true;
    const waiters = tokenWaiters;
    tokenWaiters = [];
    for (const resolve of waiters) resolve();
  });
}

// ---- the bat, its curve and its modes ------------------------------------

const PROPERTY_ROWS = [
  ['length_m', 'Length', 'm', 'length_in', 'in'],
  ['mass_kg', 'Mass / weight', 'kg', 'weight_oz', 'oz'],
  [null, 'Drop (length − weight)', '', 'drop', ''],
  ['balance_point_m', 'Balance point from the knob', 'm', 'balance_point_in', 'in'],
  ['moi_knob_kg_m2', 'MOI about the knob', 'kg·m²', 'moi_knob_oz_in2', 'oz·in²'],
  ['moi_six_inch_kg_m2', 'MOI about the 6-in point (swing weight)', 'kg·m²', 'moi_six_inch_oz_in2', 'oz·in²'],
  ['moi_centroid_kg_m2', 'MOI about the balance point', 'kg·m²', 'moi_centroid_oz_in2', 'oz·in²'],
  ['volume_m3', 'Volume of material', 'm³', null, ''],
];

function renderProperties(properties) {
  const body = $('#properties tbody');
  body.replaceChildren(
    ...PROPERTY_ROWS.map(([si, label, siUnit, imperial, imperialUnit]) =>
      el(
        'tr',
        { dataset: { key: si || imperial } },
        el('th', { text: label }),
        el(
          'td',
          { dataset: { si: si ? String(properties[si]) : '' } },
          si ? `${fmt(properties[si], 5)} ${siUnit}` : '—',
        ),
        el(
          'td',
          { dataset: { imperial: imperial ? String(properties.imperial?.[imperial]) : '' } },
          imperial ? `${fmt(properties.imperial?.[imperial], 4)} ${imperialUnit}` : '—',
        ),
      ),
    ),
  );
}

/** The markers of a /v1/sweet-spot answer, for the chart and the drawing. */
function marksOf(sweet) {
  const marks = [
    {
      key: 'max_exit_speed',
      label: 'max exit speed',
      short: 'max',
      position_m: sweet.max_exit_speed?.position_from_knob_m,
    },
    {
      key: 'center_of_percussion',
      label: 'centre of percussion',
      short: 'CoP',
      position_m: sweet.center_of_percussion?.position_from_knob_m,
    },
    {
      key: 'vibration_node',
      label: 'vibration node',
      short: 'node',
      position_m: sweet.vibration_node?.position_from_knob_m,
    },
  ];
  for (const mark of marks) mark.at = q(sweet[mark.key], 'position_from_knob_m');
  return marks;
}

function renderMarkers(sweet) {
  const m = sweet.max_exit_speed;
  const cop = sweet.center_of_percussion;
  const node = sweet.vibration_node;
  const zone = sweet.sweet_zone;
  const item = (key, title, text, position) =>
    el(
      'li',
      { class: key, dataset: { marker: key, positionM: position === undefined ? '' : String(position) } },
      el('b', { text: title }),
      ` ${text}`,
    );
  const tip = (obj, key) =>
    page.units === 'imperial' && typeof obj?.[key] === 'number' ? `, ${fmt(obj[key], 3)} in from the tip` : '';
  $('#markers').replaceChildren(
    item(
      'max_exit_speed',
      'Max exit speed',
      `${qu(m, 'exit_speed_mps')} at ${qu(m, 'position_from_knob_m')} from the knob${tip(m, 'position_from_tip_in')} (${m.model}, ${m.placement.replaceAll('_', ' ')})`,
      m.position_from_knob_m,
    ),
    item(
      'center_of_percussion',
      'Centre of percussion',
      `${qu(cop, 'position_from_knob_m')} (hands at ${qu(cop, 'hands_from_knob_m')}; ${cop.placement.replaceAll('_', ' ')})`,
      cop.position_from_knob_m,
    ),
    item(
      'vibration_node',
      'Vibration node',
      `${qu(node, 'position_from_knob_m')} (fundamental bending mode, ${fmt(node.frequency_hz, 4)} Hz)`,
      node.position_from_knob_m,
    ),
    el(
      'li',
      {
        class: 'sweet_zone',
        dataset: { marker: 'sweet_zone', fromM: String(zone.from_knob_m), toM: String(zone.to_knob_m) },
      },
      el('b', { text: 'Sweet zone' }),
      ` ${fmt(q(zone, 'from_knob_m'), 4)}–${qu(zone, 'to_knob_m')} from the knob (within ${qu(zone, 'tolerance_mps', 3)} of the maximum)`,
    ),
  );
}

/**
 * The headline: the sweet spot, its exit speed, THE BBCOR, the barrel's hoop
 * frequency (hollow bats) and the batted ball's carry, each the API's number
 * in the page's units (`data-value` holds it, `data-path` says where it is).
 */
function renderHeadline(sweet, scene) {
  const m = sweet.max_exit_speed;
  const bb = sweet.batted_ball;
  const barrel = sweet.barrel;
  const imperial = page.units === 'imperial';
  const item = (key, title, path, value, unit, digits, note = '') =>
    el(
      'div',
      { class: 'item', dataset: { key, path, value: value === undefined || value === null ? '' : String(value) } },
      el('dt', { text: title }),
      el('dd', {}, el('b', { text: fmt(value, digits) }), unit ? ` ${unit}` : '', note ? el('small', { text: note }) : ''),
    );
  const spotKey = imperial ? 'position_from_tip_in' : 'position_from_knob_m';
  const items = [
    item(
      'sweet_spot',
      'Sweet spot',
      `max_exit_speed.${spotKey}`,
      m[spotKey],
      imperial ? 'in from the tip' : 'm from the knob',
      3,
      imperial ? ` ${fmt(m.position_from_knob_in, 4)} in from the knob` : '',
    ),
    item('exit_speed', 'Exit speed there', `max_exit_speed.${imperial ? 'exit_speed_mph' : 'exit_speed_mps'}`,
      q(m, 'exit_speed_mps'), u('exit_speed_mps'), 4, ` ${m.model} model, head-on`),
    item('bbcor', 'BBCOR', 'bbcor.value', sweet.bbcor?.value, '', 3,
      sweet.bbcor ? ` max of the scan, ${qu(sweet.bbcor, 'impact_from_tip_m', 3)} from the tip` : ''),
  ];
  if (barrel?.hollow) {
    items.push(item('hoop_frequency', 'Barrel hoop frequency', 'barrel.hoop_frequency_hz', barrel.hoop_frequency_hz, 'Hz', 4,
      ` effective COR ${fmt(barrel.effective_cor, 3)}`));
  }
  if (bb) {
    const carryKey = imperial ? 'distance_ft' : 'distance_m';
    items.push(
      item('carry', 'Carry', `batted_ball.${carryKey}`, bb[carryKey], imperial ? 'ft' : 'm', 4,
        ` at ${qu(bb, 'exit_speed_mps', 4)}, ${fmt(bb.launch_angle_deg, 3)}°, ${fmt(bb.backspin_rpm, 4)} rpm`),
    );
  }
  $('#headline-values').replaceChildren(...items);
  const ball = scene.ball?.preset ? `the ${scene.ball.preset} ball` : 'the default ball';
  const pitch = scene.ball?.speed_mph ?? scene.ball?.speed_mps;
  const pitchUnit = scene.ball?.speed_mph !== undefined ? 'mph' : 'm/s';
  const swing = sweet.swing;
  $('#headline-about').textContent =
    `(${ball}${pitch === undefined ? '' : ` at ${pitch} ${pitchUnit}`}` +
    `${swing?.bat_speed_mps !== undefined ? `, bat speed ${qu(swing, 'bat_speed_mps', 3)}` : ''}; POST /v1/sweet-spot)`;
}

function renderModes(modes) {
  const imperial = page.units === 'imperial';
  const nodes = imperial ? 'nodes_from_knob_in' : 'nodes_from_knob_m';
  page.modes.update(modes.modes, {
    x: imperial ? 'position_from_knob_in' : 'position_from_knob_m',
    nodes,
    xLabel: `position from the knob (${u('position_from_knob_m')})`,
  });
  $('#modes-about').textContent = modes.modes
    .map(
      (m) =>
        `Mode ${m.mode}: ${fmt(m.frequency_hz, 4)} Hz, nodes at ${(m[nodes] || []).map((x) => fmt(x, 3)).join(', ')} ${u('position_from_knob_m')}`,
    )
    .join('. ');
  $('#modes-chart').dataset.frequenciesHz = modes.modes.map((m) => m.frequency_hz).join(',');
}

/** The bat the inputs describe, as the three calls of the bat section see it. */
async function refreshBat() {
  const seq = ++page.refreshSeq;
  const form = $('#bat-form');
  const bat = page.batForm.request();
  const scene = page.batForm.scene();
  document.body.dataset.state = 'busy';
  setStatus('Computing…');
  const started = performance.now();
  const results = await Promise.allSettled([
    api.post('/v1/bat/properties', { bat, report_units: page.units }),
    api.post('/v1/sweet-spot', {
      bat,
      ...scene,
      outputs: SWEET_SPOT_OUTPUTS,
      options: { curve_samples: CURVE_SAMPLES },
      report_units: page.units,
    }),
    api.post('/v1/bat/modes', { bat, modes: 2, shape_samples: 81, report_units: page.units }),
  ]);
  if (seq !== page.refreshSeq) return; // A newer edit has its own requests.
  clearErrors(form);
  const failures = results.filter((r) => r.status === 'rejected').map((r) => r.reason);
  if (failures.length) {
    const seen = new Set();
    for (const error of failures) {
      const key = `${error.field}|${error.message}`;
      if (seen.has(key)) continue;
      seen.add(key);
      showError(form, error);
    }
    for (const section of ['#headline', '#bat-section', '#curve-section', '#modes-section']) {
      $(section).classList.add('stale');
    }
    document.body.dataset.state = 'error';
    setStatus(
      'The API refused the inputs: see the message beside the field. The charts show the last valid bat.',
      'error',
    );
    return;
  }
  const [properties, sweet, modes] = results.map((r) => r.value);
  for (const section of ['#headline', '#bat-section', '#curve-section', '#modes-section']) {
    $(section).classList.remove('stale');
  }
  const outline = page.batForm.outline(bat);
  page.good = { bat, scene, properties, sweet, modes, outline };
  const marks = marksOf(sweet);
  const zone = { from_m: sweet.sweet_zone.from_knob_m, to_m: sweet.sweet_zone.to_knob_m };
  drawBat($('#bat-drawing'), [outline && { ...outline, role: 'main' }], {
    marks,
    zone,
    axisUnit: page.units === 'imperial' ? 'in' : 'm',
  });
  renderProperties(properties);
  page.curve.update(
    sweet.exit_speed_curve,
    marks,
    { ...zone, from: q(sweet.sweet_zone, 'from_knob_m'), to: q(sweet.sweet_zone, 'to_knob_m') },
    {
      position: q(sweet.max_exit_speed, 'position_from_knob_m'),
      speed: q(sweet.max_exit_speed, 'exit_speed_mps'),
    },
    {
      x: page.units === 'imperial' ? 'position_from_knob_in' : 'position_from_knob_m',
      y: page.units === 'imperial' ? 'exit_speed_mph' : 'exit_speed_mps',
      xLabel: `position from the knob (${u('position_from_knob_m')})`,
      yLabel: `exit speed (${u('exit_speed_mps')})`,
    },
  );
  renderHeadline(sweet, scene);
  const chart = $('#curve-chart');
  chart.dataset.maxExitSpeedPositionM = String(sweet.max_exit_speed.position_from_knob_m);
  chart.dataset.maxExitSpeedMps = String(sweet.max_exit_speed.exit_speed_mps);
  chart.dataset.centerOfPercussionM = String(sweet.center_of_percussion.position_from_knob_m);
  chart.dataset.vibrationNodeM = String(sweet.vibration_node.position_from_knob_m);
  renderMarkers(sweet);
  renderModes(modes);
  updateVariablesAbout();
  saveState();
  document.body.dataset.revision = String(Number(document.body.dataset.revision || 0) + 1);
  document.body.dataset.state = 'ready';
  setStatus(`Up to date (3 requests, ${Math.round(performance.now() - started)} ms).`, 'ok');
  refreshCompare();
  page.bats.refresh();
  refreshFlight(sweet.batted_ball);
  page.flightViews.update(page.good);
}

/**
 * The batted ball's path from the side: /v1/flight with the launch the
 * batted_ball block gives (its exit speed, angle and spins, from 3 ft as it
 * flew), sampled every 0.05 s.
 */
async function refreshFlight(battedBall) {
  const seq = ++page.flightSeq;
  const section = $('#flight-section');
  if (!battedBall) return;
  const launch = {
    exit_speed_mps: battedBall.exit_speed_mps,
    launch_angle_deg: battedBall.launch_angle_deg,
    backspin_rpm: battedBall.backspin_rpm,
    sidespin_rpm: battedBall.sidespin_rpm,
  };
  const body = { launch, outputs: ['trajectory'], report_units: page.units };
  let answer;
  try {
    answer = await api.post('/v1/flight', body);
  } catch (error) {
    if (seq !== page.flightSeq) return;
    section.classList.add('stale');
    $('#flight-about').textContent = `The flight was refused: ${error.message}`;
    return;
  }
  if (seq !== page.flightSeq) return;
  section.classList.remove('stale');
  const imperial = page.units === 'imperial';
  const unit = imperial ? 'ft' : 'm';
  page.flight.update(answer.trajectory, imperial ? 'y_ft' : 'y_m', imperial ? 'z_ft' : 'z_m', unit);
  const distance = imperial ? answer.distance_ft : answer.distance_m;
  const apex = imperial ? answer.apex_ft : answer.apex_m;
  const chart = $('#flight-chart');
  chart.dataset.distance = String(distance);
  chart.dataset.points = String(answer.trajectory.length);
  $('#flight-about').textContent =
    `Launched at ${qu(answer.trajectory[0], 'speed_mps', 4)}, ${fmt(battedBall.launch_angle_deg, 3)}°, ` +
    `${fmt(answer.backspin_rpm, 4)} rpm backspin: ${fmt(distance, 4)} ${unit} from home plate, apex ` +
    `${fmt(apex, 3)} ${unit}, ${fmt(answer.hang_time_s, 3)} s in the air (${answer.aero_model}, ` +
    `${answer.classification?.barrel ? 'a barrel' : 'not a barrel'} by Statcast's definition).`;
}

// ---- units and the URL ----------------------------------------------------

/** The forms whose inputs the URL keeps. */
const stateForms = () => [$('#bat-form'), $('#optimize-form'), ...FLIGHT_FORMS.map((id) => $(id))];
/** The flight views' and the frontier's forms (flight_views.js, frontier.js). */
const FLIGHT_FORMS = ['#flight-top-form', '#carry-form', '#frontier-form'];

/** The URL's hash of the page's state: the forms' inputs, then the bats side by side. */
function stateHash() {
  const params = stateParams(stateForms(), page.units);
  page.bats.writeParams(params);
  return `#${params.toString()}`;
}

/** Writes the inputs that differ from the defaults into the URL's hash (a link restores them). */
function saveState() {
  const hash = stateHash();
  if (hash !== window.location.hash) history.replaceState(null, '', hash);
  $('#share-link').href = window.location.href;
}

/** The page as the URL's hash says: the defaults, in its units, with its inputs over them. */
function restoreState() {
  const params = new URLSearchParams(window.location.hash.slice(1));
  const units = params.get('units');
  resetControls(stateForms());
  setUnits(units === 'si' ? 'si' : 'imperial');
  restoreParams(stateForms(), params);
  page.bats.readParams(params);
  page.batForm.syncShape();
}

/** Switches the page to `system`: the inputs at their defaults, the answers' units. */
function setUnits(system) {
  page.units = system;
  for (const radio of document.querySelectorAll('input[name="units"]')) radio.checked = radio.value === system;
  document.body.dataset.units = system;
  for (const form of stateForms()) switchInputs(form, system);
}

function setupUnits() {
  $('#units').addEventListener('change', (event) => {
    setUnits(event.target.value);
    refreshBat();
  });
}

let editTimer = 0;
function setupBatForm() {
  const form = $('#bat-form');
  form.addEventListener('submit', (event) => event.preventDefault());
  form.addEventListener('change', (event) => {
    if (event.target.tagName === 'SELECT') page.batForm.syncShape();
    clearTimeout(editTimer);
    refreshBat();
  });
  form.addEventListener('input', (event) => {
    if (event.target.tagName === 'SELECT') return;
    clearTimeout(editTimer);
    editTimer = setTimeout(refreshBat, 400);
  });
}

// ---- variants ------------------------------------------------------------

/** The cork fill of the paper's Table 4 at `density` kg/m³ (the catalogue's cork otherwise). */
function corkFill(density) {
  const cork = page.catalogue.materials.get('cork');
  return {
    material: { name: `cork-${density}`, density_kg_m3: density, youngs_modulus_pa: cork.youngs_modulus_pa },
    diameter_m: 0.0254,
    depth_m: 0.254,
  };
}

/** The variants offered: changes applied to the bat above. */
const VARIANTS = [
  {
    id: 'cork-260',
    label: 'cork fill, 260 kg/m³ (paper, Table 4)',
    needs: ['cork'],
    checked: true,
    make: () => ({ fill: corkFill(260) }),
  },
  {
    id: 'cork-320',
    label: 'cork fill, 320 kg/m³',
    needs: ['cork'],
    checked: true,
    make: () => ({ fill: corkFill(320) }),
  },
  {
    id: 'aluminium',
    label: 'hollow aluminium-7050, 3 mm wall (wood against aluminium)',
    needs: ['aluminium-7050'],
    checked: true,
    make: () => ({ material: 'aluminium-7050', wall_thickness_m: 0.003, fill: null }),
  },
  { id: 'ash', label: 'white ash', needs: ['ash'], checked: false, make: () => ({ material: 'ash' }) },
  { id: 'maple', label: 'hard maple', needs: ['hard-maple'], checked: false, make: () => ({ material: 'hard-maple' }) },
];

function setupVariants() {
  const box = $('#variant-choices');
  for (const variant of VARIANTS) {
    const available = variant.needs.every((name) => page.catalogue.materials.has(name));
    box.append(
      el(
        'label',
        { class: 'choice' },
        el('input', {
          type: 'checkbox',
          name: variant.id,
          checked: variant.checked && available,
          disabled: !available,
        }),
        ` ${variant.label}`,
        el('output', { class: 'error', hidden: true, dataset: { errorFor: `variant:${variant.id}` } }),
      ),
    );
  }
  $('#compare-form').addEventListener('change', () => refreshCompare());
}

function compareCell(value, digits, delta, deltaDigits = 3) {
  return el(
    'td',
    { dataset: { value: value === undefined ? '' : String(value) } },
    fmt(value, digits),
    delta === undefined ? '' : el('small', { class: 'delta', text: ` ${fmtDelta(delta, deltaDigits)}` }),
  );
}

async function refreshCompare() {
  if (!page.good) return;
  const seq = ++page.compareSeq;
  const form = $('#compare-form');
  const chosen = VARIANTS.filter((v) => form.elements[v.id]?.checked);
  const base = page.good.bat;
  const variants = chosen.map((v) => {
    const change = v.make();
    const bat = { ...base, ...change };
    // A change in metres replaces the base's own form of that field (a wall typed in inches).
    for (const key of Object.keys(change)) if (key.endsWith('_m')) delete bat[`${key.slice(0, -2)}_in`];
    return { name: v.id, bat };
  });
  const body = {
    baseline: base,
    variants,
    ...page.good.scene,
    outputs: ['max_exit_speed', 'center_of_percussion', 'sweet_zone', 'exit_speed_curve'],
    options: { curve_samples: CURVE_SAMPLES },
    report_units: page.units,
  };
  let answer;
  try {
    answer = await api.post('/v1/compare', body);
  } catch (error) {
    if (seq !== page.compareSeq) return;
    clearErrors(form);
    showError(form, error, (field) =>
      field.replace(/^variants\[(\d+)\]/, (_, i) => `variant:${chosen[Number(i)]?.id}`),
    );
    $('#compare-section').classList.add('stale');
    return;
  }
  if (seq !== page.compareSeq) return;
  clearErrors(form);
  $('#compare-section').classList.remove('stale');
  const rows = answer.rows;
  const bats = [base, ...variants.map((v) => v.bat)];
  const head = el(
    'tr',
    {},
    el('th', { text: '' }),
    ...rows.map((row, i) => {
      const svg = document.createElementNS('http://www.w3.org/2000/svg', 'svg');
      svg.classList.add('mini');
      const outline = outlineOf(bats[i], page.catalogue);
      drawBat(svg, [outline && { ...outline, role: 'main' }], { axis: false });
      return el(
        'th',
        { dataset: { variant: row.name }, style: `--series: ${PALETTE[i % PALETTE.length]}` },
        el('span', { class: 'name', text: row.name }),
        svg,
      );
    }),
  );
  const line = (label, unit, pick, digits, pickDelta) =>
    el(
      'tr',
      {},
      el('th', {}, label, unit ? el('small', { text: ` ${unit}` }) : ''),
      ...rows.map((row) => compareCell(pick(row), digits, pickDelta ? pickDelta(row) : undefined)),
    );
  const table = $('#compare-table');
  table.replaceChildren(
    el('thead', {}, head),
    el(
      'tbody',
      {},
      line('Mass', u('mass_kg'), (r) => q(r.properties, 'mass_kg'), 4, (r) => q(r.deltas, 'mass_kg')),
      line('Weight', 'oz', (r) => r.properties.imperial?.weight_oz, 4),
      line('Balance point', u('balance_point_m'), (r) => q(r.properties, 'balance_point_m'), 4, (r) =>
        q(r.deltas, 'balance_point_m'),
      ),
      line('MOI about 6 in', u('moi_six_inch_kg_m2'), (r) => q(r.properties, 'moi_six_inch_kg_m2'), 4, (r) =>
        q(r.deltas, 'moi_six_inch_kg_m2'),
      ),
      line('Max exit speed', u('exit_speed_mps'), (r) => q(r.max_exit_speed, 'exit_speed_mps'), 4, (r) =>
        q(r.deltas, 'max_exit_speed_mps'),
      ),
      line('… at', u('position_from_knob_m'), (r) => q(r.max_exit_speed, 'position_from_knob_m'), 4, (r) =>
        q(r.deltas, 'max_exit_speed_position_m'),
      ),
      line(
        'Centre of percussion',
        u('position_from_knob_m'),
        (r) => q(r.center_of_percussion, 'position_from_knob_m'),
        4,
        (r) => q(r.deltas, 'center_of_percussion_m'),
      ),
      line('Sweet zone from', u('from_knob_m'), (r) => q(r.sweet_zone, 'from_knob_m'), 4),
      line('Sweet zone to', u('to_knob_m'), (r) => q(r.sweet_zone, 'to_knob_m'), 4),
      line('COR', '', (r) => r.cor, 3),
    ),
  );
  table.dataset.variants = rows.map((r) => r.name).join(',');
  page.variantsChart.update(rows, {
    x: page.units === 'imperial' ? 'position_from_knob_in' : 'position_from_knob_m',
    y: page.units === 'imperial' ? 'exit_speed_mph' : 'exit_speed_mps',
    xLabel: `position from the knob (${u('position_from_knob_m')})`,
    yLabel: `exit speed (${u('exit_speed_mps')})`,
  });
}

// ---- optimisation --------------------------------------------------------

/** The variables the optimisation may change, for the bat above. */
function optimizeVariables(bat, radiusMin, radiusMax, byDiameterIn) {
  // The bounds' input says the variables' form: radii in m, or diameters in inches (the API
  // takes either, docs/api.md "The trade's units"; the answer names them as written).
  const radius = byDiameterIn ? 'diameter_in' : 'radius_m';
  if (bat.three_segment) {
    // The taper's positions in the unit the shape's inputs give them, bounded by its length.
    const unit = 'taper_start_in' in bat.three_segment ? 'in' : 'm';
    const length = bat.three_segment[`length_${unit}`];
    return [
      { path: `three_segment.handle_${radius}`, min: radiusMin, max: radiusMax },
      { path: `three_segment.barrel_${radius}`, min: radiusMin, max: radiusMax },
      { path: `three_segment.taper_start_${unit}`, min: 0, max: length },
      { path: `three_segment.taper_end_${unit}`, min: 0, max: length },
    ];
  }
  const knots = page.catalogue.presets.get(bat.preset)?.bat.profile.knots || [];
  return knots.map((_, i) => ({ path: `profile.knots[${i}].${radius}`, min: radiusMin, max: radiusMax }));
}

function updateVariablesAbout() {
  const bat = page.good?.bat;
  if (!bat) return;
  $('#variables-about').textContent = bat.three_segment
    ? 'The handle and barrel radii or diameters (between the bounds below) and where the taper starts and ends.'
    : `The radius (or diameter) of each of the preset's ${page.catalogue.presets.get(bat.preset)?.bat.profile.knots.length} knots (between the bounds below); their positions stay.`;
}

function optimizeBody() {
  const form = $('#optimize-form');
  const bat = page.batForm.request();
  const constraints = readFields(form, 'constraints.');
  if (form.elements.rules.value) constraints.rules = form.elements.rules.value;
  return {
    bat,
    ...page.batForm.scene(),
    variables: optimizeVariables(
      bat,
      readValue(form.elements.radius_min),
      readValue(form.elements.radius_max),
      form.elements.radius_min.dataset.system === 'imperial',
    ),
    constraints,
    objective: form.elements.objective.value,
    options: readFields(form, 'options.'),
    report_units: page.units,
  };
}

function showJob(job) {
  const state = $('#optimize-state');
  const progress = $('#optimize-progress');
  progress.hidden = false;
  progress.value = job.progress || 0;
  state.dataset.state = job.state;
  state.dataset.jobId = job.id;
  const percent = Math.round((job.progress || 0) * 100);
  state.textContent =
    job.state === 'running' || job.state === 'queued'
      ? `${job.state}${job.cancel_requested ? ', cancelling' : ''}: ${percent} %`
      : job.state;
}

function renderOptimum(result, original) {
  const optimised = outlineOf(result.bat, page.catalogue);
  drawBat(
    $('#optimize-drawing'),
    [original && { ...original.outline, role: 'original' }, optimised && { ...optimised, role: 'optimised' }],
    {
      marks: [
        {
          key: 'max_exit_speed',
          label: 'optimum sweet spot',
          short: 'max',
          position_m: result.sweet_spot?.position_from_knob_m,
        },
      ],
    },
  );
  $('#optimize-drawing').dataset.optimised = 'true';
  $('#optimize-figure').hidden = false;
  const p = result.properties;
  const o = original?.properties || {};
  const s = result.summary || {};
  const row = (label, value, before, unit, digits = 4) =>
    el(
      'tr',
      {},
      el('th', { text: label }),
      el('td', { dataset: { value: String(value) } }, `${fmt(value, digits)} ${unit}`),
      el('td', {}, before === undefined ? '' : `${fmt(before, digits)} ${unit}`),
    );
  $('#optimize-result').replaceChildren(
    el('thead', {}, el('tr', {}, el('th'), el('th', { text: 'optimised' }), el('th', { text: 'the bat above' }))),
    el(
      'tbody',
      {},
      el(
        'tr',
        { dataset: { key: 'termination' } },
        el('th', { text: 'Termination' }),
        el('td', { colspan: 2, text: `${s.termination} — ${s.message}` }),
      ),
      row(`Objective (${result.objective})`, result.objective_value, undefined, result.objective_unit),
      row(
        'Sweet spot (from the knob)',
        q(result.sweet_spot, 'position_from_knob_m'),
        q(original?.sweet.max_exit_speed, 'position_from_knob_m'),
        u('position_from_knob_m'),
      ),
      row(
        'Exit speed there',
        q(result.sweet_spot, 'exit_speed_mps'),
        q(original?.sweet.max_exit_speed, 'exit_speed_mps'),
        u('exit_speed_mps'),
      ),
      row('Mass', q(p, 'mass_kg'), q(o, 'mass_kg'), u('mass_kg')),
      row('Balance point', q(p, 'balance_point_m'), q(o, 'balance_point_m'), u('balance_point_m')),
      row('MOI about 6 in', q(p, 'moi_six_inch_kg_m2'), q(o, 'moi_six_inch_kg_m2'), u('moi_six_inch_kg_m2')),
      row('Constraint violation', s.constraint_violation, undefined, '', 3),
      row('Starts converged', s.spread?.converged, undefined, `of ${s.spread?.starts}`, 3),
    ),
  );
}

function renderInfeasible(error) {
  const conflicts = error.body?.conflicts || [];
  $('#optimize-result').replaceChildren(
    el(
      'tbody',
      {},
      el('tr', { dataset: { key: 'infeasible' } }, el('th', { text: error.code }), el('td', { text: error.message })),
      ...conflicts.map((c) =>
        el('tr', {}, el('th', { text: (c.constraints || []).join(', ') }), el('td', { text: c.message })),
      ),
    ),
  );
}

async function runOptimisation() {
  const form = $('#optimize-form');
  clearErrors(form);
  $('#optimize-result').replaceChildren();
  $('#optimize-figure').hidden = true;
  const original = page.good;
  let job;
  try {
    job = await api.post('/v1/jobs', { path: '/v1/optimize', body: optimizeBody() });
  } catch (error) {
    showError(form, error, (field) => (field === 'body' ? '*' : field));
    return;
  }
  page.job = job;
  $('#optimize-run').disabled = true;
  $('#optimize-cancel').disabled = false;
  showJob(job);
  try {
    while (!FINAL_STATES.has(job.state)) {
      await sleep(150);
      job = await api.get(`/v1/jobs/${job.id}`);
      showJob(job);
    }
    if (job.state === 'cancelled') {
      setStatus('Optimisation cancelled.', 'ok');
      return;
    }
    try {
      const result = await api.get(`/v1/jobs/${job.id}/result`);
      renderOptimum(result, original);
      setStatus('Optimisation finished.', 'ok');
    } catch (error) {
      if (error.body?.conflicts || error.code === 'Infeasible') renderInfeasible(error);
      showError(form, error);
      setStatus('The optimisation did not give a design: see the message.', 'error');
    }
  } catch (error) {
    showError(form, error);
  } finally {
    $('#optimize-run').disabled = false;
    $('#optimize-cancel').disabled = true;
    page.job = null;
  }
}

function setupOptimizeForm() {
  $('#optimize-form').addEventListener('change', () => saveState());
  $('#optimize-form').addEventListener('submit', (event) => {
    event.preventDefault();
    runOptimisation();
  });
  $('#optimize-cancel').addEventListener('click', async () => {
    if (!page.job) return;
    $('#optimize-cancel').disabled = true;
    try {
      showJob(await api.del(`/v1/jobs/${page.job.id}`));
    } catch (error) {
      showError($('#optimize-form'), error);
    }
  });
}

// ---- exports ---------------------------------------------------------------

/** The CSV / SVG buttons under each chart: what the chart shows, as files. */
function setupExports() {
  const stem = () => (page.good?.bat.preset || 'bat').replace(/[^A-Za-z0-9_-]/g, '_');
  const actions = {
    'bat-drawing-svg': () => downloadSvg(`${stem()}-drawing.svg`, $('#bat-drawing')),
    'curve-csv': () => downloadCsv(`${stem()}-exit-speed-${page.units}.csv`, page.curve.table()),
    'flight-csv': () => downloadCsv(`${stem()}-flight-${page.units}.csv`, page.flight.table()),
    'modes-csv': () => downloadCsv(`${stem()}-modes.csv`, page.modes.table()),
    'compare-csv': () => downloadCsv(`${stem()}-variants.csv`, page.variantsChart.table()),
  };
  for (const button of document.querySelectorAll('[data-export]')) {
    button.addEventListener('click', () => actions[button.dataset.export]?.());
  }
}

// ---- start ---------------------------------------------------------------

async function start() {
  api.setUnauthorizedHandler(() => {});
  setupTokenForm();
  let presets;
  let materials;
  let balls;
  for (;;) {
    try {
      [presets, materials, balls] = await Promise.all([
        api.get('/v1/presets'),
        api.get('/v1/materials'),
        api.get('/v1/balls'),
      ]);
      break;
    } catch (error) {
      if (error.status !== 401) {
        setStatus(`Cannot load the catalogues: ${error.message}`, 'error');
        document.body.dataset.state = 'error';
        return;
      }
      await askForToken(error);
    }
  }
  api.setUnauthorizedHandler((error) => askForToken(error).then(refreshBat));
  page.catalogue = {
    presets: new Map(presets.presets.map((p) => [p.name, p])),
    materials: new Map(materials.materials.map((m) => [m.name, m])),
    balls: new Map(balls.balls.map((b) => [b.name, b])),
  };
  page.batForm = new BatForm($('#bat-form'), page.catalogue);
  page.curve = new CurveChart($('#curve-chart'));
  page.modes = new ModesChart($('#modes-chart'));
  page.variantsChart = new VariantsChart($('#compare-chart'));
  page.flight = new FlightChart($('#flight-chart'));
  page.bats = new ComparePanel($('#bats-section'), {
    catalogue: page.catalogue,
    units: () => page.units,
    current: () => page.good,
    onChange: saveState,
  });
  const stem = () => (page.good?.bat.preset || 'bat').replace(/[^A-Za-z0-9_-]/g, '_');
  page.flightViews = new FlightViews({ units: () => page.units, saveState, stem });
  page.frontier = new Frontier({ optimizeBody, saveState, stem });
  setupUnits();
  restoreState();
  setupBatForm();
  setupVariants();
  setupOptimizeForm();
  setupExports();
  window.addEventListener('hashchange', () => {
    if (window.location.hash === stateHash()) return;
    restoreState();
    refreshBat();
  });
  await refreshBat();
}

start();
