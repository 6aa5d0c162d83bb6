// Bats side by side in the design explorer (web/src/compare.js), in a real
// browser: Debian's chromium (headless, playwright-core) against the real
// sweetspot-server. Every number the section shows is checked against the
// API's own answer to the same POST /v1/compare, asked by this test directly.
// Screenshots go to --artifacts.
//
//   node tests/browser/compare.test.mjs --server build/server/sweetspot-server \
//     --web-root build/server/web --node-modules build/web/npm/node_modules \
//     --artifacts build/browser-artifacts-compare [--chromium /usr/bin/chromium]
//
// ctest runs it as Browser.Compare (tests/CMakeLists.txt).
import assert from 'node:assert/strict';
import {
  GAME,
  GAME_SI,
  apiPost,
  assertNoOverflow,
  download,
  openPhone,
  run,
  setup,
  shot,
  waitForPage,
} from './harness.mjs';

const harness = setup('compare.test.mjs');
const { artifacts } = harness;

const OUTPUTS = ['max_exit_speed', 'center_of_percussion', 'exit_speed_curve'];
const ALLOY = 'bbcor-33-aluminium';
/** The bats added once the scenarios have added the alloy bat and a copy of the bat above. */
const TWO_ADDED = [
  { name: ALLOY, bat: { preset: ALLOY } },
  { name: 'copy: wood-34-ash', bat: { preset: 'wood-34-ash' } },
];

/** The request the section sends for these bats (the test's own copy of it). */
function compareBody(baseline, variants, { sameBatter = false, units = 'imperial', scene = GAME } = {}) {
  const swing = { ...scene.swing };
  if (sameBatter) swing.speed_model = 'swing_weight';
  return {
    baseline,
    variants,
    ...scene,
    swing,
    outputs: OUTPUTS,
    options: { curve_samples: 121 },
    report_units: units,
  };
}

/** Asks the API; asserts a 200. */
async function compare(url, body) {
  const answer = await apiPost(url, '/v1/compare', body);
  assert.equal(answer.status, 200, JSON.stringify(answer.body));
  return answer.body;
}

/** The value at a dotted path ("swing.bat_speed_mph") of `obj`. */
const at = (obj, path) => path.split('.').reduce((o, k) => (o == null ? undefined : o[k]), obj);

/** The section's refresh counter (data-revision of #bats-state). */
const batsRevision = (page) => page.evaluate(() => Number(document.querySelector('#bats-state').dataset.revision || 0));

/** Waits until the section has finished a refresh newer than `after`, and the page is ready. */
async function waitForBats(page, after) {
  await waitForPage(page, 
    (r) => {
      const state = document.querySelector('#bats-state');
      return (
        Number(state.dataset.revision || 0) > r &&
        state.dataset.state === 'ready' &&
        document.body.dataset.state === 'ready'
      );
    },
    after,
    { timeout: 30000 },
  );
}

/** The table as shown: [{key, path, deltaPath, cells: [{bat, value, delta}]}]. */
function readTable(page) {
  return page.evaluate(() =>
    [...document.querySelectorAll('#bats-table tbody tr')].map((tr) => ({
      key: tr.dataset.key,
      path: tr.dataset.path,
      deltaPath: tr.dataset.deltaPath,
      cells: [...tr.querySelectorAll('td')].map((td) => ({
        bat: td.dataset.bat,
        value: td.dataset.value === '' ? null : Number(td.dataset.value),
        delta: td.dataset.delta === '' ? null : Number(td.dataset.delta),
      })),
    })),
  );
}

/**
 * Every cell of the table equals the API's number at the row's path (the value)
 * and in the bat's `deltas` (the delta); the rows named in `expect` are there.
 */
async function assertTableIsTheApis(page, answer, expect) {
  const table = await readTable(page);
  const keys = table.map((r) => r.key);
  for (const key of expect) assert.ok(keys.includes(key), `the table has no row ${key} (${keys})`);
  for (const row of table) {
    assert.equal(row.cells.length, answer.rows.length, `${row.key}: one cell per bat`);
    row.cells.forEach((cell, i) => {
      const want = at(answer.rows[i], row.path);
      assert.equal(cell.value, typeof want === 'number' ? want : null, `${row.key} of bat ${i} (${row.path})`);
      if (i === 0 || !row.deltaPath) {
        assert.equal(cell.delta, null, `${row.key}: no delta for bat ${i}`);
      } else {
        // The API gives a bat speed's delta only with the swing-weight model: none shown then.
        const delta = at(answer.rows[i], row.deltaPath);
        assert.equal(
          cell.delta,
          typeof delta === 'number' ? delta : null,
          `${row.key}: bat ${i}'s delta (${row.deltaPath})`,
        );
      }
    });
  }
  return table;
}

/** The mode line: {mode, speeds: [{name, value}]}. */
function readMode(page) {
  return page.evaluate(() => {
    const mode = document.querySelector('#bats-mode');
    return {
      mode: mode.dataset.mode,
      text: mode.textContent,
      speeds: [...mode.querySelectorAll('.speed')].map((s) => ({
        name: s.dataset.name,
        value: Number(s.dataset.batSpeed),
      })),
    };
  });
}

/** The chart's series and peaks, and the drawing's lanes. */
function readViews(page) {
  return page.evaluate(() => ({
    series: [...document.querySelectorAll('#bats-curves-svg .series')].map((g) => ({
      bat: g.dataset.bat,
      points: g.querySelector('polyline').getAttribute('points').trim().split(/\s+/).length,
      peak: g.querySelector('.peak') && {
        x: Number(g.querySelector('.peak').dataset.x),
        y: Number(g.querySelector('.peak').dataset.y),
      },
    })),
    legend: [...document.querySelectorAll('#bats-curves-svg .legend-item')].map((g) => g.textContent),
    lanes: [...document.querySelectorAll('#bats-profiles .lane')].map((g) => ({
      bat: g.dataset.bat,
      maxM: Number(g.dataset.maxExitSpeedM),
      bodyWidthPx: g.querySelector('.bat .body')?.getBoundingClientRect().width,
    })),
    listed: [...document.querySelectorAll('#bats-list li')].map((li) => li.dataset.bat),
  }));
}

/** The chart and the drawing show the answer: one series and one lane per bat, each peak the API's. */
async function assertViewsAreTheApis(page, answer, units = 'imperial') {
  const views = await readViews(page);
  const x = units === 'imperial' ? 'position_from_knob_in' : 'position_from_knob_m';
  const y = units === 'imperial' ? 'exit_speed_mph' : 'exit_speed_mps';
  assert.equal(views.series.length, answer.rows.length);
  assert.equal(views.legend.length, answer.rows.length);
  assert.equal(views.lanes.length, answer.rows.length);
  assert.equal(views.listed.length, answer.rows.length);
  answer.rows.forEach((row, i) => {
    assert.equal(views.series[i].points, row.exit_speed_curve.length, `bat ${i}: the curve's points`);
    assert.equal(views.series[i].peak.x, row.max_exit_speed[x], `bat ${i}: the peak's position`);
    assert.equal(views.series[i].peak.y, row.max_exit_speed[y], `bat ${i}: the peak's exit speed`);
    assert.equal(views.lanes[i].maxM, row.max_exit_speed.position_from_knob_m, `bat ${i}: the drawing's mark`);
  });
  // One scale for every lane: the bodies' drawn widths are as the bats' lengths (the API's). The
  // widths are whole-path boxes of 800-odd drawing units rendered at > 1 px per 2 units, so 0.5 %
  // holds them to a pixel or two; a lane drawn at its own scale would be off by the lengths' ratio.
  const lengths = answer.rows.map((r) => r.properties.length_m);
  for (let i = 1; i < lengths.length; ++i) {
    const drawn = views.lanes[i].bodyWidthPx / views.lanes[0].bodyWidthPx;
    const real = lengths[i] / lengths[0];
    assert.ok(Math.abs(drawn / real - 1) < 0.005, `lane ${i}: drawn ${drawn}, lengths ${real}`);
  }
  return views;
}

const scenarios = [];
const scenario = (name, fn) => scenarios.push({ name, fn });

scenario(
  'a preset added by keyboard beside the bat above: same bat speed, in inches and mph',
  async ({ page, url }) => {
    await page.goto(url);
    await page.waitForSelector('body[data-state="ready"]', { timeout: 20000 });
    await waitForPage(page, () => document.querySelector('#bats-state').dataset.state === 'ready', null, {
      timeout: 20000,
    });
    assert.equal(await page.locator('#bats-views').isHidden(), true, 'no views before a bat is added');
    // Labelled controls: the list, the switch, every button says what it does.
    assert.equal(await page.locator('#bats-add-choice').evaluate((s) => s.labels.length), 1);
    assert.equal(await page.locator('#bats-same-batter').evaluate((s) => s.labels.length), 1);
    // Keyboard only: the list offers the alloy bat first (alloy against wood), Tab to "Add", Enter.
    assert.equal(await page.locator('#bats-add-choice').inputValue(), ALLOY);
    await page.focus('#bats-add-choice');
    const before = await batsRevision(page);
    await page.keyboard.press('Tab');
    assert.equal(await page.evaluate(() => document.activeElement.id), 'bats-add');
    await page.keyboard.press('Enter');
    await waitForBats(page, before);

    const answer = await compare(
      url,
      compareBody({ preset: 'wood-34-ash' }, [{ name: ALLOY, bat: { preset: ALLOY } }]),
    );
    await assertTableIsTheApis(page, answer, [
      'bat_speed',
      'max_exit_speed',
      'max_exit_speed_position',
      'mass',
      'balance_point',
      'moi_six_inch',
    ]);
    const table = await readTable(page);
    assert.equal(table.find((r) => r.key === 'mass').path, 'properties.mass_oz', 'the mass in ounces');
    assert.equal(table.find((r) => r.key === 'mass').cells[1].delta, answer.rows[1].deltas.mass_oz);
    assert.equal(
      table.find((r) => r.key === 'max_exit_speed').cells[1].delta,
      answer.rows[1].deltas.max_exit_speed_mph,
    );
    assert.equal(
      table.find((r) => r.key === 'bat_speed').cells[1].delta,
      null,
      'no bat-speed delta at a fixed bat speed',
    );
    assert.equal(table.find((r) => r.key === 'max_exit_speed').deltaPath, 'deltas.max_exit_speed_mph');
    const mode = await readMode(page);
    assert.equal(mode.mode, 'same_bat_speed');
    assert.match(mode.text, /^Mode: same bat speed\. swing\.speed_model "fixed"/);
    assert.deepEqual(
      mode.speeds.map((s) => s.value),
      answer.rows.map((r) => r.swing.bat_speed_mph),
    );
    assert.deepEqual(
      mode.speeds.map((s) => s.value),
      [70, 70],
      'both bats at the 70 mph given',
    );
    const views = await assertViewsAreTheApis(page, answer);
    assert.match(views.legend[1], new RegExp(`^${ALLOY}: max `));
    await assertNoOverflow(page, 1280);
    await page.locator('#bats-section').screenshot({ path: `${artifacts}/compare-01-section.png` });
    await shot(page, artifacts, 'compare-01-two-bats');
  },
);

scenario(
  '"same batter" switched on by keyboard: the swing-weight model, each bat speed the API\'s',
  async ({ page, url }) => {
    const before = await batsRevision(page);
    await page.focus('#bats-same-batter');
    await page.keyboard.press('Space');
    await waitForBats(page, before);
    assert.equal(await page.locator('#bats-same-batter').isChecked(), true);

    const answer = await compare(
      url,
      compareBody({ preset: 'wood-34-ash' }, [{ name: ALLOY, bat: { preset: ALLOY } }], { sameBatter: true }),
    );
    const mode = await readMode(page);
    assert.equal(mode.mode, 'same_batter');
    assert.match(mode.text, /^Mode: same batter\. swing\.speed_model "swing_weight".*Cross & Bower/);
    assert.match(mode.text, /wood-34-ash/, 'the reference bat named');
    assert.deepEqual(
      mode.speeds.map((s) => s.value),
      answer.rows.map((r) => r.swing.bat_speed_mph),
    );
    // The alloy bat is lighter to swing: the batter swings it faster than the 70 mph given.
    assert.equal(mode.speeds[0].value, 70);
    assert.ok(mode.speeds[1].value > 70, `${mode.speeds[1].value}`);
    const table = await assertTableIsTheApis(page, answer, ['bat_speed', 'max_exit_speed']);
    assert.equal(table.find((r) => r.key === 'bat_speed').cells[1].delta, answer.rows[1].deltas.bat_speed_mph);
    await assertViewsAreTheApis(page, answer);
    assert.match(page.url(), /cmp\.same_batter=on/);
    await assertNoOverflow(page, 1280);
    await shot(page, artifacts, 'compare-02-same-batter');
  },
);

scenario(
  'a copy of the bat above, then the bat above changed: three bats, and every view exported',
  async ({ page, url }) => {
    let before = await batsRevision(page);
    await page.selectOption('#bats-add-choice', '@current');
    await page.click('#bats-add');
    await waitForBats(page, before);
    before = await batsRevision(page);
    await page.selectOption('select[name="material"]', 'hard-maple');
    await waitForBats(page, before);

    const variants = TWO_ADDED;
    const answer = await compare(
      url,
      compareBody({ preset: 'wood-34-ash', material: 'hard-maple' }, variants, { sameBatter: true }),
    );
    await assertTableIsTheApis(page, answer, ['bat_speed', 'max_exit_speed', 'mass']);
    const views = await assertViewsAreTheApis(page, answer);
    assert.deepEqual(views.listed.slice(1), [ALLOY, 'copy: wood-34-ash']);
    const mode = await readMode(page);
    assert.deepEqual(
      mode.speeds.map((s) => s.value),
      answer.rows.map((r) => r.swing.bat_speed_mph),
    );

    // The curves' CSV: the header names each bat, and every row is the API's curve point.
    const csv = await download(page, '[data-bats-export="curves-csv"]');
    assert.match(csv.name, /^bats-same-batter-exit-speed-imperial\.csv$/);
    const lines = csv.text.trim().split('\r\n');
    assert.equal(
      lines[0],
      'position from the knob (in),the bat above (wood-34-ash): exit speed (mph),bbcor-33-aluminium: exit speed (mph),copy: wood-34-ash: exit speed (mph)',
    );
    const byX = new Map(lines.slice(1).map((line) => [Number(line.split(',')[0]), line.split(',').slice(1)]));
    answer.rows.forEach((row, i) => {
      for (const p of row.exit_speed_curve) {
        assert.equal(
          Number(byX.get(p.position_from_knob_in)[i]),
          p.exit_speed_mph,
          `bat ${i} at ${p.position_from_knob_in} in`,
        );
      }
    });
    // The chart as SVG: a standalone file with the three curves and the legend.
    const curves = await download(page, '[data-bats-export="curves-svg"]');
    assert.match(curves.text, /^<\?xml/);
    assert.match(curves.text, /xmlns="http:\/\/www\.w3\.org\/2000\/svg"/);
    assert.equal((curves.text.match(/<polyline/g) || []).length, 3);
    for (const name of ['the bat above (wood-34-ash)', ALLOY, 'copy: wood-34-ash'])
      assert.ok(curves.text.includes(name), name);
    // The profiles as SVG (three lanes) and as CSV (each bat's knots, a preset's as GET /v1/presets gives them).
    const profiles = await download(page, '[data-bats-export="profiles-svg"]');
    assert.equal((profiles.text.match(/class="lane"/g) || []).length, 3);
    const presets = (await (await fetch(`${url}/v1/presets`)).json()).presets;
    const alloyKnots = presets.find((p) => p.name === ALLOY).bat.profile.knots;
    const knots = (await download(page, '[data-bats-export="profiles-csv"]')).text.trim().split('\r\n');
    assert.equal(knots[0], 'bat,knot,x from the knob (m),radius (m),wall (m; 0: solid)');
    const alloyRows = knots.filter((line) => line.startsWith(`${ALLOY},`));
    assert.equal(alloyRows.length, alloyKnots.length);
    alloyRows.forEach((line, j) => {
      const [, knot, x, r] = line.split(',');
      assert.equal(Number(knot), j);
      assert.equal(Number(x), alloyKnots[j].x_m);
      assert.equal(Number(r), alloyKnots[j].radius_m);
    });
    // The numbers' CSV: one row per bat, each value and delta the API's.
    const numbers = (await download(page, '[data-bats-export="table-csv"]')).text.trim().split('\r\n');
    assert.equal(numbers.length, 4);
    const header = numbers[0].split(',');
    const alloy = numbers[2].split(',');
    assert.equal(alloy[0], ALLOY);
    assert.equal(Number(alloy[header.indexOf('Mass: delta from the bat above (oz)')]), answer.rows[1].deltas.mass_oz);
    assert.equal(Number(alloy[header.indexOf('Bat speed (mph)')]), answer.rows[1].swing.bat_speed_mph);
    assert.equal(
      Number(alloy[header.indexOf('Max exit speed: delta from the bat above (mph)')]),
      answer.rows[1].deltas.max_exit_speed_mph,
    );
    await assertNoOverflow(page, 1280);
    await shot(page, artifacts, 'compare-03-three-bats');
  await page.locator('#bats-section').screenshot({ path: `${artifacts}/compare-03-section.png` });
  },
);

scenario(
  'the link restores the bats and the switch on a 390-px phone, nothing cut off',
  async ({ page, url, browser }) => {
    const hash = new URL(page.url()).hash;
    assert.match(hash, /cmp\.bat=/);
    const { context: phone, page: small, errors } = await openPhone(browser, `${url}/${hash}`, { hasTouch: true });
    await waitForBats(small, 0);
    assert.equal(await small.locator('#bats-same-batter').isChecked(), true);
    const variants = TWO_ADDED;
    const answer = await compare(
      url,
      compareBody({ preset: 'wood-34-ash', material: 'hard-maple' }, variants, { sameBatter: true }),
    );
    await assertTableIsTheApis(small, answer, ['bat_speed', 'max_exit_speed']);
    await assertViewsAreTheApis(small, answer);
    // The chart is drawn at the phone's width, its legend inside it.
    const chart = await small.evaluate(() => {
      const svg = document.querySelector('#bats-curves-svg');
      const box = svg.getBoundingClientRect();
      const texts = [...svg.querySelectorAll('text')].map((t) => t.getBoundingClientRect());
      return {
        right: box.right,
        left: box.left,
        textRight: Math.max(...texts.map((r) => r.right)),
        textLeft: Math.min(...texts.map((r) => r.left)),
      };
    });
    assert.ok(chart.right <= 390, `chart ends at ${chart.right}`);
    assert.ok(
      chart.textRight <= chart.right + 0.5 && chart.textLeft >= chart.left - 0.5,
      `a label past the chart's edge: ${JSON.stringify(chart)}`,
    );
    await assertNoOverflow(small, 390);
    await shot(small, artifacts, 'compare-04-phone');
    await small.locator('#bats-section').screenshot({ path: `${artifacts}/compare-04-phone-section.png` });
    assert.deepEqual(errors, []);
    await phone.close();
  },
);

scenario('the unit switch: the same bats in SI, then a bat removed by keyboard', async ({ page, url }) => {
  let before = await batsRevision(page);
  await page.check('input[name="units"][value="si"]');
  await waitForBats(page, before);
  const variants = TWO_ADDED;
  const answer = await compare(
    url,
    compareBody({ preset: 'wood-34-ash', material: 'hard-maple' }, variants, {
      sameBatter: true,
      units: 'si',
      scene: GAME_SI,
    }),
  );
  const table = await assertTableIsTheApis(page, answer, ['bat_speed', 'max_exit_speed', 'mass']);
  assert.equal(table.find((r) => r.key === 'mass').path, 'properties.mass_kg');
  assert.equal(table.find((r) => r.key === 'mass').deltaPath, 'deltas.mass_kg');
  await assertViewsAreTheApis(page, answer, 'si');
  const mode = await readMode(page);
  assert.deepEqual(
    mode.speeds.map((s) => s.value),
    answer.rows.map((r) => r.swing.bat_speed_mps),
  );
  assert.match(mode.text, /m\/s/);
  await shot(page, artifacts, 'compare-05-si');

  before = await batsRevision(page);
  await page.focus(`#bats-list button[aria-label="Remove ${ALLOY}"]`);
  await page.keyboard.press('Enter');
  await waitForBats(page, before);
  const two = await compare(
    url,
    compareBody({ preset: 'wood-34-ash', material: 'hard-maple' }, [variants[1]], {
      sameBatter: true,
      units: 'si',
      scene: GAME_SI,
    }),
  );
  await assertTableIsTheApis(page, two, ['bat_speed', 'mass']);
  await assertViewsAreTheApis(page, two, 'si');
  assert.ok(!page.url().includes(ALLOY), 'the link forgets the removed bat');
});

scenario('"same batter" without a bat speed: the API\'s message beside the switch', async ({ page }) => {
  let before = await batsRevision(page);
  const revision = await page.evaluate(() => Number(document.body.dataset.revision || 0));
  await page.fill('input[name="bat_speed_mps"]', '');
  await waitForPage(page, (r) => Number(document.body.dataset.revision || 0) > r, revision, { timeout: 20000 });
  const slot = page.locator('#bats-form [data-error-for="swing"]');
  await slot.waitFor({ state: 'visible', timeout: 20000 });
  assert.match(await slot.textContent(), /^swing\.speed_model = swing_weight: needs swing\.bat_speed_mps/);
  assert.equal(await page.locator('#bats-section').evaluate((s) => s.classList.contains('stale')), true);
  await shot(page, artifacts, 'compare-06-refused');
  // Off: every bat at the same angular speed (no bat speed given), the message gone.
  before = await batsRevision(page);
  await page.focus('#bats-same-batter');
  await page.keyboard.press('Space');
  await waitForBats(page, before);
  assert.equal(await slot.isHidden(), true);
  assert.equal((await readMode(page)).mode, 'same_bat_speed');
});

scenario('a link naming a bat the API does not know: its message beside that bat', async ({ page, url }) => {
  await page.goto(`${url}/#cmp.bat=no-such-bat`);
  await page.waitForSelector('body[data-state="ready"]', { timeout: 20000 });
  const slot = page.locator('#bats-list [data-error-for="bats:0"]');
  await slot.waitFor({ state: 'visible', timeout: 20000 });
  const answer = await apiPost(
    url,
    '/v1/compare',
    compareBody({ preset: 'wood-34-ash' }, [{ name: 'no-such-bat', bat: { preset: 'no-such-bat' } }]),
  );
  assert.equal(answer.status, 400);
  assert.equal(await slot.textContent(), `${answer.body.message} (${answer.body.code})`);
  await shot(page, artifacts, 'compare-07-unknown-bat');
  // Removed, the section is back to the bat above alone.
  const before = await batsRevision(page);
  await page.click('#bats-list button[aria-label="Remove no-such-bat"]');
  await waitForBats(page, before);
  assert.equal(await page.locator('#bats-views').isHidden(), true);
  assert.equal(await slot.count(), 0);
});

await run(harness, scenarios);
