// The design explorer: one page over the public API (docs/explorer.md).
// Nothing shown is computed here: the page builds requests from the inputs,
// draws what the API answers, and shows the API's own error messages.
import './style.css';
import * as api from './api.js';
import { BatForm, drawBat, outlineOf } from './bat.js';
import { CurveChart, ModesChart, PALETTE, VariantsChart } from './charts.js';
import { clearErrors, el, fmt, fmtDelta, readFields, readValue, showError } from './form.js';

const $ = (selector) => document.querySelector(selector);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/** The outputs the bat section asks /v1/sweet-spot for. */
const SWEET_SPOT_OUTPUTS = [
  'max_exit_speed',
  'center_of_percussion',
  'vibration_node',
  'sweet_zone',
  'exit_speed_curve',
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
  compareSeq: 0,
  good: null, // the last bat the API accepted, with its answers
  job: null, // the optimisation job being watched
};

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
  return [
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
  $('#markers').replaceChildren(
    item(
      'max_exit_speed',
      'Max exit speed',
      `${fmt(m.exit_speed_mps, 4)} m/s at ${fmt(m.position_from_knob_m, 4)} m from the knob (${m.model}, ${m.placement.replaceAll('_', ' ')})`,
      m.position_from_knob_m,
    ),
    item(
      'center_of_percussion',
      'Centre of percussion',
      `${fmt(cop.position_from_knob_m, 4)} m (hands at ${fmt(cop.hands_from_knob_m, 4)} m; ${cop.placement.replaceAll('_', ' ')})`,
      cop.position_from_knob_m,
    ),
    item(
      'vibration_node',
      'Vibration node',
      `${fmt(node.position_from_knob_m, 4)} m (fundamental bending mode, ${fmt(node.frequency_hz, 4)} Hz)`,
      node.position_from_knob_m,
    ),
    el(
      'li',
      {
        class: 'sweet_zone',
        dataset: { marker: 'sweet_zone', fromM: String(zone.from_knob_m), toM: String(zone.to_knob_m) },
      },
      el('b', { text: 'Sweet zone' }),
      ` ${fmt(zone.from_knob_m, 4)}–${fmt(zone.to_knob_m, 4)} m (within ${fmt(zone.tolerance_mps, 3)} m/s of the maximum)`,
    ),
  );
}

function renderModes(modes) {
  page.modes.update(modes.modes);
  $('#modes-about').textContent = modes.modes
    .map(
      (m) =>
        `Mode ${m.mode}: ${fmt(m.frequency_hz, 4)} Hz, nodes at ${m.nodes_from_knob_m.map((x) => fmt(x, 3)).join(', ')} m`,
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
    api.post('/v1/bat/properties', { bat }),
    api.post('/v1/sweet-spot', {
      bat,
      ...scene,
      outputs: SWEET_SPOT_OUTPUTS,
      options: { curve_samples: CURVE_SAMPLES },
    }),
    api.post('/v1/bat/modes', { bat, modes: 2, shape_samples: 81 }),
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
    for (const section of ['#bat-section', '#curve-section', '#modes-section']) $(section).classList.add('stale');
    document.body.dataset.state = 'error';
    setStatus(
      'The API refused the inputs: see the message beside the field. The charts show the last valid bat.',
      'error',
    );
    return;
  }
  const [properties, sweet, modes] = results.map((r) => r.value);
  for (const section of ['#bat-section', '#curve-section', '#modes-section']) $(section).classList.remove('stale');
  const outline = page.batForm.outline(bat);
  page.good = { bat, scene, properties, sweet, modes, outline };
  const marks = marksOf(sweet);
  const zone = { from_m: sweet.sweet_zone.from_knob_m, to_m: sweet.sweet_zone.to_knob_m };
  drawBat($('#bat-drawing'), [outline && { ...outline, role: 'main' }], { marks, zone });
  renderProperties(properties);
  page.curve.update(sweet.exit_speed_curve, marks, zone, {
    position_m: sweet.max_exit_speed.position_from_knob_m,
    speed_mps: sweet.max_exit_speed.exit_speed_mps,
  });
  const chart = $('#curve-chart');
  chart.dataset.maxExitSpeedPositionM = String(sweet.max_exit_speed.position_from_knob_m);
  chart.dataset.maxExitSpeedMps = String(sweet.max_exit_speed.exit_speed_mps);
  chart.dataset.centerOfPercussionM = String(sweet.center_of_percussion.position_from_knob_m);
  chart.dataset.vibrationNodeM = String(sweet.vibration_node.position_from_knob_m);
  renderMarkers(sweet);
  renderModes(modes);
  updateVariablesAbout();
  document.body.dataset.revision = String(Number(document.body.dataset.revision || 0) + 1);
  document.body.dataset.state = 'ready';
  setStatus(`Up to date (3 requests, ${Math.round(performance.now() - started)} ms).`, 'ok');
  refreshCompare();
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
  const variants = chosen.map((v) => ({ name: v.id, bat: { ...base, ...v.make() } }));
  const body = {
    baseline: base,
    variants,
    ...page.good.scene,
    outputs: ['max_exit_speed', 'center_of_percussion', 'sweet_zone', 'exit_speed_curve'],
    options: { curve_samples: CURVE_SAMPLES },
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
      line(
        'Mass',
        'kg',
        (r) => r.properties.mass_kg,
        4,
        (r) => r.deltas?.mass_kg,
      ),
      line('Weight', 'oz', (r) => r.properties.imperial?.weight_oz, 4),
      line(
        'Balance point',
        'm',
        (r) => r.properties.balance_point_m,
        4,
        (r) => r.deltas?.balance_point_m,
      ),
      line(
        'MOI about 6 in',
        'kg·m²',
        (r) => r.properties.moi_six_inch_kg_m2,
        4,
        (r) => r.deltas?.moi_six_inch_kg_m2,
      ),
      line(
        'Max exit speed',
        'm/s',
        (r) => r.max_exit_speed.exit_speed_mps,
        4,
        (r) => r.deltas?.max_exit_speed_mps,
      ),
      line(
        '… at',
        'm',
        (r) => r.max_exit_speed.position_from_knob_m,
        4,
        (r) => r.deltas?.max_exit_speed_position_m,
      ),
      line(
        'Centre of percussion',
        'm',
        (r) => r.center_of_percussion.position_from_knob_m,
        4,
        (r) => r.deltas?.center_of_percussion_m,
      ),
      line('Sweet zone from', 'm', (r) => r.sweet_zone.from_knob_m, 4),
      line('Sweet zone to', 'm', (r) => r.sweet_zone.to_knob_m, 4),
      line('COR', '', (r) => r.cor, 3),
    ),
  );
  table.dataset.variants = rows.map((r) => r.name).join(',');
  page.variantsChart.update(rows);
}

// ---- optimisation --------------------------------------------------------

/** The variables the optimisation may change, for the bat above. */
function optimizeVariables(bat, radiusMin, radiusMax) {
  if (bat.three_segment) {
    const length = bat.three_segment.length_m;
    return [
      { path: 'three_segment.handle_radius_m', min: radiusMin, max: radiusMax },
      { path: 'three_segment.barrel_radius_m', min: radiusMin, max: radiusMax },
      { path: 'three_segment.taper_start_m', min: 0, max: length },
      { path: 'three_segment.taper_end_m', min: 0, max: length },
    ];
  }
  const knots = page.catalogue.presets.get(bat.preset)?.bat.profile.knots || [];
  return knots.map((_, i) => ({ path: `profile.knots[${i}].radius_m`, min: radiusMin, max: radiusMax }));
}

function updateVariablesAbout() {
  const bat = page.good?.bat;
  if (!bat) return;
  $('#variables-about').textContent = bat.three_segment
    ? 'The handle and barrel radii (between the bounds below) and where the taper starts and ends.'
    : `The radius of each of the preset's ${page.catalogue.presets.get(bat.preset)?.bat.profile.knots.length} knots (between the bounds below); their positions stay.`;
}

function optimizeBody() {
  const form = $('#optimize-form');
  const bat = page.batForm.request();
  const constraints = readFields(form, 'constraints.');
  if (form.elements.rules.value) constraints.rules = form.elements.rules.value;
  return {
    bat,
    ...page.batForm.scene(),
    variables: optimizeVariables(bat, readValue(form.elements.radius_min), readValue(form.elements.radius_max)),
    constraints,
    objective: form.elements.objective.value,
    options: readFields(form, 'options.'),
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
        'Sweet spot',
        result.sweet_spot?.position_from_knob_m,
        original?.sweet.max_exit_speed.position_from_knob_m,
        'm',
      ),
      row('Exit speed there', result.sweet_spot?.exit_speed_mps, original?.sweet.max_exit_speed.exit_speed_mps, 'm/s'),
      row('Mass', p.mass_kg, o.mass_kg, 'kg'),
      row('Balance point', p.balance_point_m, o.balance_point_m, 'm'),
      row('MOI about 6 in', p.moi_six_inch_kg_m2, o.moi_six_inch_kg_m2, 'kg·m²'),
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

// ---- start ---------------------------------------------------------------

async function start() {
  api.setUnauthorizedHandler(() => {});
  setupTokenForm();
  let presets;
  let materials;
  for (;;) {
    try {
      [presets, materials] = await Promise.all([api.get('/v1/presets'), api.get('/v1/materials')]);
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
  };
  page.batForm = new BatForm($('#bat-form'), page.catalogue);
  page.curve = new CurveChart($('#curve-chart'));
  page.modes = new ModesChart($('#modes-chart'));
  page.variantsChart = new VariantsChart($('#compare-chart'));
  setupBatForm();
  setupVariants();
  setupOptimizeForm();
  await refreshBat();
}

start();
