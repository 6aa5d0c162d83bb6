// The one harness of the explorer's browser tests (explorer.test.mjs, compare.test.mjs,
// flight.test.mjs): the arguments, the real sweetspot-server on 127.0.0.1 with an ephemeral
// port, Debian's chromium driven by playwright-core, the API asked directly (never through
// the page), the page's own ready/revision signals, screenshots that must hold a PNG image,
// the no-overflow check, downloads, and the run loop (a failing scenario stops the run:
// later ones start from its page).
//
// Cost: one chromium per test, launched while the test's servers start; every server a test
// needs started once, before its first scenario; no fixed sleeps (each wait is for a signal
// of the page, and a page-side wait is woken by the page's own changes rather than polled on
// every animation frame).
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { parseArgs } from 'node:util';

// ---- what the page opens on (docs/explorer.md, "What it opens on") -------------------------

/** The page's opening scene: the mlb ball at 90 mph, a 70 mph bat speed, a fly ball (issue 37). */
export const GAME = {
  ball: { preset: 'mlb', speed_mph: 90, descent_angle_deg: 7 },
  swing: { bat_speed_mph: 70, attack_angle_deg: 10 },
  contact: { undercut_in: 0.5 },
};
/** The same scene in SI, as the unit switch's defaults write it (90 mph and 70 mph exactly). */
export const GAME_SI = {
  ball: { preset: 'mlb', speed_mps: 40.2336, descent_angle_deg: 7 },
  swing: { bat_speed_mps: 31.2928, attack_angle_deg: 10 },
  contact: { undercut_m: 0.0127 },
};

// ---- the test's arguments, the server ------------------------------------------------------

/**
 * Reads --server, --web-root, --node-modules, --artifacts (required) and --chromium; exits 2
 * (1) when one is missing (when a file is absent). Returns the harness: {args, chromium
 * (playwright-core's), artifacts (the test's own folder, emptied)}.
 */
export function setup(testName) {
  const { values: args } = parseArgs({
    options: {
      server: { type: 'string' },
      'web-root': { type: 'string' },
      'node-modules': { type: 'string' },
      artifacts: { type: 'string' },
      chromium: { type: 'string', default: '/usr/bin/chromium' },
    },
  });
  for (const name of ['server', 'web-root', 'node-modules', 'artifacts']) {
    if (!args[name]) {
      console.error(`${testName}: --${name} is required (see the comment at the top)`);
      process.exit(2);
    }
  }
  if (!fs.existsSync(args.chromium)) {
    console.error(`${testName}: no browser at ${args.chromium}: run scripts/install-deps.sh (Debian's chromium)`);
    process.exit(1);
  }
  if (!fs.existsSync(path.join(args['web-root'], 'index.html'))) {
    console.error(`${testName}: no index.html in ${args['web-root']}: build the sweetspot_web target`);
    process.exit(1);
  }
  const { chromium } = createRequire(path.join(path.resolve(args['node-modules']), 'x.cjs'))('playwright-core');
  const artifacts = path.resolve(args.artifacts);
  fs.rmSync(artifacts, { recursive: true, force: true });
  fs.mkdirSync(artifacts, { recursive: true });
  return { args, chromium, artifacts };
}

/**
 * Starts sweetspot-server on 127.0.0.1:0 with `env` added to the environment, its log in
 * `name`.log of the artifacts; resolves to {url, stop()} once /health answers.
 */
export async function startServer({ args, artifacts }, name, env = {}) {
  const log = fs.createWriteStream(path.join(artifacts, `${name}.log`));
  const child = spawn(
    args.server,
    ['--host', '127.0.0.1', '--port', '0', '--jobs-db', 'none', '--web-root', args['web-root'], '--job-workers', '2'],
    { env: { ...process.env, ...env }, stdio: ['ignore', 'ignore', 'pipe'] },
  );
  let stderr = '';
  const port = await new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`${name}: no "listening on" within 20 s:\n${stderr}`)), 20000);
    child.stderr.on('data', (chunk) => {
      log.write(chunk);
      stderr += chunk;
      const match = /listening on 127\.0\.0\.1:(\d+)/.exec(stderr);
      if (match) {
        clearTimeout(timer);
        resolve(Number(match[1]));
      }
    });
    child.on('exit', (code) => reject(new Error(`${name} exited with ${code}:\n${stderr}`)));
  });
  const url = `http://127.0.0.1:${port}`;
  // Listening, so /health answers at once; the retry (every 0.1 s, 10 s at most) is for a
  // machine too loaded to accept the first connection.
  for (let i = 0; ; ++i) {
    try {
      if ((await fetch(`${url}/health`)).ok) break;
    } catch (error) {
      if (i > 100) throw error;
    }
    await new Promise((r) => setTimeout(r, 100));
  }
  return {
    url,
    stop: () =>
      new Promise((resolve) => {
        child.removeAllListeners('exit');
        child.on('exit', () => {
          log.end();
          resolve();
        });
        child.kill('SIGTERM');
      }),
  };
}

/** The API's answer to a POST, as the test's own client (never through the page). */
export async function apiPost(url, route, body, headers = {}) {
  const res = await fetch(`${url}${route}`, {
    method: 'POST',
    headers: { 'Content-Type': 'application/json', ...headers },
    body: JSON.stringify(body),
  });
  return { status: res.status, body: await res.json() };
}

// ---- the page --------------------------------------------------------------------------------

/**
 * In the page: resolves once `test(arg)` is true, re-checking it on each change of the DOM,
 * each hash change and, for state kept outside the DOM, every 0.1 s; rejects after `timeout`
 * ms. Sent as source text (the page's Content-Security-Policy forbids building functions
 * from strings inside the page).
 */
function pageWaiter(test, arg, timeout, source) {
  return new Promise((resolve, reject) => {
    let done = false;
    let observer = null;
    let interval = 0;
    let timer = 0;
    const finish = (error, value) => {
      if (done) return;
      done = true;
      observer?.disconnect();
      clearInterval(interval);
      clearTimeout(timer);
      window.removeEventListener('hashchange', check);
      if (error) reject(error);
      else resolve(value);
    };
    function check() {
      try {
        const value = test(arg);
        if (value) finish(null, value);
      } catch (error) {
        finish(error);
      }
    }
    observer = new MutationObserver(check);
    observer.observe(document, { attributes: true, childList: true, subtree: true, characterData: true });
    interval = setInterval(check, 100);
    timer = setTimeout(() => finish(new Error(`not true within ${timeout} ms: ${source} (${JSON.stringify(arg)})`)), timeout);
    window.addEventListener('hashchange', check);
    check();
  });
}

/**
 * Waits until `predicate(arg)` is true in the page: page.waitForFunction's contract (the
 * same predicate, `timeout` ms at most), but woken by the page's own changes instead of
 * polled on every animation frame while the page works. Resolves to the predicate's value.
 * Not across a navigation (wait for the new page with waitForSelector).
 */
export async function waitForPage(page, predicate, arg = null, { timeout = 30000 } = {}) {
  const source = predicate.toString();
  return page.evaluate(
    `(${pageWaiter.toString()})((${source}), ${JSON.stringify(arg)}, ${timeout}, ${JSON.stringify(source)})`,
  );
}

/**
 * A page of a new 390 × 844 phone context (isMobile, and `options`) opened at `address` and
 * ready (body[data-state="ready"]); its uncaught exceptions are gathered in `errors`.
 * Resolves to {context, page, errors}.
 */
export async function openPhone(browser, address, options = {}) {
  const context = await browser.newContext({ viewport: { width: 390, height: 844 }, isMobile: true, ...options });
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (error) => errors.push(error.message));
  await page.goto(address);
  await page.waitForSelector('body[data-state="ready"]', { timeout: 20000 });
  return { context, page, errors };
}

/** The page's bat revision (body[data-revision]: each accepted refresh adds one). */
export async function revision(page) {
  return Number(await page.evaluate(() => document.body.dataset.revision || 0));
}

/** Waits until the page has finished a bat refresh newer than `after` (body[data-revision], [data-state]). */
export async function waitForRefresh(page, after) {
  await waitForPage(
    page,
    (r) => Number(document.body.dataset.revision || 0) > r && document.body.dataset.state === 'ready',
    after,
    { timeout: 20000 },
  );
}

/** Downloads what clicking `selector` offers; resolves to its file name and text. */
export async function download(page, selector) {
  const [file] = await Promise.all([page.waitForEvent('download'), page.click(selector)]);
  return { name: file.suggestedFilename(), text: fs.readFileSync(await file.path(), 'utf8') };
}

/** A full-page screenshot `name`.png in `artifacts`, checked to exist and hold a PNG image. */
export async function shot(page, artifacts, name) {
  const file = path.join(artifacts, `${name}.png`);
  await page.screenshot({ path: file, fullPage: true });
  // The screenshot is part of the test's evidence: it must exist and hold an image.
  const bytes = fs.readFileSync(file);
  assert.ok(bytes.length > 1000, `${file} is empty`);
  assert.equal(bytes.subarray(1, 4).toString('latin1'), 'PNG', `${file} is no PNG`);
  return file;
}

/** The page is no wider than its viewport (nothing cut off or scrolled sideways). */
export async function assertNoOverflow(page, width) {
  const sizes = await page.evaluate(() => ({
    scroll: document.documentElement.scrollWidth,
    client: document.documentElement.clientWidth,
    wide: [...document.querySelectorAll('main *')]
      .filter((e) => e.getBoundingClientRect().right > document.documentElement.clientWidth + 0.5)
      .filter((e) => !e.closest('.scroll'))
      .slice(0, 5)
      .map((e) => `${e.tagName.toLowerCase()}#${e.id}.${e.className?.baseVal ?? e.className}`),
  }));
  assert.equal(sizes.client, width);
  assert.ok(
    sizes.scroll <= sizes.client,
    `page ${sizes.scroll} px wide in ${sizes.client} px: ${sizes.wide.join(', ')}`,
  );
  assert.deepEqual(sizes.wide, [], 'elements past the right edge');
}

// ---- the run -------------------------------------------------------------------------------

/**
 * Runs `scenarios` ([{name, fn}]) in order on one page of a 1280 × 900 context against the
 * test's server, stopping at the first failure (a FAIL-n.png of the page is saved). One
 * chromium for the whole test, launched while the servers start: the test's server
 * ("server") and, once each, the further servers `servers` names ({name: env}). Each fn
 * gets {page, url, browser, pageErrors, servers: {name: {url}}}. A console error (other
 * than the browser's line for a 4xx answer) or an uncaught exception in the page fails the
 * scenario. Exits the process: 0 when every scenario passed.
 */
export async function run(harness, scenarios, { servers: more = {} } = {}) {
  const { args, chromium, artifacts } = harness;
  const started = Date.now();
  const failures = [];
  const launched = await Promise.allSettled([
    chromium.launch({
      executablePath: args.chromium,
      headless: true,
      args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
    }),
    startServer(harness, 'server'),
    ...Object.entries(more).map(([name, env]) => startServer(harness, name, env)),
  ]);
  const [browser, server, ...others] = launched.map((r) => (r.status === 'fulfilled' ? r.value : null));
  const stopAll = async () => {
    await Promise.all([server, ...others].filter(Boolean).map((s) => s.stop()));
    if (browser) await browser.close();
  };
  const refused = launched.find((r) => r.status === 'rejected');
  if (refused) {
    await stopAll();
    throw refused.reason;
  }
  const servers = Object.fromEntries(Object.keys(more).map((name, i) => [name, others[i]]));
  try {
    const context = await browser.newContext({ viewport: { width: 1280, height: 900 }, acceptDownloads: true });
    const page = await context.newPage();
    const pageErrors = [];
    page.on('pageerror', (error) => pageErrors.push(error.message));
    page.on('console', (message) => {
      // The browser logs every 4xx answer ("Failed to load resource"): those are the test's.
      if (message.type() === 'error' && !/Failed to load resource/.test(message.text()))
        pageErrors.push(message.text());
    });
    for (const { name, fn } of scenarios) {
      const t0 = Date.now();
      try {
        await fn({ page, url: server.url, browser, pageErrors, servers });
        assert.deepEqual(pageErrors, [], 'errors in the page');
        console.log(`ok    ${name} (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
      } catch (error) {
        failures.push(name);
        console.log(`FAIL  ${name} (${((Date.now() - t0) / 1000).toFixed(1)} s)\n${error.stack}`);
        await shot(page, artifacts, `FAIL-${failures.length}`).catch(() => {});
        break; // Later scenarios start from this one's page.
      }
    }
  } finally {
    await stopAll();
  }
  console.log(
    `${failures.length ? `FAILED (${failures.join('; ')}; later scenarios not run)` : 'passed'}: ` +
      `${scenarios.length} scenarios, ${failures.length} failed, in ${((Date.now() - started) / 1000).toFixed(1)} s; ` +
      `screenshots and server logs in ${artifacts}`,
  );
  process.exit(failures.length ? 1 : 0);
}
