// The explorer's flight views in a real browser (issue 37, item 3): the batted ball from
// above over a generic field, the carry map as a heat map with the distance sweet spot,
// and the frontier of the best bat at every weight. Debian's chromium (headless, driven by
// playwright-core) against the real sweetspot-server; every number the page shows is
// checked against the API's own answer to the same request, fetched by this test.
//
//   node tests/browser/flight.test.mjs --server build/server/sweetspot-server \
//     --web-root build/server/web --node-modules build/web/npm/node_modules \
//     --artifacts build/browser-artifacts-flight [--chromium /usr/bin/chromium]
//
// ctest runs it as Browser.Flight (tests/CMakeLists.txt).
import assert from 'node:assert/strict';
import {
  GAME,
  GAME_SI,
  apiPost,
  assertNoOverflow,
  download as downloadFrom,
  openPhone,
  revision,
  run,
  setup,
  shot,
  waitForPage,
  waitForRefresh,
} from './harness.mjs';

const harness = setup('flight.test.mjs');
const { artifacts } = harness;

/** The page's opening bat and scene (docs/explorer.md, "What it opens on"). */
const BAT = { preset: 'wood-34-ash' };

/** The batted ball's launch as the page flies it: the batted_ball block of /v1/sweet-spot. */
async function launchOf(url, scene, units) {
  const sweet = await apiPost(url, '/v1/sweet-spot', { bat: BAT, ...scene, outputs: ['batted_ball'], report_units: units });
  assert.equal(sweet.status, 200, JSON.stringify(sweet.body));
  const bb = sweet.body.batted_ball;
  return {
    exit_speed_mps: bb.exit_speed_mps,
    launch_angle_deg: bb.launch_angle_deg,
    backspin_rpm: bb.backspin_rpm,
    sidespin_rpm: bb.sidespin_rpm,
  };
}

/** The landing the view from above shows: {x, y, distance, unit}. */
async function shownLanding(page) {
  return page.evaluate(() => {
    const g = document.querySelector('#flight-top .landing');
    return {
      x: Number(g.dataset.x),
      y: Number(g.dataset.y),
      distance: Number(g.dataset.distance),
      unit: document.querySelector('#flight-top').dataset.unit,
    };
  });
}

/** Types `text` into the input named `name` from the keyboard, then leaves it (Tab: a change). */
async function typeInto(page, name, text) {
  const input = page.locator(`input[name="${name}"]`);
  await input.focus();
  await page.keyboard.press('Control+A');
  await page.keyboard.type(text);
  await page.keyboard.press('Tab');
}

/** Downloads what the button `key` exports; resolves to its file name and text. */
const download = (page, key) => downloadFrom(page, `[data-export="${key}"]`);

/** Every input of the new forms has a label (its own <label> or aria-label). */
async function assertLabelled(page) {
  const unlabelled = await page.evaluate(() =>
    [...document.querySelectorAll('#flight-top-form input, #carry-form input, #frontier-form input')]
      .filter((input) => !input.labels?.length && !input.getAttribute('aria-label'))
      .map((input) => input.name),
  );
  assert.deepEqual(unlabelled, []);
}

const scenarios = [];
const scenario = (name, fn) => scenarios.push({ name, fn });

scenario('the flight from above: a generic field, the API landing point, the spray angle by keyboard', async ({ page, url }) => {
  const response = await page.goto(url);
  assert.equal(response.status(), 200);
  await page.waitForSelector('body[data-state="ready"]', { timeout: 20000 });
  await page.waitForSelector('#flight-top .landing');
  await assertLabelled(page);

  const launch = await launchOf(url, GAME, 'imperial');
  const straight = await apiPost(url, '/v1/flight', { launch, outputs: ['trajectory'], report_units: 'imperial' });
  assert.equal(straight.status, 200, JSON.stringify(straight.body));
  let shown = await shownLanding(page);
  assert.deepEqual(shown, {
    x: straight.body.landing.x_ft,
    y: straight.body.landing.y_ft,
    distance: straight.body.distance_ft,
    unit: 'ft',
  });
  assert.equal(Number(await page.locator('#flight-top').getAttribute('data-points')), straight.body.trajectory.length);
  // The field is drawn and said to be generic; its fence is labelled in feet.
  assert.equal(await page.locator('#flight-top .fence').count(), 1);
  assert.equal(await page.locator('#flight-top .diamond').count(), 1);
  assert.match(await page.locator('#flight-top').textContent(), /400 ft/);
  assert.match(await page.locator('#flight-top-section figcaption').textContent(), /generic outline/);

  // A spray angle the API refuses: its message beside the field, the view dimmed.
  await typeInto(page, 'spray_angle_deg', '200');
  const slot = page.locator('#flight-top-form [data-error-for="launch.spray_angle_deg"]');
  await slot.waitFor({ state: 'visible' });
  assert.match(await slot.textContent(), /^launch\.spray_angle_deg = 200: /);
  assert.equal(await page.locator('input[name="spray_angle_deg"]').getAttribute('aria-invalid'), 'true');
  assert.ok(await page.locator('#flight-top-section.stale').count());

  // 25° toward right field, typed from the keyboard: the landing moves right, to the API's.
  await typeInto(page, 'spray_angle_deg', '25');
  const sprayed = await apiPost(url, '/v1/flight', {
    launch: { ...launch, spray_angle_deg: 25 },
    outputs: ['trajectory'],
    report_units: 'imperial',
  });
  await waitForPage(page, (x) => Number(document.querySelector('#flight-top .landing')?.dataset.x) === x, sprayed.body.landing.x_ft);
  shown = await shownLanding(page);
  assert.equal(shown.y, sprayed.body.landing.y_ft);
  assert.ok(shown.x > 100, `a 25° spray lands toward right field (x = ${shown.x} ft)`);
  assert.match(await page.locator('#flight-top-about').textContent(), /spray angle 25°/);
  assert.match(page.url(), /spray_angle_deg=25/);
  assert.equal(await slot.isVisible(), false);
  assert.equal(await page.locator('#flight-top-section.stale').count(), 0);

  // The exports: the path as CSV (the API's numbers), the view as a standalone SVG.
  const csv = await download(page, 'flight-top-csv');
  assert.equal(csv.name, 'wood-34-ash-flight-above-imperial.csv');
  const lines = csv.text.trim().split('\r\n');
  assert.equal(lines[0], 't (s),toward right field (ft),toward centre field (ft)');
  assert.equal(lines.length, sprayed.body.trajectory.length + 1);
  const last = sprayed.body.trajectory[sprayed.body.trajectory.length - 1];
  assert.deepEqual(lines[lines.length - 1].split(',').map(Number), [last.t_s, last.x_ft, last.y_ft]);
  const svg = await download(page, 'flight-top-svg');
  assert.match(svg.text, /^<\?xml/);
  assert.match(svg.text, /<svg[^>]*xmlns="http:\/\/www\.w3\.org\/2000\/svg"/);
  assert.match(svg.text, /class="landing"/);

  await page.locator('#flight-top-section').scrollIntoViewIfNeeded();
  await shot(page, artifacts, 'flight-01-above');
  await assertNoOverflow(page, 1280);
});

scenario('the carry map: a heat map equal to carry_map, the distance sweet spot, a legend in ft then m', async ({ page, url }) => {
  await page.waitForSelector('#carry-section[data-state="ready"]');
  const body = {
    bat: BAT,
    ...GAME,
    outputs: ['distance_sweet_spot', 'carry_map'],
    options: { distance: { map_positions: 41, map_undercuts: 21 } },
    report_units: 'imperial',
  };
  const answer = await apiPost(url, '/v1/sweet-spot', body);
  assert.equal(answer.status, 200, JSON.stringify(answer.body));
  const map = answer.body.carry_map;
  const spot = answer.body.distance_sweet_spot;
  const shownMap = async () =>
    page.evaluate(() => {
      const svg = document.querySelector('#carry-map');
      const spotMark = svg.querySelector('.spot');
      const legend = svg.querySelector('.legend');
      return {
        positions: Number(svg.dataset.positions),
        undercuts: Number(svg.dataset.undercuts),
        cells: [...svg.querySelectorAll('rect.cell')].map((r) => (r.dataset.value === '' ? null : Number(r.dataset.value))),
        spot: {
          position: Number(spotMark.dataset.position),
          undercut: Number(spotMark.dataset.undercut),
          distance: Number(spotMark.dataset.distance),
        },
        legend: { min: Number(legend.dataset.min), max: Number(legend.dataset.max), unit: legend.dataset.unit, text: legend.textContent },
      };
    });
  let shown = await shownMap();
  assert.equal(shown.positions, 41);
  assert.equal(shown.undercuts, 21);
  // Every cell is the API's carry in feet (null: no carry), position by position.
  assert.deepEqual(shown.cells, map.positions.flatMap((row) => row.distance_ft));
  assert.ok(shown.cells.some((v) => v === null), 'the 2-in undercuts hold misses, drawn grey');
  assert.deepEqual(shown.spot, { position: spot.position_from_knob_in, undercut: spot.undercut_in, distance: spot.distance_ft });
  const carries = shown.cells.filter((v) => v !== null);
  assert.equal(shown.legend.min, Math.min(...carries));
  assert.equal(shown.legend.max, Math.max(...carries));
  assert.equal(shown.legend.unit, 'ft');
  assert.match(shown.legend.text, /carry \(ft\)/);
  assert.match(await page.locator('#carry-map').textContent(), /undercut \(in\)/);
  // The distance sweet spot lies inside the map's ranges, and carries at least the grid's best
  // (it is the search's optimum; 0.1 ft: the flights' default tolerance, docs/api.md).
  assert.ok(spot.distance_ft >= map.best.distance_ft - 0.1);
  assert.match(await page.locator('#carry-about').textContent(), new RegExp(`${spot.distance_ft.toPrecision(4)} ft`));
  // By keyboard: the map takes focus (Tab), the cursor starts at the distance sweet spot's cell,
  // the arrows move it cell by cell and the cell read out is the API's carry there.
  const cursor = async () =>
    page.evaluate(() => {
      const out = document.querySelector('#carry-cell');
      return { i: Number(out.dataset.i), j: Number(out.dataset.j), value: out.dataset.value, text: out.textContent };
    });
  await page.locator('#carry-map').focus();
  assert.equal(await page.evaluate(() => document.activeElement?.id), 'carry-map');
  const home = await cursor();
  const nearest = (list, v) => list.reduce((b, w, k) => (Math.abs(w - v) < Math.abs(list[b] - v) ? k : b), 0);
  assert.equal(home.i, nearest(map.positions.map((r) => r.position_from_knob_in), spot.position_from_knob_in));
  assert.equal(home.j, nearest(map.undercuts_in, spot.undercut_in));
  await page.keyboard.press('ArrowLeft');
  await page.keyboard.press('ArrowLeft');
  await page.keyboard.press('ArrowUp');
  const moved = await cursor();
  assert.deepEqual([moved.i, moved.j], [home.i - 2, home.j + 1]);
  const carry = map.positions[moved.i].distance_ft[moved.j];
  assert.equal(moved.value, carry === null ? '' : String(carry));
  assert.match(moved.text, carry === null ? /no carry/ : / ft$/);
  assert.equal(await page.locator('#carry-map rect.cursor').count(), 1);
  await page.keyboard.press('Home');
  assert.deepEqual([(await cursor()).i, (await cursor()).j], [home.i, home.j]);

  // A bat the API refuses (a negative barrel): the views keep the last valid bat's, dimmed.
  await page.selectOption('select[name="shape"]', 'three_segment');
  await page.waitForSelector('body[data-state="ready"]');
  await typeInto(page, 'barrel_radius_m', '-1');
  await page.waitForSelector('body[data-state="error"]');
  assert.equal(await page.locator('#flight-top-section.stale, #carry-section.stale').count(), 2);
  let fixed = await revision(page);
  await typeInto(page, 'barrel_radius_m', '2.6');
  await waitForRefresh(page, fixed);
  fixed = await revision(page);
  await page.selectOption('select[name="shape"]', 'preset');
  await waitForRefresh(page, fixed);
  assert.doesNotMatch(page.url(), /barrel|shape/);
  await page.waitForSelector('#carry-section[data-state="ready"]');
  assert.equal(await page.locator('#flight-top-section.stale, #carry-section.stale').count(), 0);
  assert.deepEqual((await shownMap()).cells, map.positions.flatMap((row) => row.distance_ft));

  // A coarser grid typed from the keyboard: 21 positions.
  await typeInto(page, 'map_positions', '21');
  await waitForPage(page, () => document.querySelector('#carry-map')?.dataset.positions === '21');
  const coarse = await apiPost(url, '/v1/sweet-spot', {
    ...body,
    options: { distance: { map_positions: 21, map_undercuts: 21 } },
  });
  await page.waitForSelector('#carry-section[data-state="ready"]');
  shown = await shownMap();
  assert.deepEqual(shown.cells, coarse.body.carry_map.positions.flatMap((row) => row.distance_ft));
  const csv = await download(page, 'carry-map-csv');
  const lines = csv.text.trim().split('\r\n');
  assert.equal(lines[0], 'position from the knob (in),undercut (in),carry (ft)');
  assert.equal(lines.length, 21 * 21 + 1);
  const row0 = coarse.body.carry_map.positions[0];
  assert.deepEqual(lines[1].split(',').map(Number), [row0.position_from_knob_in, coarse.body.carry_map.undercuts_in[0], row0.distance_ft[0]]);
  const svg = await download(page, 'carry-map-svg');
  assert.match(svg.text, /<svg[^>]*xmlns/);
  assert.match(svg.text, /linearGradient/);
  await page.locator('#carry-section').scrollIntoViewIfNeeded();
  await shot(page, artifacts, 'flight-02-carry-map-ft');

  // The unit switch, by keyboard: the map and the view from above in metres, the API's SI answers.
  const before = await revision(page);
  await page.locator('input[name="units"][value="imperial"]').focus();
  await page.keyboard.press('ArrowRight');
  await waitForRefresh(page, before);
  await waitForPage(page, () => document.querySelector('#carry-map .legend')?.dataset.unit === 'm');
  await page.waitForSelector('#carry-section[data-state="ready"]');
  const si = await apiPost(url, '/v1/sweet-spot', {
    bat: BAT,
    ...GAME_SI,
    outputs: ['distance_sweet_spot', 'carry_map'],
    options: { distance: { map_positions: 21, map_undercuts: 21 } },
    report_units: 'si',
  });
  shown = await shownMap();
  assert.deepEqual(shown.cells, si.body.carry_map.positions.flatMap((row) => row.distance_m));
  assert.deepEqual(shown.spot, {
    position: si.body.distance_sweet_spot.position_from_knob_m,
    undercut: si.body.distance_sweet_spot.undercut_m,
    distance: si.body.distance_sweet_spot.distance_m,
  });
  assert.match(shown.legend.text, /carry \(m\)/);
  const launch = await launchOf(url, GAME_SI, 'si');
  const flight = await apiPost(url, '/v1/flight', {
    launch: { ...launch, spray_angle_deg: 25 },
    outputs: ['trajectory'],
    report_units: 'si',
  });
  await waitForPage(page, () => document.querySelector('#flight-top')?.dataset.unit === 'm');
  await waitForPage(page, (x) => Number(document.querySelector('#flight-top .landing')?.dataset.x) === x, flight.body.landing.x_m);
  assert.equal((await shownLanding(page)).y, flight.body.landing.y_m);
  assert.match(await page.locator('#flight-top').textContent(), /121\.9 m/);
  await page.locator('#carry-section').scrollIntoViewIfNeeded();
  await shot(page, artifacts, 'flight-03-carry-map-si');

  const back = await revision(page);
  await page.locator('input[name="units"][value="si"]').focus();
  await page.keyboard.press('ArrowLeft');
  await waitForRefresh(page, back);
  await waitForPage(page, () => document.querySelector('#carry-map .legend')?.dataset.unit === 'ft');
});

/** The /v1/jobs requests the page sends (their bodies), recorded from now on. */
function recordJobs(page) {
  const bodies = [];
  page.on('request', (request) => {
    if (request.method() === 'POST' && new URL(request.url()).pathname === '/v1/jobs') bodies.push(request.postDataJSON());
  });
  return bodies;
}

/** Runs the frontier from the keyboard; resolves to the page's request and the states it went through. */
async function runFrontier(page, jobs) {
  const already = jobs.length;
  await page.evaluate(() => {
    window.frontierStates = [];
    new MutationObserver(() => window.frontierStates.push(document.querySelector('#frontier-section').dataset.state)).observe(
      document.querySelector('#frontier-section'),
      { attributes: true, attributeFilter: ['data-state'] },
    );
  });
  await page.locator('#frontier-run').focus();
  await page.keyboard.press('Enter');
  await waitForPage(page, () => window.frontierStates.includes('ready') || window.frontierStates.includes('error'), null, {
    timeout: 60000,
  });
  const states = await page.evaluate(() => window.frontierStates);
  assert.equal(jobs.length, already + 1, 'one job request');
  return { request: jobs[jobs.length - 1], states };
}

/** The points the frontier chart shows. */
async function shownFrontier(page) {
  return page.evaluate(() => ({
    points: [...document.querySelectorAll('#frontier-chart circle.point')].map((c) => ({
      index: Number(c.dataset.index),
      x: Number(c.dataset.x),
      y: Number(c.dataset.y),
      pareto: c.dataset.pareto === 'true',
    })),
    pareto: document.querySelector('#frontier-chart').dataset.pareto,
    text: document.querySelector('#frontier-chart').textContent,
  }));
}

const jobsSeen = [];
scenario('the frontier: the best bat from 28 to 32 oz, run by keyboard, equal to /v1/optimize', async ({ page, url }) => {
  jobsSeen.push(recordJobs(page));
  const { request, states } = await runFrontier(page, jobsSeen[0]);
  assert.ok(states.includes('busy'), `busy while it runs: ${states}`);
  assert.equal(states[states.length - 1], 'ready', `${states}: ${await page.locator('#frontier-form').textContent()}`);
  assert.equal(request.path, '/v1/optimize');
  const body = request.body;
  // The page's defaults: 9 weights from 28 to 32 oz, the optimisation section's problem
  // (its 32-oz mass bound replaced by the frontier's weights), in the trade's units.
  assert.deepEqual(body.frontier, { constraint: 'mass_oz', from: 28, to: 32, count: 9 });
  assert.equal(body.constraints.mass_oz, undefined);
  assert.equal(body.constraints.rules, 'mlb-wood');
  assert.equal(body.objective, 'max_exit_speed');
  assert.equal(body.report_units, 'imperial');
  assert.equal(body.variables.length, 14);

  // The same request by the test's own client: the chart's points are its rows.
  const t0 = Date.now();
  const answer = await apiPost(url, '/v1/optimize', body);
  const seconds = (Date.now() - t0) / 1000;
  assert.equal(answer.status, 200, JSON.stringify(answer.body));
  console.log(`      the frontier of 9 weights answered in ${seconds.toFixed(2)} s`);
  const shown = await shownFrontier(page);
  const rows = answer.body.rows;
  assert.equal(shown.points.length, 9);
  assert.equal(answer.body.summary.termination, 'converged');
  // Same request, same seed, same engine: the same optima. 1e-9 relative: the optimiser's
  // answers are deterministic but the job runs on another thread than the direct request;
  // its tolerances (1e-8 and up) are far above any order-of-operations difference.
  for (const [i, point] of shown.points.entries()) {
    assert.equal(point.index, rows[i].index);
    assert.equal(point.x, rows[i].mass_oz);
    const y = rows[i].sweet_spot.exit_speed_mph;
    assert.ok(Math.abs(point.y - y) <= 1e-9 * y, `weight ${point.x}: ${point.y} vs ${y}`);
  }
  assert.equal(shown.pareto, answer.body.summary.pareto.join(','));
  assert.deepEqual(
    shown.points.filter((p) => p.pareto).map((p) => p.index),
    answer.body.summary.pareto,
  );
  assert.match(shown.text, /weight \(oz\)/);
  assert.match(shown.text, /best exit speed \(mph\)/);
  // A heavier bat swung at the same speed hits harder: the frontier rises (the API's numbers).
  assert.ok(rows[8].sweet_spot.exit_speed_mph > rows[0].sweet_spot.exit_speed_mph);

  const csv = await download(page, 'frontier-csv');
  const lines = csv.text.trim().split('\r\n');
  assert.equal(lines[0], 'index,weight (oz),best exit speed (mph),termination,pareto');
  assert.equal(lines.length, 10);
  assert.equal(Number(lines[1].split(',')[1]), 28);
  const svg = await download(page, 'frontier-svg');
  assert.match(svg.text, /class="pareto"/);
  await page.locator('#frontier-section').scrollIntoViewIfNeeded();
  await shot(page, artifacts, 'flight-04-frontier');
  await assertNoOverflow(page, 1280);

  // A refusal beside its field: fewer than 2 weights.
  await typeInto(page, 'frontier_count', '1');
  await runFrontier(page, jobsSeen[0]);
  const slot = page.locator('#frontier-form [data-error-for="frontier.count"]');
  await slot.waitFor({ state: 'visible' });
  assert.match(await slot.textContent(), /frontier\.count/);
  await typeInto(page, 'frontier_count', '9');

  // Another objective of the optimisation section: the least MOI about the 6-in point, plotted
  // as each row's properties.moi_six_inch_oz_in2 (the API's number in the page's units).
  await page.selectOption('select[name="objective"]', 'min_moi');
  const moiRun = await runFrontier(page, jobsSeen[0]);
  assert.equal(moiRun.states.at(-1), 'ready');
  assert.equal(moiRun.request.body.objective, 'min_moi');
  const moi = await apiPost(url, '/v1/optimize', moiRun.request.body);
  assert.equal(moi.status, 200, JSON.stringify(moi.body));
  const shownMoi = await shownFrontier(page);
  assert.equal(shownMoi.points.length, moi.body.rows.length);
  for (const [i, point] of shownMoi.points.entries()) {
    const y = moi.body.rows[i].properties.moi_six_inch_oz_in2;
    assert.ok(Math.abs(point.y - y) <= 1e-9 * y, `${point.y} vs ${y}`); // 1e-9: as above
  }
  assert.equal(shownMoi.pareto, moi.body.summary.pareto.join(','));
  assert.match(shownMoi.text, /least MOI about 6 in \(oz·in²\)/);
  await page.selectOption('select[name="objective"]', 'max_exit_speed');

  // The unit switch (keyboard) asks the frontier again in SI: its weights in kg (28 and 32 oz
  // written in kg, exactly), its speeds in m/s. (Not the same optima as in ounces: the
  // optimisation section's radius bounds differ between the systems, 0.008-0.034 m against
  // diameters of 0.6-2.61 in.)
  const switchUnits = async (from, key) => {
    await page.evaluate(() => {
      window.frontierStates = [];
    });
    const before = await revision(page);
    await page.locator(`input[name="units"][value="${from}"]`).focus();
    await page.keyboard.press(key);
    await waitForRefresh(page, before);
    await waitForPage(page, () => window.frontierStates.includes('ready') || window.frontierStates.includes('error'), null, {
      timeout: 60000,
    });
    assert.equal((await page.evaluate(() => window.frontierStates)).at(-1), 'ready');
    return jobsSeen[0][jobsSeen[0].length - 1].body;
  };
  const siBody = await switchUnits('imperial', 'ArrowRight');
  assert.deepEqual(siBody.frontier, { constraint: 'mass_kg', from: 0.7937866475, to: 0.90718474, count: 9 });
  assert.equal(siBody.report_units, 'si');
  const si = await apiPost(url, '/v1/optimize', siBody);
  assert.equal(si.status, 200, JSON.stringify(si.body));
  const shownSi = await shownFrontier(page);
  for (const [i, point] of shownSi.points.entries()) {
    const row = si.body.rows[i];
    assert.equal(point.x, row.mass_kg);
    assert.ok(Math.abs(point.y - row.sweet_spot.exit_speed_mps) <= 1e-9 * point.y, `${point.y} vs ${row.sweet_spot.exit_speed_mps}`);
  }
  assert.match(shownSi.text, /weight \(kg\)/);
  assert.match(shownSi.text, /best exit speed \(m\/s\)/);
  await page.locator('#frontier-section').scrollIntoViewIfNeeded();
  await shot(page, artifacts, 'flight-04b-frontier-si');
  const back = await switchUnits('si', 'ArrowLeft');
  assert.equal(back.frontier.constraint, 'mass_oz');
});

scenario('the link restores the flight views and the frontier at a phone width, nothing cut off', async ({ page, url, browser }) => {
  await typeInto(page, 'frontier_to', '31');
  await waitForPage(page, () => window.location.hash.includes('frontier.mass_oz.to=31'));
  const hash = new URL(page.url()).hash;
  assert.match(hash, /spray_angle_deg=25/);
  assert.match(hash, /map_positions=21/);

  const { context: phone, page: small, errors } = await openPhone(browser, `${url}/${hash}`, { acceptDownloads: true });
  assert.equal(await small.locator('input[name="spray_angle_deg"]').inputValue(), '25');
  assert.equal(await small.locator('input[name="map_positions"]').inputValue(), '21');
  assert.equal(await small.locator('input[name="frontier_to"]').inputValue(), '31');
  await small.waitForSelector('#carry-section[data-state="ready"]');
  await waitForPage(small, () => document.querySelector('#carry-map')?.dataset.positions === '21');
  const launch = await launchOf(url, GAME, 'imperial');
  const flight = await apiPost(url, '/v1/flight', {
    launch: { ...launch, spray_angle_deg: 25 },
    outputs: ['trajectory'],
    report_units: 'imperial',
  });
  await waitForPage(small, (x) => Number(document.querySelector('#flight-top .landing')?.dataset.x) === x, flight.body.landing.x_ft);

  const jobs = recordJobs(small);
  const { request, states } = await runFrontier(small, jobs);
  assert.equal(states[states.length - 1], 'ready', String(states));
  assert.deepEqual(request.body.frontier, { constraint: 'mass_oz', from: 28, to: 31, count: 9 });
  const answer = await apiPost(url, '/v1/optimize', request.body);
  const shown = await shownFrontier(small);
  assert.deepEqual(
    shown.points.map((p) => p.x),
    answer.body.rows.map((r) => r.mass_oz),
  );
  await assertNoOverflow(small, 390);
  await shot(small, artifacts, 'flight-05-phone');
  assert.deepEqual(errors, []);
  await phone.close();

  // The first page (imperial, the last weight typed as 31 oz): a switch to SI keeps the typed
  // weight's unit, and the other weight (at its default) stays in ounces with it; the frontier
  // asked again in ounces answers in m/s.
  await page.locator('input[name="units"][value="imperial"]').focus();
  await page.evaluate(() => {
    window.frontierStates = [];
  });
  await page.keyboard.press('ArrowRight');
  await waitForPage(page, () => window.frontierStates.includes('ready') || window.frontierStates.includes('error'), null, {
    timeout: 30000,
  });
  assert.equal((await page.evaluate(() => window.frontierStates)).at(-1), 'ready');
  assert.equal(await page.locator('input[name="frontier_from"]').inputValue(), '28');
  assert.equal(await page.locator('input[name="frontier_from"]').getAttribute('data-field'), 'frontier.mass_oz.from');
  const sent = jobsSeen[0][jobsSeen[0].length - 1].body;
  assert.deepEqual(sent.frontier, { constraint: 'mass_oz', from: 28, to: 31, count: 9 });
  assert.equal(sent.report_units, 'si');
  const again = await apiPost(url, '/v1/optimize', sent);
  const shownMixed = await shownFrontier(page);
  assert.deepEqual(
    shownMixed.points.map((p) => p.x),
    again.body.rows.map((r) => r.mass_oz),
  );
  for (const [i, point] of shownMixed.points.entries()) {
    const y = again.body.rows[i].sweet_spot.exit_speed_mps;
    assert.ok(Math.abs(point.y - y) <= 1e-9 * y, `${point.y} vs ${y}`); // 1e-9: as above
  }
  assert.match(shownMixed.text, /weight \(oz\)/);
  assert.match(shownMixed.text, /\(m\/s\)/);
  // A link with the two weights in two units (both typed): the page says so, sends nothing.
  const before = jobsSeen[0].length;
  await page.evaluate(() => {
    window.location.hash = 'units=si&frontier.mass_oz.from=27&frontier.mass_kg.to=0.9';
  });
  await waitForPage(page, () => document.querySelector('input[name="frontier_to"]').value === '0.9');
  await page.locator('#frontier-run').click();
  const slot = page.locator('#frontier-form [data-error-for="frontier"]');
  await slot.waitFor({ state: 'visible' });
  assert.match(await slot.textContent(), /two units \(from in oz, to in kg\)/);
  assert.equal(jobsSeen[0].length, before);
});

await run(harness, scenarios);
