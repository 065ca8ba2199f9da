// Headless-Chromium test of the archive page: an archive made by `textile export`, served as a
// static file by the server under test (TEXTILE_URL, archive at TEXTILE_ARCHIVE), shown by
// /static/pmtiles.html through the pmtiles library's range requests. Run by tests/browser.rs.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { chromium } from 'playwright-core';

const BASE = process.env.TEXTILE_URL;
const ARCHIVE = process.env.TEXTILE_ARCHIVE;
const PART = process.env.TEXTILE_ARCHIVE_PART;
let browser;

before(async () => {
  assert.ok(BASE && ARCHIVE && PART, 'TEXTILE_URL, TEXTILE_ARCHIVE and TEXTILE_ARCHIVE_PART must be set');
  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--no-first-run'],
  });
});

after(async () => { await browser?.close(); });

test('the archive page shows an exported archive from its byte ranges', async () => {
  const page = await browser.newPage({ viewport: { width: 900, height: 700 } });
  const errors = [];
  const ranges = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('request', (r) => { if (r.url().includes(ARCHIVE)) ranges.push(r.headers().range || ''); });
  await page.goto(`${BASE}/static/pmtiles.html?url=${encodeURIComponent(ARCHIVE)}`);
  await page.waitForSelector('body[data-ready="1"]', { timeout: 20000 });
  await page.waitForFunction(() => window.textileArchive.loaded >= 4, null, { timeout: 20000 });
  const s = await page.evaluate(() => window.textileArchive);
  assert.equal(s.failed, 0);
  assert.equal(s.metadata.textile.texture, 'gravel');
  assert.ok(ranges.length > 0 && ranges.every((r) => r.startsWith('bytes=')), `range requests: ${ranges}`);
  // The map shows texture, not an empty canvas.
  const spread = await page.evaluate(() => {
    const c = document.querySelector('#map canvas');
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let s = 0, s2 = 0, n = 0;
    for (let i = 0; i < d.length; i += 16) { const v = d[i]; s += v; s2 += v * v; n++; }
    return Math.sqrt(s2 / n - (s / n) ** 2);
  });
  assert.ok(spread > 5, `pixel spread ${spread}`);
  const info = await page.textContent('#info');
  assert.match(info, /zooms 0–3, 85 tiles/);
  assert.deepEqual(errors, []);
});

test('an archive of part of the world opens on its own bounds', async () => {
  const page = await browser.newPage({ viewport: { width: 900, height: 700 } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(`${BASE}/static/pmtiles.html?url=${encodeURIComponent(PART)}`);
  await page.waitForSelector('body[data-ready="1"]', { timeout: 20000 });
  await page.waitForFunction(() => window.textileArchive.loaded >= 4, null, { timeout: 20000 });
  const s = await page.evaluate(() => ({ ...window.textileArchive, at: window.textileArchive.view() }));
  const h = s.header;
  assert.equal(s.failed, 0);
  assert.ok(h.minLon > 0 && h.maxLat < 85, `a part of the world: ${JSON.stringify(h)}`);
  const [lon, lat] = s.at.center;
  assert.ok(lon >= h.minLon && lon <= h.maxLon && lat >= h.minLat && lat <= h.maxLat,
    `view centre ${lon},${lat} inside ${h.minLon},${h.minLat},${h.maxLon},${h.maxLat}`);
  assert.ok(s.at.zoom >= h.minZoom, `zoom ${s.at.zoom}`);
  // Texture fills the view, not an empty grey map.
  const spread = await page.evaluate(() => {
    const c = document.querySelector('#map canvas');
    const d = c.getContext('2d').getImageData(c.width / 4, c.height / 4, c.width / 2, c.height / 2).data;
    let s = 0, s2 = 0, n = 0;
    for (let i = 0; i < d.length; i += 16) { const v = d[i]; s += v; s2 += v * v; n++; }
    return Math.sqrt(s2 / n - (s / n) ** 2);
  });
  assert.ok(spread > 5, `pixel spread ${spread}`);
  assert.deepEqual(errors, []);
});
