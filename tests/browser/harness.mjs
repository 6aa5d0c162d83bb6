// What a browser test of the explorer needs around its scenarios: the
// arguments, the real sweetspot-server on 127.0.0.1 with an ephemeral port,
// Debian's chromium driven by playwright-core, the API asked directly (never
// through the page), screenshots that must hold an image, the no-overflow
// check, and the run loop (a failing scenario stops the run: later ones start
// from its page). compare.test.mjs uses it; explorer.test.mjs has its own copy
// of the same pieces.
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { parseArgs } from 'node:util';

/**
 * Reads --server, --web-root, --node-modules, --artifacts (required) and
 * --chromium; exits 2 (1) when one is missing (when a file is absent).
 * Returns {args, chromium (playwright-core's), artifacts (emptied)}.
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

/** Starts sweetspot-server on 127.0.0.1:0; resolves to {url, stop()} once /health answers. */
export async function startServer(args, artifacts, name, env = {}) {
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

/** A full-page screenshot `name`.png in `artifacts`, checked to exist and hold an image. */
export async function shot(page, artifacts, name) {
  const file = path.join(artifacts, `${name}.png`);
  await page.screenshot({ path: file, fullPage: true });
  // The screenshot is part of the test's evidence: it must exist and hold an image.
  assert.ok(fs.statSync(file).size > 1000, `${file} is empty`);
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

/**
 * Runs `scenarios` ([{name, fn}]) in order on one page of a 1280 × 900
 * context against one server; each fn gets {page, url, browser}. A console
 * error (other than the browser's line for a 4xx answer) or an uncaught
 * exception fails the scenario. Exits 0 when all passed.
 */
export async function run({ args, chromium, artifacts, scenarios }) {
  const started = Date.now();
  const failures = [];
  const browser = await chromium.launch({
    executablePath: args.chromium,
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
  });
  const server = await startServer(args, artifacts, 'server');
  let page;
  try {
    const context = await browser.newContext({ viewport: { width: 1280, height: 900 }, acceptDownloads: true });
    page = await context.newPage();
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
        await fn({ page, url: server.url, browser, pageErrors });
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
    await server.stop();
    await browser.close();
  }
  console.log(
    `${failures.length ? `FAILED (${failures.join('; ')}; later scenarios not run)` : 'passed'}: ` +
      `${scenarios.length} scenarios, ${failures.length} failed, in ${((Date.now() - started) / 1000).toFixed(1)} s; ` +
      `screenshots and server logs in ${artifacts}`,
  );
  process.exit(failures.length ? 1 : 0);
}
