// The design explorer in a real browser: Debian's chromium (headless, driven
// by playwright-core) against the real sweetspot-server on 127.0.0.1 with an
// ephemeral port. Every value the page shows is checked against the API's own
// answer to the same request. Screenshots go to --artifacts.
//
//   node tests/browser/explorer.test.mjs --server build/server/sweetspot-server \
//     --web-root build/server/web --node-modules build/web/npm/node_modules \
//     --artifacts build/browser-artifacts [--chromium /usr/bin/chromium]
//
// ctest runs it as Browser.Explorer (tests/CMakeLists.txt). Exit status 0 when
// every scenario passed.
import assert from 'node:assert/strict';
import path from 'node:path';
import {
  GAME,
  GAME_SI,
  apiPost,
  assertNoOverflow,
  download,
  openPhone,
  revision,
  run,
  setup,
  shot,
  waitForRefresh,
} from './harness.mjs';

const harness = setup('explorer.test.mjs');
const { artifacts } = harness;

const TOKEN = 'browser-test-token-0123456789';

// ---- the scenarios ---------------------------------------------------------

const SWEET = ['max_exit_speed', 'center_of_percussion', 'vibration_node', 'sweet_zone', 'exit_speed_curve'];
/** What the page asks /v1/sweet-spot for (the markers' outputs and the headline's). */
const PAGE_OUTPUTS = [...SWEET, 'bbcor', 'barrel', 'batted_ball'];
/** The state the scenarios after the game-condition ones start from: the paper's bat, SI, the API's scene. */
const PAPER_HASH =
  '#units=si&preset=paper-wood&ball_preset=&ball.speed_mps=&swing.bat_speed_mps=&descent_angle_deg=&attack_angle_deg=&contact.undercut_m=';

async function markerOf(page, key) {
  const mark = page.locator(`#curve-chart .u-mark[data-marker="${key}"]`);
  await mark.waitFor({ state: 'attached' });
  return {
    positionM: Number(await mark.getAttribute('data-position-m')),
    xPx: Number(await mark.getAttribute('data-x-px')),
  };
}

/** The headline's items: key -> {value (the API number it shows), path, text}. */
async function headline(page) {
  return page.evaluate(() =>
    Object.fromEntries(
      [...document.querySelectorAll('#headline-values .item')].map((item) => [
        item.dataset.key,
        { value: item.dataset.value === '' ? null : Number(item.dataset.value), path: item.dataset.path, text: item.textContent },
      ]),
    ),
  );
}

const scenarios = [];
const scenario = (name, fn) => scenarios.push({ name, fn });

scenario('opens at game conditions: a real bat, mlb at 90 mph, 70 mph bat speed, in inches and mph', async ({ page, url }) => {
  const response = await page.goto(url);
  assert.equal(response.status(), 200);
  await page.waitForSelector('body[data-state="ready"]', { timeout: 20000 });
  assert.equal(await page.locator('select[name="preset"]').inputValue(), 'wood-34-ash');
  assert.equal(await page.locator('select[name="ball_preset"]').inputValue(), 'mlb');
  assert.equal(await page.locator('input[name="ball_speed_mps"]').inputValue(), '90');
  assert.equal(await page.locator('input[name="ball_speed_mps"]').getAttribute('data-field'), 'ball.speed_mph');
  assert.equal(await page.locator('input[name="bat_speed_mps"]').inputValue(), '70');
  assert.equal(await page.locator('input[name="bat_speed_mps"]').getAttribute('data-field'), 'swing.bat_speed_mph');
  assert.equal(await page.locator('input[name="units"][value="imperial"]').isChecked(), true);

  const bat = { preset: 'wood-34-ash' };
  const body = { bat, ...GAME, outputs: PAGE_OUTPUTS, options: { curve_samples: 121 }, report_units: 'imperial' };
  const sweet = await apiPost(url, '/v1/sweet-spot', body);
  assert.equal(sweet.status, 200, JSON.stringify(sweet.body));
  const h = await headline(page);
  assert.equal(h.sweet_spot.value, sweet.body.max_exit_speed.position_from_tip_in);
  assert.match(h.sweet_spot.text, / in from the tip/);
  assert.equal(h.exit_speed.value, sweet.body.max_exit_speed.exit_speed_mph);
  assert.match(h.exit_speed.text, / mph/);
  assert.equal(h.bbcor.value, sweet.body.bbcor.value);
  assert.equal(h.carry.value, sweet.body.batted_ball.distance_ft);
  assert.match(h.carry.text, / ft/);
  assert.equal(h.hoop_frequency, undefined, 'a solid wood bat has no hoop mode');
  assert.equal(sweet.body.barrel.hollow, false);
  // The curve in inches and mph, its markers at the API's positions.
  assert.equal((await markerOf(page, 'max_exit_speed')).positionM, sweet.body.max_exit_speed.position_from_knob_m);
  assert.match(await page.locator('#curve-chart').textContent(), /exit speed \(mph\)/);
  const properties = await apiPost(url, '/v1/bat/properties', { bat, report_units: 'imperial' });
  assert.equal(
    Number(await page.locator('#properties tr[data-key="mass_kg"] td[data-imperial]').getAttribute('data-imperial')),
    properties.body.imperial.weight_oz,
  );
  // The bending modes in inches too: the axis, the nodes' text in the API's inch twins, and each
  // node's dot at the API's position (its metres kept in data-position-m).
  const modes = await apiPost(url, '/v1/bat/modes', { bat, modes: 2, shape_samples: 81, report_units: 'imperial' });
  assert.equal(modes.status, 200, JSON.stringify(modes.body));
  assert.equal(await page.locator('#modes-chart').getAttribute('data-x-unit'), 'in');
  const first = modes.body.modes[0];
  assert.match(
    await page.locator('#modes-about').textContent(),
    new RegExp(`nodes at ${first.nodes_from_knob_in.map((x) => Number(x.toPrecision(3))).join(', ')} in`),
  );
  assert.equal(
    Number(await page.locator('#modes-chart .u-node[data-mode="1"]').first().getAttribute('data-position-m')),
    first.nodes_from_knob_m[0],
  );
  // The flight from the side: /v1/flight at the batted ball's launch, as the test asks it.
  const bb = sweet.body.batted_ball;
  const flight = await apiPost(url, '/v1/flight', {
    launch: {
      exit_speed_mps: bb.exit_speed_mps,
      launch_angle_deg: bb.launch_angle_deg,
      backspin_rpm: bb.backspin_rpm,
      sidespin_rpm: bb.sidespin_rpm,
    },
    outputs: ['trajectory'],
    report_units: 'imperial',
  });
  assert.equal(flight.status, 200, JSON.stringify(flight.body));
  await page.waitForSelector('#flight-chart[data-points]');
  assert.equal(Number(await page.locator('#flight-chart').getAttribute('data-distance')), flight.body.distance_ft);
  assert.equal(Number(await page.locator('#flight-chart').getAttribute('data-points')), flight.body.trajectory.length);
  // The same flight as the batted_ball block's: both integrate to the flight's default
  // tolerance (the landing within 0.1 ft, docs/api.md), so the carries agree within 0.2 ft.
  assert.ok(Math.abs(flight.body.distance_ft - bb.distance_ft) < 0.2, `${flight.body.distance_ft} vs ${bb.distance_ft}`);
  assert.match(await page.locator('#flight-chart').textContent(), /height \(ft\)/);

  // Keyboard: the unit switch is a labelled radio group reached with Tab and changed with arrows.
  await page.locator('input[name="units"][value="imperial"]').focus();
  assert.equal(await page.evaluate(() => document.activeElement.closest('fieldset')?.querySelector('legend')?.textContent), 'Units');
  for (const control of await page.locator('#bat-form input, #bat-form select').all()) {
    const id = await control.evaluate((e) => e.name);
    assert.ok(await control.evaluate((e) => Boolean(e.labels?.length || e.getAttribute('aria-label'))), `${id} has no label`);
  }
  // The variants' table and the drawing's axis in the trade's units too: the baseline's mass is
  // the properties' own mass_oz (one bat, one answer), the axis in inches.
  await page.waitForSelector('#compare-table[data-variants]');
  assert.equal(
    Number(await page.locator('#compare-table tbody tr:first-child td').first().getAttribute('data-value')),
    properties.body.mass_oz,
  );
  assert.match(await page.locator('#compare-table tbody tr:first-child th').textContent(), /Mass oz/);
  assert.match(await page.locator('#bat-drawing .axis').textContent(), /in from the knob/);
  await assertNoOverflow(page, 1280);
  await shot(page, artifacts, '00-game-conditions');

  // The optimisation in the trade's units: diameters in inches, the mass at most 32 oz.
  await page.click('#optimize-run');
  await page.waitForSelector('#optimize-state[data-state="done"]', { timeout: 60000 });
  const id = await page.locator('#optimize-state').getAttribute('data-job-id');
  const result = await (await fetch(`${url}/v1/jobs/${id}/result`)).json();
  assert.equal(result.summary.termination, 'converged', result.summary.message);
  assert.equal(Object.keys(result.variables).length, 14); // one per knot of wood-34-ash
  assert.ok(Object.keys(result.variables).every((k) => k.endsWith('.diameter_in')), Object.keys(result.variables).join());
  assert.ok(result.properties.mass_oz <= 32 + 1e-6, `mass ${result.properties.mass_oz} oz over the 32 oz bound`);
  const massRow = page.locator('#optimize-result tbody tr', { hasText: 'Mass' });
  assert.equal(Number(await massRow.locator('td').first().getAttribute('data-value')), result.properties.mass_oz);
  assert.match(await massRow.textContent(), / oz/);

  // A hollow bat: its barrel's hoop frequency and THE BBCOR, as the API gives them.
  const rev = await revision(page);
  await page.selectOption('select[name="preset"]', 'bbcor-33-aluminium');
  await waitForRefresh(page, rev);
  const alloy = await apiPost(url, '/v1/sweet-spot', { ...body, bat: { preset: 'bbcor-33-aluminium' } });
  assert.equal(alloy.status, 200, JSON.stringify(alloy.body));
  assert.equal(alloy.body.barrel.hollow, true);
  const ha = await headline(page);
  assert.equal(ha.hoop_frequency.value, alloy.body.barrel.hoop_frequency_hz);
  assert.match(ha.hoop_frequency.text, / Hz/);
  assert.equal(ha.bbcor.value, alloy.body.bbcor.value);
  assert.equal(ha.carry.value, alloy.body.batted_ball.distance_ft);
  await shot(page, artifacts, '00b-hollow-bat');

  // A refused trade-unit input: the API names the field as written (ball.speed_mph), and its
  // message is shown beside that input.
  const good = await revision(page);
  await page.fill('input[name="ball_speed_mps"]', '-10');
  await page.press('input[name="ball_speed_mps"]', 'Tab');
  const slot = page.locator('[data-error-for="ball.speed_mph"]');
  await slot.waitFor({ state: 'visible', timeout: 20000 });
  const refused = await apiPost(url, '/v1/sweet-spot', {
    ...body,
    bat: { preset: 'bbcor-33-aluminium' },
    ball: { ...GAME.ball, speed_mph: -10 },
  });
  assert.equal(refused.status, 400);
  assert.equal(refused.body.field, 'ball.speed_mph');
  assert.equal(await slot.textContent(), `${refused.body.message} (${refused.body.code})`);
  await page.fill('input[name="ball_speed_mps"]', '90');
  await page.press('input[name="ball_speed_mps"]', 'Tab');
  await waitForRefresh(page, good);
  assert.equal(await slot.isVisible(), false);
});

scenario('the unit switch: SI inputs and answers, a link that restores them, CSV, a phone width', async ({ page, url, browser }) => {
  const rev = await revision(page);
  await page.locator('input[name="units"][value="imperial"]').focus();
  await page.keyboard.press('ArrowRight'); // the keyboard's way to the next radio of the group
  await waitForRefresh(page, rev);
  assert.equal(await page.locator('input[name="units"][value="si"]').isChecked(), true);
  assert.equal(await page.locator('input[name="ball_speed_mps"]').inputValue(), '40.2336');
  assert.equal(await page.locator('input[name="ball_speed_mps"]').getAttribute('data-field'), 'ball.speed_mps');
  assert.equal(await page.locator('input[name="bat_speed_mps"]').inputValue(), '31.2928');
  const bat = { preset: 'bbcor-33-aluminium' };
  const si = await apiPost(url, '/v1/sweet-spot', {
    bat,
    ...GAME_SI,
    outputs: PAGE_OUTPUTS,
    options: { curve_samples: 121 },
    report_units: 'si',
  });
  assert.equal(si.status, 200, JSON.stringify(si.body));
  const h = await headline(page);
  assert.equal(h.sweet_spot.value, si.body.max_exit_speed.position_from_knob_m);
  assert.match(h.sweet_spot.text, / m from the knob/);
  assert.equal(h.exit_speed.value, si.body.max_exit_speed.exit_speed_mps);
  assert.match(h.exit_speed.text, / m\/s/);
  assert.equal(h.carry.value, si.body.batted_ball.distance_m);
  assert.equal(h.hoop_frequency.value, si.body.barrel.hoop_frequency_hz);
  // The same conditions in either unit: 90 mph is 40.2336 m/s exactly, so the two answers agree
  // to the rounding of the factor's product (a few ulps; 1e-9 relative is ample).
  const imperial = await apiPost(url, '/v1/sweet-spot', { bat, ...GAME, outputs: ['max_exit_speed'] });
  const rel = Math.abs(imperial.body.max_exit_speed.exit_speed_mps / si.body.max_exit_speed.exit_speed_mps - 1);
  assert.ok(rel < 1e-9, `exit speed differs by ${rel} between the units`);

  // The curve's CSV is what the chart shows: the API's curve in SI.
  const csv = (await download(page, '[data-export="curve-csv"]')).text.trim().split('\r\n');
  assert.equal(csv[0], 'position from the knob (m),exit speed (m/s)');
  assert.equal(csv.length, 122);
  assert.deepEqual(csv[61].split(',').map(Number), [
    si.body.exit_speed_curve[60].position_from_knob_m,
    si.body.exit_speed_curve[60].exit_speed_mps,
  ]);
  assert.match((await download(page, '[data-export="bat-drawing-svg"]')).text, /<svg[^>]*xmlns="http:\/\/www.w3.org\/2000\/svg"/);

  // The link restores the page: units and inputs, at a phone's width, nothing cut off.
  const hash = new URL(page.url()).hash;
  assert.match(hash, /units=si/);
  assert.match(hash, /preset=bbcor-33-aluminium/);
  const { context: phone, page: small } = await openPhone(browser, `${url}/${hash}`);
  assert.equal(await small.locator('input[name="units"][value="si"]').isChecked(), true);
  assert.equal(await small.locator('select[name="preset"]').inputValue(), 'bbcor-33-aluminium');
  assert.equal((await headline(small)).sweet_spot.value, si.body.max_exit_speed.position_from_knob_m);
  await assertNoOverflow(small, 390);
  await shot(small, artifacts, '00c-phone-si');
  await phone.close();

  // Another link in the same tab: everything it does not name goes back to the defaults.
  const before = await revision(page);
  await page.evaluate(() => {
    window.location.hash = '#units=imperial&preset=paper-wood';
  });
  await waitForRefresh(page, before);
  assert.equal(await page.locator('input[name="units"][value="imperial"]').isChecked(), true);
  assert.equal(await page.locator('select[name="preset"]').inputValue(), 'paper-wood');
  assert.equal(await page.locator('input[name="ball_speed_mps"]').inputValue(), '90');
  const paper = await apiPost(url, '/v1/sweet-spot', {
    bat: { preset: 'paper-wood' },
    ...GAME,
    outputs: ['max_exit_speed'],
    report_units: 'imperial',
  });
  assert.equal((await headline(page)).exit_speed.value, paper.body.max_exit_speed.exit_speed_mph);
});

scenario('load the page: bat, properties, curve with markers, modes, variants', async ({ page, url }) => {
  await page.goto('about:blank');
  const response = await page.goto(`${url}/${PAPER_HASH}`);
  assert.equal(response.status(), 200);
  assert.match(response.headers()['content-type'], /^text\/html/);
  await page.waitForSelector('body[data-state="ready"]', { timeout: 20000 });
  assert.equal(await page.title(), 'sweetspot — bat design explorer');
  assert.equal(await page.locator('select[name="preset"]').inputValue(), 'paper-wood');

  const bat = { preset: 'paper-wood' };
  const properties = await apiPost(url, '/v1/bat/properties', { bat });
  assert.equal(properties.status, 200);
  assert.equal(
    Number(await page.locator('#properties tr[data-key="mass_kg"] td[data-si]').getAttribute('data-si')),
    properties.body.mass_kg,
  );
  assert.equal(
    Number(await page.locator('#properties tr[data-key="mass_kg"] td[data-imperial]').getAttribute('data-imperial')),
    properties.body.imperial.weight_oz,
  );

  const sweet = await apiPost(url, '/v1/sweet-spot', { bat, outputs: SWEET, options: { curve_samples: 121 } });
  assert.equal(sweet.status, 200);
  assert.equal((await markerOf(page, 'max_exit_speed')).positionM, sweet.body.max_exit_speed.position_from_knob_m);
  assert.equal(
    (await markerOf(page, 'center_of_percussion')).positionM,
    sweet.body.center_of_percussion.position_from_knob_m,
  );
  assert.equal((await markerOf(page, 'vibration_node')).positionM, sweet.body.vibration_node.position_from_knob_m);
  const zone = page.locator('#curve-chart .u-zone');
  assert.equal(Number(await zone.getAttribute('data-from-m')), sweet.body.sweet_zone.from_knob_m);
  assert.equal(Number(await zone.getAttribute('data-to-m')), sweet.body.sweet_zone.to_knob_m);
  assert.equal(await page.locator('#curve-chart canvas').count(), 1);
  // The drawing: one bat with the markers, to scale (viewBox width = length in mm).
  assert.equal(await page.locator('#bat-drawing g.bat.main').count(), 1);
  assert.equal(Number(await page.locator('#bat-drawing').getAttribute('data-length-m')), 0.855);
  assert.equal(await page.locator('#bat-drawing g.mark').count(), 3);

  const modes = await apiPost(url, '/v1/bat/modes', { bat, modes: 2, shape_samples: 81 });
  assert.equal(
    await page.locator('#modes-chart').getAttribute('data-frequencies-hz'),
    modes.body.modes.map((m) => m.frequency_hz).join(','),
  );
  assert.equal(await page.locator('#modes-chart .u-legend .u-series').count(), 3); // x + 2 modes
  assert.equal(await page.locator('#modes-chart').getAttribute('data-x-unit'), 'm');
  assert.equal(
    Number(await page.locator('#modes-chart .u-node[data-mode="1"]').first().getAttribute('data-position-m')),
    modes.body.modes[0].nodes_from_knob_m[0],
  );

  // The variants: the paper's cork at 260 and 320 kg/m3, hollow aluminium, side by side.
  await page.waitForSelector('#compare-table[data-variants]');
  assert.equal(
    await page.locator('#compare-table').getAttribute('data-variants'),
    'baseline,cork-260,cork-320,aluminium',
  );
  assert.equal(await page.locator('#compare-table svg.mini .fill').count(), 2);
  assert.equal(await page.locator('#compare-table svg.mini .hollow').count(), 1);
  const cork = await apiPost(url, '/v1/compare', {
    baseline: bat,
    variants: [
      {
        name: 'cork-320',
        bat: {
          ...bat,
          fill: {
            material: { name: 'cork-320', density_kg_m3: 320, youngs_modulus_pa: 2e7 },
            diameter_m: 0.0254,
            depth_m: 0.254,
          },
        },
      },
    ],
  });
  const corkMass = await page.locator('#compare-table tbody tr:first-child td').nth(2).getAttribute('data-value');
  assert.equal(Number(corkMass), cork.body.rows[1].properties.mass_kg);
  await shot(page, artifacts, '01-loaded');
});

scenario('change the bat: the curve and its markers move, to the API values', async ({ page, url }) => {
  const before = await markerOf(page, 'max_exit_speed');
  let rev = await revision(page);
  await page.selectOption('select[name="preset"]', 'wood-34-ash');
  await waitForRefresh(page, rev);
  const ash = await apiPost(url, '/v1/sweet-spot', {
    bat: { preset: 'wood-34-ash' },
    outputs: SWEET,
    options: { curve_samples: 121 },
  });
  const after = await markerOf(page, 'max_exit_speed');
  assert.equal(after.positionM, ash.body.max_exit_speed.position_from_knob_m);
  assert.notEqual(after.positionM, before.positionM);
  assert.notEqual(after.xPx, before.xPx);
  assert.equal(
    Number(await page.locator('#curve-chart').getAttribute('data-max-exit-speed-mps')),
    ash.body.max_exit_speed.exit_speed_mps,
  );
  await shot(page, artifacts, '02-wood-34-ash');

  // A hollow bat: the shell is drawn.
  rev = await revision(page);
  await page.selectOption('select[name="preset"]', 'bbcor-33-aluminium');
  await waitForRefresh(page, rev);
  assert.equal(await page.locator('#bat-drawing g.bat.metal path.hollow').count(), 1);

  // Back to the paper's bat as three segments, then a thinner barrel.
  rev = await revision(page);
  await page.selectOption('select[name="preset"]', 'paper-wood');
  await waitForRefresh(page, rev);
  rev = await revision(page);
  await page.selectOption('select[name="shape"]', 'three_segment');
  await waitForRefresh(page, rev);
  const paper = await markerOf(page, 'max_exit_speed');
  rev = await revision(page);
  await page.fill('input[name="barrel_radius_m"]', '0.03');
  await page.press('input[name="barrel_radius_m"]', 'Tab');
  await waitForRefresh(page, rev);
  const bat = {
    preset: 'paper-wood',
    three_segment: {
      length_m: 0.855,
      handle_radius_m: 0.0125,
      barrel_radius_m: 0.03,
      taper_start_m: 0.3459,
      taper_end_m: 0.6423,
    },
  };
  const thin = await apiPost(url, '/v1/sweet-spot', { bat, outputs: SWEET, options: { curve_samples: 121 } });
  const moved = await markerOf(page, 'max_exit_speed');
  assert.equal(moved.positionM, thin.body.max_exit_speed.position_from_knob_m);
  assert.notEqual(moved.positionM, paper.positionM);
  assert.equal(
    (await markerOf(page, 'center_of_percussion')).positionM,
    thin.body.center_of_percussion.position_from_knob_m,
  );
  // A cork fill from the form is drawn in the bat.
  rev = await revision(page);
  await page.selectOption('select[name="fill_material"]', 'cork');
  await waitForRefresh(page, rev);
  assert.equal(await page.locator('#bat-drawing g.bat.main rect.fill').count(), 1);
  await shot(page, artifacts, '03-three-segment-cork');
});

scenario('a bad input shows the API message beside the field', async ({ page, url }) => {
  const rev = await revision(page);
  await page.fill('input[name="barrel_radius_m"]', '-0.01');
  await page.press('input[name="barrel_radius_m"]', 'Tab');
  await page.waitForSelector('body[data-state="error"]', { timeout: 20000 });
  const bat = {
    preset: 'paper-wood',
    three_segment: {
      length_m: 0.855,
      handle_radius_m: 0.0125,
      barrel_radius_m: -0.01,
      taper_start_m: 0.3459,
      taper_end_m: 0.6423,
    },
    fill: { material: 'cork', diameter_m: 0.0254, depth_m: 0.254 },
  };
  const refused = await apiPost(url, '/v1/bat/properties', { bat });
  assert.equal(refused.status, 400);
  assert.equal(refused.body.field, 'bat.three_segment.barrel_radius_m');
  const slot = page.locator('[data-error-for="bat.three_segment.barrel_radius_m"]');
  await slot.waitFor({ state: 'visible' });
  assert.equal(await slot.textContent(), `${refused.body.message} (${refused.body.code})`);
  assert.equal(await page.locator('input[name="barrel_radius_m"]').getAttribute('aria-invalid'), 'true');
  // Beside the field: the message's box is just below the input.
  const input = await page.locator('input[name="barrel_radius_m"]').boundingBox();
  const box = await slot.boundingBox();
  assert.ok(
    Math.abs(box.y - (input.y + input.height)) < 30,
    `message at y=${box.y}, input ends at ${input.y + input.height}`,
  );
  await shot(page, artifacts, '04-bad-input');

  // A fixed input clears the message.
  await page.fill('input[name="barrel_radius_m"]', '0.035');
  await page.press('input[name="barrel_radius_m"]', 'Tab');
  await waitForRefresh(page, rev);
  assert.equal(await slot.isVisible(), false);
  assert.equal(await page.locator('input[name="barrel_radius_m"]').getAttribute('aria-invalid'), null);

  // Text that is not a number goes to the API as text: the API says what is wrong.
  const fixed = await revision(page);
  await page.fill('input[name="ball_mass_kg"]', 'heavy');
  await page.press('input[name="ball_mass_kg"]', 'Tab');
  const mass = page.locator('[data-error-for="ball.mass_kg"]');
  await mass.waitFor({ state: 'visible' });
  const text = await apiPost(url, '/v1/sweet-spot', { bat: { preset: 'paper-wood' }, ball: { mass_kg: 'heavy' } });
  assert.equal(text.status, 400);
  assert.equal(await mass.textContent(), `${text.body.message} (${text.body.code})`);
  await page.fill('input[name="ball_mass_kg"]', '');
  await page.press('input[name="ball_mass_kg"]', 'Tab');
  await waitForRefresh(page, fixed);
  assert.equal(await mass.isVisible(), false);
});

scenario('run an optimisation: progress, then the optimised profile over the original', async ({ page, url }) => {
  let rev = await revision(page);
  await page.selectOption('select[name="fill_material"]', '');
  await waitForRefresh(page, rev);
  rev = await revision(page);
  await page.selectOption('select[name="shape"]', 'preset');
  await waitForRefresh(page, rev);
  await page.click('#optimize-run');
  await page.waitForSelector('#optimize-progress:not([hidden])', { timeout: 10000 });
  await page.waitForSelector('#optimize-state[data-state="done"]', { timeout: 60000 });
  const id = await page.locator('#optimize-state').getAttribute('data-job-id');
  const result = await (await fetch(`${url}/v1/jobs/${id}/result`)).json();
  assert.equal(result.summary.termination, 'converged');
  assert.equal(await page.locator('#optimize-drawing g.bat.original').count(), 1);
  assert.equal(await page.locator('#optimize-drawing g.bat.optimised').count(), 1);
  const shown = await page.locator('#optimize-result tbody tr').nth(1).locator('td').first().getAttribute('data-value');
  assert.equal(Number(shown), result.objective_value);
  assert.equal(
    Number(
      await page
        .locator('#optimize-progress')
        .inputValue()
        .catch(() => 1),
    ) >= 0,
    true,
  );
  await page.locator('#optimize-section').screenshot({ path: path.join(artifacts, '05-optimised.png') });
});

scenario('cancel a running optimisation', async ({ page, url }) => {
  // Slow on purpose: the widest sweet zone, 64 starts, a 30 s budget.
  await page.selectOption('select[name="objective"]', 'widest_sweet_zone');
  await page.fill('input[name="starts"]', '64');
  await page.fill('input[name="max_time_s"]', '30');
  await page.click('#optimize-run');
  await page.waitForSelector('#optimize-progress:not([hidden])', { timeout: 10000 });
  await page.waitForSelector('#optimize-state[data-state="running"]', { timeout: 10000 });
  await page.screenshot({ path: path.join(artifacts, '06-running.png'), fullPage: true });
  const id = await page.locator('#optimize-state').getAttribute('data-job-id');
  const clicked = Date.now();
  await page.click('#optimize-cancel');
  await page.waitForSelector('#optimize-state[data-state="cancelled"]', { timeout: 30000 });
  const seconds = (Date.now() - clicked) / 1000;
  const job = await (await fetch(`${url}/v1/jobs/${id}`)).json();
  assert.equal(job.state, 'cancelled');
  assert.equal(job.cancel_requested, true);
  assert.ok(seconds < 15, `cancelled after ${seconds} s`);
  // A cancelled optimisation keeps the best design found so far (issue 19): its answer is a 200
  // whose summary says it was cut short ("cancelled ..."), with the chosen start's termination
  // (no_convergence for a start that converged or was cut; failure for a start that failed,
  // e.g. in Ipopt's restoration phase, when that is all that ran before the cancel).
  const result = await fetch(`${url}/v1/jobs/${id}/result`);
  assert.equal(result.status, 200);
  const answer = await result.json();
  assert.match(answer.summary.message, /^cancelled/, answer.summary.message);
  assert.ok(['no_convergence', 'failure', 'infeasible'].includes(answer.summary.termination),
            answer.summary.termination);
  assert.ok(answer.bat, 'the kept design');
  assert.equal(await page.locator('#optimize-run').isEnabled(), true);
  console.log(`    (cancelled ${seconds.toFixed(2)} s after the click)`);
  await page.locator('#optimize-section').screenshot({ path: path.join(artifacts, '07-cancelled.png') });
});

scenario('an optimisation the API refuses shows the message beside the field', async ({ page }) => {
  await page.selectOption('select[name="objective"]', 'max_exit_speed');
  await page.fill('input[name="starts"]', '1000');
  await page.click('#optimize-run');
  const slot = page.locator('#optimize-form [data-error-for="options.starts"]');
  await slot.waitFor({ state: 'visible', timeout: 30000 });
  assert.match(await slot.textContent(), /^options\.starts = 1000: /);
  await page.fill('input[name="starts"]', '4');
});

// The page with a token configured: static files load without it, the page asks for it.
// Its own server (started with the test's, once) and its own context: the test's page
// stays as the scenarios above left it.
scenario('a server with a token: the page asks for it and then works', async ({ browser, servers }) => {
  const guarded = servers['server-with-token'];
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const tokenPage = await context.newPage();
  const response = await tokenPage.goto(guarded.url);
  assert.equal(response.status(), 200);
  await tokenPage.waitForSelector('#token-form:not([hidden])', { timeout: 20000 });
  await tokenPage.fill('#token', TOKEN);
  await tokenPage.click('#token-form button[type="submit"]');
  await tokenPage.waitForSelector('body[data-state="ready"]', { timeout: 20000 });
  const sweet = await apiPost(
    guarded.url,
    '/v1/sweet-spot',
    { bat: { preset: 'wood-34-ash' }, ...GAME, outputs: SWEET, options: { curve_samples: 121 } },
    { Authorization: `Bearer ${TOKEN}` },
  );
  assert.equal(
    (await markerOf(tokenPage, 'max_exit_speed')).positionM,
    sweet.body.max_exit_speed.position_from_knob_m,
  );
  assert.equal(await tokenPage.evaluate(() => sessionStorage.getItem('sweetspot-token')), TOKEN);
  await tokenPage.screenshot({ path: path.join(artifacts, '08-token.png') });
  await context.close();
});

await run(harness, scenarios, { servers: { 'server-with-token': { SWEETSPOT_AUTH_TOKEN: TOKEN } } });
