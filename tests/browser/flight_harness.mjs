// The browser tests' harness: arguments, the real sweetspot-server on an ephemeral port,
// the API's own answers (never through the page), screenshots and the overflow check, and
// a runner that stops at the first failing scenario (later ones start from its page).
// The same helpers as tests/browser/explorer.test.mjs, shared by flight.test.mjs.
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { parseArgs } from 'node:util';

/** The command line (--server, --web-root, --node-modules, --artifacts, --chromium), checked. */
export function readArgs(script) {
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
      console.error(`${script}: --${name} is required (see the comment at the top)`);
      process.exit(2);
    }
  }
  if (!fs.existsSync(args.chromium)) {
    console.error(`${script}: no browser at ${args.chromium}: run scripts/install-deps.sh (Debian's chromium)`);
    process.exit(1);
  }
  if (!fs.existsSync(path.join(args['web-root'], 'index.html'))) {
    console.error(`${script}: no index.html in ${args['web-root']}: build the sweetspot_web target`);
    process.exit(1);
  }
  const artifacts = path.resolve(args.artifacts);
  fs.rmSync(artifacts, { recursive: true, force: true });
  fs.mkdirSync(artifacts, { recursive: true });
  const { chromium } = createRequire(path.join(path.resolve(args['node-modules']), 'x.cjs'))('playwright-core');
  return { args, artifacts, chromium };
}

/** Starts sweetspot-server on 127.0.0.1:0; resolves to {url, stop()} once /health answers. */
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
export async function apiPost(url, route, body) {
  const res = await fetch(`${url}${route}`, {
    method: 'POST',
    headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify(body),
  });
  return { status: res.status, body: await res.json() };
}

/** A full-page screenshot `name`.png in the artifacts, checked to exist and hold an image. */
export async function shot(artifacts, page, name) {
  const file = path.join(artifacts, `${name}.png`);
  await page.screenshot({ path: file, fullPage: true });
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
  assert.ok(sizes.scroll <= sizes.client, `page ${sizes.scroll} px wide in ${sizes.client} px: ${sizes.wide.join(', ')}`);
  assert.deepEqual(sizes.wide, [], 'elements past the right edge');
}

/** Waits until the page has finished a bat refresh newer than `after` (body[data-revision]). */
export async function waitForRefresh(page, after) {
  await page.waitForFunction(
    (r) => Number(document.body.dataset.revision || 0) > r && document.body.dataset.state === 'ready',
    after,
    { timeout: 20000 },
  );
}

/** The page's bat revision (each accepted refresh adds one). */
export async function revision(page) {
  return Number(await page.evaluate(() => document.body.dataset.revision || 0));
}

/**
 * Runs `scenarios` ([{name, fn}]) in one 1280-px page against one server, in order,
 * stopping at the first failure (a FAIL-n.png is saved). Browser messages for 4xx
 * answers are expected; any other console error or uncaught exception fails.
 * Exits the process: 0 when every scenario passed.
 */
export async function run(harness, scenarios) {
  const { args, artifacts, chromium } = harness;
  const started = Date.now();
  const failures = [];
  const browser = await chromium.launch({
    executablePath: args.chromium,
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
  });
  const server = await startServer(harness, 'server');
  try {
    const context = await browser.newContext({ viewport: { width: 1280, height: 900 }, acceptDownloads: true });
    const page = await context.newPage();
    const pageErrors = [];
    page.on('pageerror', (error) => pageErrors.push(error.message));
    page.on('console', (message) => {
      if (message.type() === 'error' && !/Failed to load resource/.test(message.text())) pageErrors.push(message.text());
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
        await shot(artifacts, page, `FAIL-${failures.length}`).catch(() => {});
        break;
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
