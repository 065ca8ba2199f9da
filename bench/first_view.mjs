// Where the first 3D view's time goes (issue 61, item 1): opens /3d.html on a server in headless
// Chromium (SwiftShader, on the same cores as the server), for each view until its tiles have
// settled, and reports the time, the content tiles requested and, from the server's access log
// (JSON lines), their count, summed server time and the slowest, by level.
//
// Usage (from the repository root, the server started with `--access-log FILE`):
//   node bench/first_view.mjs URL ACCESS_LOG [HASH | >TEXTURE …]
// e.g. node bench/first_view.mjs http://127.0.0.1:8080 /tmp/access.log 't=gravel' 't=flagstones'
// A HASH opens a page of its own; `>TEXTURE` picks that texture in the page before it, as a user
// switching textures does (e.g. 't=gravel' '>flagstones').
import { readFileSync, statSync } from 'node:fs';

import { chromium } from './browser_libs.mjs';

const [base, log, ...hashes] = process.argv.slice(2);
const views = hashes.length ? hashes : ['t=gravel', 't=flagstones'];
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
const size = () => { try { return statSync(log).size; } catch { return 0; } };
console.log('| view | settled in | content tiles | by level: tiles, server ms summed, slowest ms |');
console.log('|---|---|---|---|');
let page = null;
for (const hash of views) {
  const from = size();
  const t0 = Date.now();
  let before = 0;
  if (hash.startsWith('>') && page) {
    const id = hash.slice(1);
    before = await page.evaluate(() => window.textile3d.requested.length);
    await page.selectOption('#texture', id);
    // The new tileset replaces the old after the page's debounce.
    await page.waitForFunction((id) => window.textile3d.tiles?.rootURL?.includes(`/3dtiles/${id}/`), id, { timeout: 60000, polling: 50 });
  } else {
    await page?.close();
    page = await browser.newPage({ viewport: { width: 1000, height: 640 } });
    await page.goto(`${base}/3d.html#${hash}`);
    await page.waitForSelector('body[data-ready="1"]', { state: 'attached', timeout: 60000 });
  }
  const settled = () => page.waitForFunction(() => window.textile3d?.settled(), null, { timeout: 300000, polling: 100 });
  await settled();
  await page.waitForTimeout(300);
  await settled();
  const ms = Date.now() - t0 - 300;
  const requested = (await page.evaluate(() => window.textile3d.requested.length)) - before;
  await new Promise((r) => setTimeout(r, 500)); // the log's writer thread
  const lines = readFileSync(log, 'utf8').slice(from).split('\n').filter(Boolean).map((l) => JSON.parse(l));
  const by = {};
  for (const l of lines) {
    const m = l.path.match(/\/3dtiles\/[^/]+\/tiles\/(\d+)\//);
    if (!m) continue;
    const b = (by[m[1]] ??= { n: 0, ms: 0, max: 0 });
    b.n++; b.ms += l.ms; b.max = Math.max(b.max, l.ms);
  }
  const levels = Object.entries(by).map(([k, b]) => `${k}: ${b.n}, ${b.ms.toFixed(0)}, ${b.max.toFixed(0)}`).join('; ');
  console.log(`| ${hash} | ${(ms / 1000).toFixed(1)} s | ${requested} | ${levels} |`);
}
await page?.close();
await browser.close();
