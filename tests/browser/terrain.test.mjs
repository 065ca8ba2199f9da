// Headless-Chromium tests of MapLibre GL JS against textile's raster-dem (TEXTILE_URL): the
// README's style snippet renders terrain with hillshade and no console errors, pitched relief
// differs from the same view without terrain, no background shows through between tiles; the
// terrain page has its picker and permalink. Run by tests/browser.rs.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { chromium } from 'playwright-core';

const BASE = process.env.TEXTILE_URL;
let browser;

before(async () => {
  assert.ok(BASE, 'TEXTILE_URL must name the server under test');
  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
      '--ignore-gpu-blocklist', '--disable-background-networking', '--no-first-run'],
  });
});

after(async () => { await browser?.close(); });

/** The README's MapLibre snippet (between its markers), pointed at the server under test. */
function readmeSnippet() {
  const readme = readFileSync(new URL('../../README.md', import.meta.url), 'utf8');
  const m = readme.match(/<!-- maplibre-terrain -->\s*```js\n([\s\S]*?)```/);
  assert.ok(m, 'README has the MapLibre terrain snippet');
  return m[1].replace('http://127.0.0.1:8080', BASE);
}

async function page(path) {
  // Small: software WebGL draws terrain slowly.
  const p = await browser.newPage({ viewport: { width: 512, height: 340 } });
  const errors = [];
  p.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  p.on('pageerror', (e) => errors.push(String(e)));
  p.on('response', (r) => { if (r.status() >= 400) errors.push(`${r.status()} ${r.url()}`); });
  // A JSON page has no icon of its own: the browser would ask for /favicon.ico.
  await p.route('**/favicon.ico', (r) => r.fulfill({ status: 204, body: '' }));
  await p.goto(BASE + path);
  return { p, errors };
}

/** Wait until the map has loaded every tile it wants and rendered. */
async function idle(p) {
  await p.evaluate(() => new Promise((ok) => {
    const m = window.map;
    const done = () => (m.loaded() && m.areTilesLoaded() ? ok() : m.once('idle', done));
    m.triggerRepaint();
    m.once('idle', done);
  }));
}

/** RGBA pixels of a screenshot of the map, and how many are magenta (the background). */
async function pixels(p) {
  const png = await p.locator('#map').screenshot();
  return p.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    [c.width, c.height] = [img.width, img.height];
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    // Magenta in the lower 60 % of the view (the ground, below any horizon).
    let magenta = 0;
    for (let y = Math.floor(c.height * 0.4); y < c.height; y++) {
      for (let x = 0; x < c.width; x++) {
        const i = 4 * (y * c.width + x);
        if (d[i] > 240 && d[i + 1] < 16 && d[i + 2] > 240) magenta++;
      }
    }
    return { data: Array.from(d), magenta, width: c.width, height: c.height };
  }, png.toString('base64'));
}

function meanDiff(a, b) {
  let s = 0;
  for (let i = 0; i < a.data.length; i += 4) for (let c = 0; c < 3; c++) s += Math.abs(a.data[i + c] - b.data[i + c]);
  return s / (3 * a.data.length / 4);
}

test('the README snippet: terrain with hillshade, relief where it should be, no cracks', async () => {
  const { p, errors } = await page('/health');
  await p.setContent(`<!doctype html><html><head>
    <link rel="icon" href="data:,"><link rel="stylesheet" href="${BASE}/static/vendor/maplibre-gl.css">
    <style>html, body, #map { margin: 0; width: 100%; height: 100%; background: #ff00ff; }</style></head>
    <body><div id="map"></div><script src="${BASE}/static/vendor/maplibre-gl.js"></script></body></html>`);
  await p.waitForFunction(() => window.maplibregl);
  await p.evaluate(`${readmeSnippet()}\nwindow.map = map;`);
  await p.evaluate(() => new Promise((ok) => window.map.once('load', ok)));
  // Anything not drawn shows magenta: the page behind the canvas, and a background layer under
  // the texture (a missing tile, or a crack between terrain tiles, would show it).
  await p.evaluate(() => window.map.addLayer({ id: 'bg', type: 'background', paint: { 'background-color': '#ff00ff' } }, 'texture'));
  await idle(p);
  const pitched = await pixels(p);
  assert.equal(pitched.magenta, 0, 'no background between the tiles of the pitched terrain');
  const layers = await p.evaluate(() => window.map.getStyle().layers.map((l) => l.type));
  assert.ok(layers.includes('hillshade'), JSON.stringify(layers));
  assert.ok(await p.evaluate(() => Boolean(window.map.getTerrain())), 'terrain is on');
  // The same pitched view without terrain: relief moves the ground.
  await p.evaluate(() => window.map.setTerrain(null));
  await idle(p);
  const flat = await pixels(p);
  const relief = meanDiff(pitched, flat);
  assert.ok(relief > 2, `terrain changes the pitched view (mean difference ${relief.toFixed(2)})`);
  // Hillshade shades the texture: seen from above, with it and without.
  await p.evaluate(() => window.map.jumpTo({ pitch: 0, bearing: 0 }));
  await idle(p);
  const shaded = await pixels(p);
  await p.evaluate(() => window.map.setLayoutProperty('hillshade', 'visibility', 'none'));
  await idle(p);
  const plain = await pixels(p);
  const shade = meanDiff(shaded, plain);
  assert.ok(shade > 1, `hillshade changes the view (mean difference ${shade.toFixed(2)})`);
  assert.equal(shaded.magenta, 0, 'no background between the tiles seen from above');
  console.log(`terrain: relief moves the pitched view by ${relief.toFixed(2)}, hillshade shades by ${shade.toFixed(2)}`);
  assert.deepEqual(errors, []);
  await p.close();
});

test('the terrain page: a picker of textures and landscapes, a permalink, no console errors', async () => {
  const { p, errors } = await page('/terrain.html#t=meadow&r=2');
  await p.waitForSelector('body[data-ready="1"]', { timeout: 30000 });
  await p.evaluate(() => { window.map = window.textileTerrain; });
  await idle(p);
  const options = await p.$$eval('#texture option', (o) => o.map((x) => x.value));
  assert.ok(options.includes('flagstones') && options.includes('meadow'), JSON.stringify(options));
  assert.equal(await p.inputValue('#texture'), 'meadow');
  assert.equal(await p.evaluate(() => window.textileTerrain.getTerrain().exaggeration), 2);
  await p.selectOption('#texture', 'flagstones');
  await p.waitForFunction(() => location.hash.includes('t=flagstones'));
  await p.evaluate(() => window.textileTerrain.jumpTo({ zoom: 7.5, pitch: 50, bearing: 30 }));
  await p.waitForFunction(() => location.hash.includes('/30/50'));
  const link = await p.getAttribute('#permalink', 'href');
  const again = await page(`/terrain.html${link}`);
  await again.p.waitForSelector('body[data-ready="1"]', { timeout: 30000 });
  const cam = await again.p.evaluate(() => [window.textileTerrain.getZoom(), window.textileTerrain.getPitch(), window.textileTerrain.getBearing()]);
  assert.deepEqual(cam.map((v) => Math.round(v * 10) / 10), [7.5, 50, 30]);
  assert.equal(await again.p.inputValue('#texture'), 'flagstones');
  assert.deepEqual([...errors, ...again.errors], []);
  await again.p.close();
  await p.close();
});

test('the 2D viewer links to the terrain page of its texture', async () => {
  const { p, errors } = await page('/#t=flagstones');
  await p.waitForSelector('body[data-ready="1"]', { timeout: 20000 });
  await p.click('#terrainlink');
  await p.waitForURL(/terrain\.html#t=flagstones/);
  await p.waitForSelector('body[data-ready="1"]', { timeout: 30000 });
  assert.deepEqual(errors, []);
  await p.close();
});
