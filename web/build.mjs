// Bundles the design explorer with esbuild into one folder that
// sweetspot-server serves at /:
//
//   node build.mjs OUT_DIR [NODE_MODULES_DIR]
//
// OUT_DIR gets index.html (from src/index.html) and assets/app-HASH.{js,css}
// (content-hashed names: the server lets browsers cache assets/ for a year and
// revalidates index.html). NODE_MODULES_DIR defaults to ./node_modules (CMake
// passes the build tree's own, installed there by `npm ci`).
import { createRequire } from 'node:module';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import zlib from 'node:zlib';

const here = path.dirname(fileURLToPath(import.meta.url));
const [outArg, modulesArg] = process.argv.slice(2);
if (!outArg) {
  console.error('usage: node build.mjs OUT_DIR [NODE_MODULES_DIR]');
  process.exit(2);
}
const out = path.resolve(outArg);
const nodeModules = path.resolve(modulesArg ?? path.join(here, 'node_modules'));
const require = createRequire(path.join(nodeModules, 'build.cjs'));
const esbuild = require('esbuild');

// A fresh output folder: stale hashed files would otherwise pile up.
fs.rmSync(path.join(out, 'assets'), { recursive: true, force: true });
fs.mkdirSync(path.join(out, 'assets'), { recursive: true });

const result = await esbuild.build({
  entryPoints: { app: path.join(here, 'src', 'main.js') },
  bundle: true,
  minify: true,
  format: 'esm',
  target: ['es2020'],
  outdir: path.join(out, 'assets'),
  entryNames: '[name]-[hash]',
  nodePaths: [nodeModules],
  metafile: true,
  logLevel: 'warning',
});

// The entry's JS and CSS, relative to OUT_DIR.
const outputs = Object.keys(result.metafile.outputs).map((file) =>
  path.relative(out, path.resolve(file)).split(path.sep).join('/'),
);
const js = outputs.find((file) => file.endsWith('.js'));
const css = outputs.find((file) => file.endsWith('.css'));
if (!js || !css) {
  console.error(`build.mjs: expected one .js and one .css output, got ${outputs.join(', ')}`);
  process.exit(1);
}
const template = fs.readFileSync(path.join(here, 'src', 'index.html'), 'utf8');
if (!template.includes('%APP_JS%') || !template.includes('%APP_CSS%')) {
  console.error('build.mjs: src/index.html must contain %APP_JS% and %APP_CSS%');
  process.exit(1);
}
const html = template.replaceAll('%APP_JS%', js).replaceAll('%APP_CSS%', css);
fs.writeFileSync(path.join(out, 'index.html'), html);

// What a first visit downloads.
let total = 0;
let totalGzip = 0;
const lines = [];
for (const file of ['index.html', js, css]) {
  const bytes = fs.readFileSync(path.join(out, file));
  const gzip = zlib.gzipSync(bytes, { level: 9 }).length;
  total += bytes.length;
  totalGzip += gzip;
  lines.push(`  ${file}: ${(bytes.length / 1024).toFixed(1)} KiB (${(gzip / 1024).toFixed(1)} KiB gzip)`);
}
console.log(
  `explorer bundle in ${out}: ${(total / 1024).toFixed(1)} KiB ` +
    `(${(totalGzip / 1024).toFixed(1)} KiB gzip)\n${lines.join('\n')}`,
);
