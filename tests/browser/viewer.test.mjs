// Headless-Chromium tests of the textile viewer against a running server (TEXTILE_URL).
// Run by tests/browser.rs, which starts the real binary; see that file.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { chromium } from 'playwright-core';

const BASE = process.env.TEXTILE_URL;
const SHOT = process.env.TEXTILE_SCREENSHOT;
let browser;

before(async () => {
  assert.ok(BASE, 'TEXTILE_URL must name the server under test');
  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--no-first-run'],
  });
});

after(async () => { await browser?.close(); });

async function open(path, viewport = { width: 1280, height: 800 }) {
  const page = await browser.newPage({ viewport });
  const errors = [];
  const tiles = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('response', (r) => { if (r.url().includes('/tiles/')) tiles.push({ url: r.url(), status: r.status() }); });
  await page.goto(BASE + path);
  await page.waitForSelector('body[data-ready="1"]', { timeout: 20000 });
  return { page, errors, tiles };
}

/** Wait until every Leaflet tile image is loaded (and at least `min` exist). */
async function settled(page, min = 4) {
  await page.waitForFunction((min) => {
    const imgs = [...document.querySelectorAll('img.leaflet-tile')];
    return imgs.length >= min && imgs.every((i) => i.complete && i.naturalWidth === 256)
      && !document.querySelector('.leaflet-tile-loading');
  }, min, { timeout: 20000 });
}

/** Pixel statistics of loaded tile images: source URL, mean, spread and a checksum. */
async function tileStats(page) {
  return page.evaluate(() => [...document.querySelectorAll('img.leaflet-tile-loaded')].map((img) => {
    const c = document.createElement('canvas');
    c.width = img.naturalWidth; c.height = img.naturalHeight;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let s = 0, s2 = 0, n = 0, h = 0;
    for (let i = 0; i < d.length; i += 4) {
      const v = (d[i] + d[i + 1] + d[i + 2]) / 3;
      s += v; s2 += v * v; n++;
      h = (h * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) >>> 0;
    }
    const mean = s / n;
    return { src: img.src, mean, sd: Math.sqrt(s2 / n - mean * mean), sum: h };
  }));
}

function assertTexture(stats) {
  assert.ok(stats.length >= 4, `expected loaded tiles, got ${stats.length}`);
  for (const t of stats) {
    assert.ok(t.mean > 8 && t.mean < 247, `tile ${t.src} looks blank (mean ${t.mean})`);
    assert.ok(t.sd > 4, `tile ${t.src} has no texture (sd ${t.sd})`);
  }
}

test('the viewer loads with no console errors and shows texture tiles', async () => {
  const { page, errors, tiles } = await open('/');
  await settled(page);
  assertTexture(await tileStats(page));
  assert.ok(tiles.length > 0 && tiles.every((t) => t.status === 200), JSON.stringify(tiles.slice(0, 5)));
  const labels = await page.$$eval('select, input, button', (els) => els.filter((e) => {
    const id = e.id;
    return !(e.labels && e.labels.length) && !e.getAttribute('aria-label') && !(e.tagName === 'BUTTON' && e.textContent.trim()) && id;
  }).map((e) => e.id));
  assert.deepEqual(labels, [], 'every control has a label');
  if (SHOT) {
    await page.waitForTimeout(600); // let Leaflet's tile fade-in finish
    await page.screenshot({ path: SHOT });
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test('tiles shed with 503 under load are retried until the view is complete', async () => {
  const shedding = process.env.TEXTILE_URL_SHEDDING;
  assert.ok(shedding, 'TEXTILE_URL_SHEDDING must name a server with a tiny in-flight limit');
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const tiles = [];
  page.on('response', (r) => { if (r.url().includes('/tiles/')) tiles.push({ url: r.url(), status: r.status() }); });
  await page.goto(shedding + '/#t=grass&z=7&x=5000&y=-3000');
  await page.waitForSelector('body[data-ready="1"]', { timeout: 20000 });
  await settled(page, 12);
  assertTexture(await tileStats(page));
  assert.ok(tiles.some((t) => t.status === 503), 'the server shed some tiles');
  assert.ok(tiles.some((t) => t.status === 200 && /[?&]v=retry\d/.test(t.url)), 'shed tiles were retried');
  assert.ok(tiles.every((t) => t.status === 200 || t.status === 503), JSON.stringify(tiles.filter((t) => t.status !== 200 && t.status !== 503)));
  await page.close();
});

test('panning requests negative tile coordinates and they render', async () => {
  const { page, errors, tiles } = await open('/#t=gravel&z=7&x=0&y=0');
  await settled(page);
  await page.evaluate(() => window.textileMap.panBy([-1800, -1400], { animate: false }));
  await settled(page);
  const negative = tiles.filter((t) => /\/7\/-\d+\/-\d+\.png/.test(t.url));
  assert.ok(negative.length > 0, 'no negative tiles were requested');
  assert.ok(negative.every((t) => t.status === 200));
  const stats = await tileStats(page);
  assert.ok(stats.some((s) => /\/7\/-\d+\/-\d+\.png/.test(s.src)), 'negative tiles are on screen');
  assertTexture(stats);
  const readout = await page.textContent('#readout');
  assert.match(readout, /x -\d+, y -\d+/);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a randomness slider (by keyboard) changes tile URLs and pixels; the permalink restores it', async () => {
  const { page, errors } = await open('/#t=grass&m=synth&s=5&z=7&x=300&y=-200');
  await settled(page);
  const find = (stats, key) => stats.find((s) => s.src.includes(key));
  const before = await tileStats(page);
  const key = '/7/1/-1.png';
  const old = find(before, key);
  assert.ok(old, `tile ${key} on screen`);
  assert.ok(!old.src.includes('randomness='));
  await page.focus('#p-randomness-3');
  for (let i = 0; i < 6; i++) await page.keyboard.press('ArrowRight');
  const moved = Date.now();
  assert.equal(await page.inputValue('#p-randomness-3'), '0.9');
  await page.waitForFunction(() => [...document.querySelectorAll('img.leaflet-tile')].some((i) => i.src.includes('randomness=')));
  await settled(page);
  const shown = await page.$$eval('img.leaflet-tile', (l) => l.length);
  // A measurement for the record, not an assertion (speed is benchmarked, not tested).
  console.log(`${shown} cold tiles re-rendered ${Date.now() - moved} ms after the slider moved (incl. 120 ms debounce)`);
  const after = await tileStats(page);
  const now = find(after, key);
  assert.ok(now && now.src.includes('randomness=') && now.src.includes('0.9'), now && now.src);
  // Levels the user did not touch keep their exact defaults (0.475, not the slider step's 0.5).
  assert.ok(decodeURIComponent(now.src).includes('randomness=1,1,0.8,0.9,0.475,0.15,0.225,0.1'), now.src);
  assert.notEqual(now.sum, old.sum, 'pixels changed with the randomness');
  await page.fill('#seed', '77');
  await page.press('#seed', 'Enter');
  await page.dispatchEvent('#seed', 'change');
  await page.waitForFunction(() => location.hash.includes('s=77'));
  const hash = await page.evaluate(() => location.hash);
  assert.match(hash, /t=grass/);
  assert.match(hash, /p\.randomness=[^&]*0\.9/);
  // Restore in a fresh page.
  const second = await open('/' + hash);
  await settled(second.page);
  assert.equal(await second.page.inputValue('#texture'), 'grass');
  assert.equal(await second.page.inputValue('#seed'), '77');
  assert.equal(await second.page.inputValue('#p-randomness-3'), '0.9');
  assert.equal(await second.page.evaluate(() => window.textileMap.getZoom()), 7);
  const restored = await tileStats(second.page);
  assert.ok(restored.every((s) => s.src.includes('seed=77') && s.src.includes('0.9')));
  assert.deepEqual(errors, []);
  assert.deepEqual(second.errors, []);
  await page.close();
  await second.page.close();
});

/** The controls a hash (or tile URL) carries, decoded. */
function controlsOf(text) {
  const m = text.match(/controls=([A-Za-z0-9_-]+)/);
  return m ? JSON.parse(Buffer.from(m[1], 'base64url').toString()) : null;
}

/** Poll the page's permalink until its controls satisfy `pred`; they are returned. */
async function waitControls(page, pred) {
  for (let i = 0; i < 200; i++) {
    const c = controlsOf(await page.evaluate(() => location.hash));
    if (pred(c)) return c;
    await page.waitForTimeout(50);
  }
  assert.fail(`the permalink's controls never matched: ${await page.evaluate(() => location.hash)}`);
}

/** Wait until every tile image on the map carries `controls=value` (none: without controls). */
async function tilesCarry(page, value) {
  await page.waitForFunction((v) => [...document.querySelectorAll('img.leaflet-tile')].every((i) => {
    const m = i.src.match(/controls=([A-Za-z0-9_-]+)/);
    return (m ? m[1] : null) === v;
  }), value);
  await settled(page);
}

const controlsValue = (hash) => { const m = hash.match(/controls=([A-Za-z0-9_-]+)/); return m ? m[1] : null; };

/** Press the mouse at `from`, move it to `to` in `steps` steps, release. */
async function drag(page, from, to, steps) {
  await page.mouse.move(from.x, from.y);
  await page.mouse.down();
  await page.mouse.move(to.x, to.y, { steps });
  await page.mouse.up();
}

/** Where texel (x, y) is on the page, at the map's current view. */
function screenOf(page, x, y) {
  return page.evaluate(([x, y]) => {
    const map = window.textileMap;
    const s = 2 ** map.getZoom();
    const r = map.getContainer().getBoundingClientRect();
    const p = map.latLngToContainerPoint(L.latLng(-y / s, x / s));
    return { x: r.left + p.x, y: r.top + p.y };
  }, [x, y]);
}

test('a feature dragged from the thumbnail shows the exemplar under it, strokes paint calm, the permalink restores both', async () => {
  // At native zoom (7 for the 128² gravel), one screen pixel is one texel.
  const { page, errors } = await open('/#t=gravel&m=synth&s=3&z=7&x=200&y=120');
  await settled(page);
  const find = (stats, key) => stats.find((s) => s.src.includes(key));
  const before = await tileStats(page);
  const key = '/7/0/0.png', other = '/7/1/0.png';
  assert.ok(find(before, key) && find(before, other), 'tiles 7/0/0 and 7/1/0 on screen');
  // Drag the centre of the thumbnail (exemplar texel 64, 64) onto texel (100, 60).
  const thumb = await page.locator('#thumb').boundingBox();
  const target = await screenOf(page, 100, 60);
  await drag(page, { x: thumb.x + thumb.width / 2, y: thumb.y + thumb.height / 2 }, target, 8);
  const placed = await waitControls(page, (c) => c && c.features);
  await tilesCarry(page, controlsValue(await page.evaluate(() => location.hash)));
  assert.equal(placed.features.length, 1, JSON.stringify(placed));
  const f = placed.features[0];
  assert.deepEqual(f.source, [64, 64]);
  assert.ok(Math.abs(f.at[0] - 100) <= 1 && Math.abs(f.at[1] - 60) <= 1, JSON.stringify(f));
  assert.equal(await page.locator('#p-controls-features li').count(), 1);
  const withFeature = await tileStats(page);
  assert.notEqual(find(withFeature, key).sum, find(before, key).sum, 'the tile under the feature changed');
  // Under the feature the tile is the exemplar around the dragged point, texel for texel.
  const mismatches = await page.evaluate(async ([f, key]) => {
    const pixels = async (src, w, h) => {
      const img = new Image();
      img.src = src;
      await img.decode();
      const c = document.createElement('canvas');
      c.width = w; c.height = h;
      const g = c.getContext('2d');
      g.drawImage(img, 0, 0);
      return g.getImageData(0, 0, w, h).data;
    };
    const tile = [...document.querySelectorAll('img.leaflet-tile')].find((i) => i.src.includes(key));
    const t = await pixels(tile.src, 256, 256);
    const e = await pixels(document.querySelector('#thumb').src, 128, 128);
    let bad = 0;
    for (let dy = -4; dy <= 4; dy++) {
      for (let dx = -4; dx <= 4; dx++) {
        const ti = 4 * ((f.at[1] + dy) * 256 + f.at[0] + dx), ei = 4 * ((f.source[1] + dy) * 128 + f.source[0] + dx);
        if (t[ti] !== e[ei] || t[ti + 1] !== e[ei + 1] || t[ti + 2] !== e[ei + 2]) bad++;
      }
    }
    return bad;
  }, [f, key]);
  assert.equal(mismatches, 0, 'the 9×9 texels around the feature are the exemplar around its source');
  // Paint a calm stroke across tile 7/1/0.
  await page.check('#p-controls-brush');
  const from = await screenOf(page, 300, 100), to = await screenOf(page, 480, 140);
  await drag(page, from, to, 12);
  const painted = await waitControls(page, (c) => c && c.strokes);
  assert.ok(painted.strokes.length >= 2 && painted.strokes.every((s) => s.value === 0), JSON.stringify(painted.strokes));
  assert.equal(painted.features.length, 1);
  await tilesCarry(page, controlsValue(await page.evaluate(() => location.hash)));
  const withStrokes = await tileStats(page);
  assert.notEqual(find(withStrokes, other).sum, find(withFeature, other).sum, 'the painted tile changed');
  await page.uncheck('#p-controls-brush');
  // The permalink, in a fresh page, shows the same bytes and lists the feature.
  const hash = await page.evaluate(() => location.hash);
  const second = await open('/' + hash);
  await settled(second.page);
  const restored = await tileStats(second.page);
  for (const k of [key, other]) assert.equal(find(restored, k).sum, find(withStrokes, k).sum, `${k} after reload`);
  assert.equal(await second.page.locator('#p-controls-features li').count(), 1);
  await second.page.close();
  // Move the feature by its handle, then delete it; clearing removes the controls altogether.
  const handle = await page.locator('.feature-handle').boundingBox();
  const dest = await screenOf(page, 150, 90);
  await drag(page, { x: handle.x + handle.width / 2, y: handle.y + handle.height / 2 }, dest, 8);
  const moved = await waitControls(page, (c) => Math.abs(c.features[0].at[0] - 150) <= 2);
  assert.ok(Math.abs(moved.features[0].at[1] - 90) <= 2, JSON.stringify(moved.features));
  await page.click('#p-controls-f0-delete');
  const left = await waitControls(page, (c) => !c.features);
  assert.equal(left.strokes.length, painted.strokes.length);
  assert.equal(await page.locator('#p-controls-features li').count(), 0);
  await page.click('#p-controls-clear');
  await waitControls(page, (c) => c === null);
  await tilesCarry(page, null);
  assert.deepEqual(errors, []);
  assert.deepEqual(second.errors, []);
  await page.close();
});

test('every mode is offered from the specs, with its own controls; texture picker; zoom out stays within minzoom', async () => {
  const { page, errors } = await open('/#t=gravel&z=7&x=0&y=0');
  await settled(page);
  const meta = await page.evaluate(async () => (await fetch('/textures/gravel')).json());
  const offered = await page.$$eval('#mode option', (l) => l.map((o) => o.value));
  assert.deepEqual(offered, meta.modes);
  for (const mode of meta.modes) {
    await page.selectOption('#mode', mode);
    await page.waitForFunction((m) => [...document.querySelectorAll('img.leaflet-tile')].some((i) => i.src.includes(`mode=${m}`)), mode);
    await settled(page);
    assertTexture(await tileStats(page));
    // Exactly the request parameters of this mode have controls.
    for (const [name, spec] of Object.entries(meta.parameters)) {
      if (!spec.modes || spec.scope !== 'request') continue;
      const shown = await page.$(`[id^="p-${name}"]`);
      assert.equal(Boolean(shown), spec.modes.includes(mode), `${name} control with mode=${mode}`);
    }
  }
  // The noise modulation toggle of synth puts `controls` into the tile URLs.
  await page.selectOption('#mode', 'synth');
  await page.check('#p-controls');
  await page.waitForFunction(() => [...document.querySelectorAll('img.leaflet-tile')].some((i) => i.src.includes('controls=')));
  await settled(page);
  assertTexture(await tileStats(page));
  await page.selectOption('#mode', 'mosaic');
  await page.focus('#p-iterations');
  await page.keyboard.press('ArrowLeft');
  await page.waitForFunction(() => [...document.querySelectorAll('img.leaflet-tile')].some((i) => i.src.includes('iterations=9')));
  await settled(page);
  await page.selectOption('#texture', 'brick');
  await page.waitForFunction(() => [...document.querySelectorAll('img.leaflet-tile')].some((i) => i.src.includes('/tiles/brick/')));
  await settled(page);
  assertTexture(await tileStats(page));
  await page.evaluate(() => window.textileMap.setZoom(0, { animate: false }));
  await settled(page, 1);
  assert.equal(await page.evaluate(() => window.textileMap.getZoom()), 0);
  assert.deepEqual(errors, []);
  await page.close();
});

test('the map picker shows a material\'s maps, and the lit view shades colour by normals under a movable light', async () => {
  const { page, errors } = await open('/#t=flagstones&z=8&x=0&y=0');
  await settled(page);
  const offered = await page.$$eval('#mapsel option', (l) => l.map((o) => o.value));
  assert.deepEqual(offered, ['albedo', 'height', 'normal', 'specular', 'lit']);
  await page.selectOption('#mapsel', 'normal');
  await page.waitForFunction(() => [...document.querySelectorAll('img.leaflet-tile')].some((i) => i.src.includes('map=normal')));
  await settled(page);
  // Normal tiles: mostly facing up (blue high, red and green around the middle).
  const mean = await page.evaluate(() => {
    const img = [...document.querySelectorAll('img.leaflet-tile')].find((i) => i.src.includes('map=normal') && i.complete);
    const c = document.createElement('canvas');
    c.width = c.height = 256;
    const ctx = c.getContext('2d');
    ctx.drawImage(img, 0, 0);
    const d = ctx.getImageData(0, 0, 256, 256).data;
    const m = [0, 0, 0];
    for (let i = 0; i < d.length; i += 4) for (let j = 0; j < 3; j++) m[j] += d[i + j] / (d.length / 4);
    return m;
  });
  assert.ok(mean[2] > 200 && Math.abs(mean[0] - 128) < 30 && Math.abs(mean[1] - 128) < 30, `normal tile means ${mean}`);
  assert.equal(await page.isVisible('#lightrow'), false, 'the light shows with the lit view only');
  // Lit: canvases drawn from colour and normals; moving the light changes them; the permalink keeps it.
  await page.selectOption('#mapsel', 'lit');
  assert.equal(await page.isVisible('#lightrow'), true);
  await page.waitForFunction(() => document.querySelectorAll('canvas[data-lit="1"]').length >= 4);
  const pixels = () => page.evaluate(() => {
    const c = document.querySelector('canvas[data-lit="1"]');
    return Array.from(c.getContext('2d').getImageData(0, 0, 64, 64).data);
  });
  const before = await pixels();
  await page.focus('#light');
  for (let i = 0; i < 90; i++) await page.keyboard.press('ArrowRight');
  await page.waitForFunction(() => location.hash.includes('l=225'));
  const after = await pixels();
  const changed = before.filter((v, i) => v !== after[i]).length;
  assert.ok(changed > 1000, `only ${changed} channel values changed with the light`);
  assert.match(await page.evaluate(() => location.hash), /a=lit/);
  // Umbrella patches have every map too: the lit view stays, drawn from umbrella normals.
  await page.selectOption('#mode', 'umbrella');
  assert.deepEqual(await page.$$eval('#mapsel option', (l) => l.map((o) => o.value)), offered);
  assert.equal(await page.$eval('#mapsel', (s) => s.value), 'lit');
  await page.waitForFunction(() => performance.getEntriesByType('resource').some((e) => e.name.includes('mode=umbrella') && e.name.includes('map=normal')));
  await page.waitForFunction(() => document.querySelectorAll('canvas[data-lit="1"]').length >= 4);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a near-regular texture shows its lattice, overlays it, and greys out the mode that declines it', async () => {
  const { page, errors } = await open('/#t=brick&m=umbrella&z=7&x=0&y=0');
  await settled(page);
  const meta = await page.evaluate(async () => (await fetch('/textures/brick')).json());
  assert.ok(meta.declined_modes.umbrella, JSON.stringify(meta.declined_modes));
  // The declined mode is offered disabled, with its reason, and the view fell back to another.
  const umbrella = await page.$eval('#mode option[value="umbrella"]', (o) => ({ disabled: o.disabled, title: o.title }));
  assert.deepEqual(umbrella, { disabled: true, title: meta.declined_modes.umbrella });
  assert.notEqual(await page.$eval('#mode', (s) => s.value), 'umbrella');
  assert.ok(await page.evaluate(() => [...document.querySelectorAll('img.leaflet-tile')].every((i) => !i.src.includes('mode=umbrella'))));
  // The lattice row names the detected waves; the overlay draws its lines.
  assert.equal(await page.$eval('#latticerow', (r) => r.hidden), false);
  const info = await page.$eval('#latticeinfo', (o) => o.textContent);
  assert.match(info, new RegExp(`^stripes: ${meta.exemplar.lattice.waves[0].period.toFixed(2)} px`), info);
  await page.check('#lattice');
  await page.waitForSelector('canvas.lattice-tile');
  const lines = await page.$$eval('canvas.lattice-tile', (cs) => cs.map((c) => {
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let cyan = 0;
    for (let i = 0; i < d.length; i += 4) if (d[i + 3] > 100 && d[i + 1] > 200 && d[i + 2] > 200 && d[i] < 80) cyan++;
    return cyan;
  }));
  // Stripes every ~18 texels: about 14 one-pixel lines down each 256 px tile.
  assert.ok(lines.length > 0 && lines.every((n) => n > 256 * 8), JSON.stringify(lines));
  // The overlay is in the permalink, and a page opened at it shows the overlay.
  await page.waitForFunction(() => /[#&]k=1(&|$)/.test(location.hash));
  const link = await page.evaluate(() => location.hash);
  const again = await open(`/${link}`);
  await settled(again.page);
  await again.page.waitForSelector('canvas.lattice-tile');
  assert.equal(await again.page.isChecked('#lattice'), true);
  assert.deepEqual(again.errors, []);
  await again.page.close();
  // A stochastic texture has no lattice row.
  await page.selectOption('#texture', 'gravel');
  await page.waitForFunction(() => [...document.querySelectorAll('img.leaflet-tile')].some((i) => i.src.includes('/tiles/gravel/')));
  assert.equal(await page.$eval('#latticerow', (r) => r.hidden), true);
  assert.equal(await page.$$eval('canvas.lattice-tile', (cs) => cs.length), 0);
  assert.doesNotMatch(await page.evaluate(() => location.hash), /[#&]k=1/);
  assert.deepEqual(errors, []);
  await page.close();
});

// Pixels of the thumbnail's structure overlay in a colour: cyan (lattice) or yellow (copies).
const overlayPixels = (page, colour) => page.$eval('#thumblattice', (c, colour) => {
  const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let n = 0;
  for (let i = 0; i < d.length; i += 4) {
    if (d[i + 3] < 100) continue;
    const cyan = d[i] < 80 && d[i + 1] > 200 && d[i + 2] > 200;
    const yellow = d[i] > 200 && d[i + 1] > 180 && d[i + 2] < 80;
    if ((colour === 'cyan' && cyan) || (colour === 'yellow' && yellow)) n++;
  }
  return n;
}, colour);

test('the exemplar thumbnail shows its detected structure: lattice, tile repeated, or none', async () => {
  const { page, errors } = await open('/#t=brick&z=7&x=0&y=0');
  await settled(page);
  // Brick: its columns, drawn over the thumbnail (about 7 lines across 128 texels) and named.
  await page.waitForFunction(() => document.querySelector('#thumblattice').dataset.structure === 'lattice');
  assert.match(await page.$eval('#structureinfo', (p) => p.textContent), /^Near-regular: a 1-D lattice, basis \[dy, dx\] \[0\.0, 18\.0\]/);
  const brickLines = await overlayPixels(page, 'cyan');
  assert.ok(brickLines > 128 * 2 * 5, `brick's lattice lines: ${brickLines} cyan pixels`);
  assert.equal(await overlayPixels(page, 'yellow'), 0);
  // The embedded corkboard is its 64 × 32 cell repeated: the tiles are outlined and the size said.
  await page.selectOption('#texture', 'corkboard');
  await page.waitForFunction(() => document.querySelector('#thumblattice').dataset.structure === 'exact');
  assert.match(await page.$eval('#structureinfo', (p) => p.textContent), /^Exact repeat: a 64×32 px tile repeated/);
  const tiles = await overlayPixels(page, 'yellow');
  assert.ok(tiles > 128 * 2 * 4, `corkboard's tile outlines: ${tiles} yellow pixels`);
  await page.screenshot({ path: process.env.TEXTILE_SCREENSHOT.replace(/\.png$/, '-structure.png'), clip: { x: 0, y: 0, width: 300, height: 260 } });
  // Gravel: nothing drawn, and said so.
  await page.selectOption('#texture', 'gravel');
  await page.waitForFunction(() => document.querySelector('#thumblattice').dataset.structure === 'none');
  assert.equal(await page.$eval('#structureinfo', (p) => p.textContent), 'No lattice: stochastic.');
  assert.equal(await overlayPixels(page, 'cyan') + await overlayPixels(page, 'yellow'), 0);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a landscape is picked beside the textures, lists its layers, and overlays its splat with a legend', async () => {
  const { page, errors, tiles } = await open('/#t=meadow&z=7&x=0&y=0');
  await settled(page);
  assertTexture(await tileStats(page));
  assert.ok(tiles.every((t) => t.status === 200 && !t.url.includes('mode=')), JSON.stringify(tiles.slice(0, 3)));
  const groups = await page.$$eval('#texture optgroup', (gs) => gs.map((g) => [g.label, [...g.children].map((o) => o.value)]));
  assert.deepEqual(groups.map((g) => g[0]), ['Textures', 'Landscapes']);
  assert.ok(groups[1][1].includes('meadow'));
  assert.equal(await page.isVisible('#mode'), false, 'a landscape has no mode of its own');
  const legend = await page.$$eval('#legend li', (l) => l.map((li) => [li.textContent, li.querySelector('.swatch').style.background]));
  assert.equal(legend.length, 3, JSON.stringify(legend));
  assert.ok(legend[0][0].startsWith('Grass') && legend[0][1].length > 0, JSON.stringify(legend));
  await page.check('#splat');
  await page.waitForFunction(() => [...document.querySelectorAll('.splat-tile img')].some((i) => i.complete && i.naturalWidth === 256 && i.src.includes('map=splat')));
  assert.match(page.url(), /[#&]o=1/);
  // The overlay's colours are the legend's: somewhere a pixel is (nearly) the grass colour.
  const greenish = await page.evaluate(() => [...document.querySelectorAll('.splat-tile img')].filter((i) => i.complete && i.naturalWidth).some((img) => {
    const c = document.createElement('canvas');
    c.width = c.height = 256;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, 256, 256).data;
    for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - 0x5a) < 4 && Math.abs(d[i + 1] - 0x8f) < 4 && Math.abs(d[i + 2] - 0x3c) < 4) return true;
    return false;
  }));
  assert.ok(greenish, 'the splat overlay shows the grass colour');
  // The permalink keeps the overlay.
  const again = await open(new URL(page.url()).hash ? '/' + new URL(page.url()).hash : '/');
  await again.page.waitForFunction(() => document.querySelector('#splat').checked && document.querySelector('.splat-tile img'));
  assert.deepEqual([...errors, ...again.errors], []);
  await again.page.close();
  await page.close();
});

test('readable on a phone-sized viewport', async () => {
  const { page, errors } = await open('/', { width: 390, height: 844 });
  await settled(page, 1);
  const box = async (sel) => page.$eval(sel, (e) => { const r = e.getBoundingClientRect(); return { w: r.width, h: r.height }; });
  const map = await box('#map');
  const panel = await box('#panel');
  assert.ok(map.w >= 380 && map.h > 300, JSON.stringify(map));
  assert.ok(panel.w >= 380 && panel.h > 100, JSON.stringify(panel));
  assert.deepEqual(errors, []);
  await page.close();
});

test('the Web-Mercator world page wraps the world with world= tiles', async () => {
  const { page, errors, tiles } = await open('/world.html');
  await page.waitForFunction(() => window.textileWorld && window.textileWorld.getAllLayers()[0].getSource().getState() === 'ready');
  const requested = async () => { await page.waitForTimeout(200); return tiles.length; };
  await page.waitForFunction(() => performance.getEntriesByType('resource').some((e) => e.name.includes('/tiles/')));
  await page.evaluate(() => new Promise((ok) => window.textileWorld.once('rendercomplete', ok)));
  await page.evaluate(() => { window.textileWorld.getView().setCenter([20037508, 0]); });
  await page.evaluate(() => new Promise((ok) => window.textileWorld.once('rendercomplete', ok)));
  assert.ok((await requested()) > 0);
  for (const t of tiles) {
    const m = t.url.match(/\/tiles\/\w+\/(\d+)\/(-?\d+)\/(-?\d+)\.png\?(.*)$/);
    assert.ok(m, t.url);
    const [z, x, y] = [Number(m[1]), Number(m[2]), Number(m[3])];
    assert.ok(x >= 0 && x < 2 ** z && y >= 0 && y < 2 ** z, `tile outside the world: ${t.url}`);
    assert.match(m[4], /world=\d+/);
    assert.equal(t.status, 200, t.url);
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test('with the admin token, the upload form adds a texture that is then shown', async () => {
  const admin = process.env.TEXTILE_URL_ADMIN;
  assert.ok(admin, 'TEXTILE_URL_ADMIN must name a server with an admin token');
  // Without an admin API there is no form.
  const plain = await open('/');
  assert.equal(await plain.page.$eval('#upload', (e) => e.hidden), true);
  await plain.page.close();
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(admin + '/');
  await page.waitForSelector('body[data-ready="1"]', { timeout: 20000 });
  await page.click('#upload summary');
  const png = readFileSync(new URL('../../config/exemplars/brick.png', import.meta.url));
  // A wrong token is refused, and said so.
  await page.fill('#u-token', 'not-the-token-at-all');
  await page.setInputFiles('#u-file', { name: 'My Bricks.png', mimeType: 'image/png', buffer: png });
  assert.equal(await page.inputValue('#u-id'), 'my-bricks', 'the id is suggested from the file name');
  await page.fill('#u-name', 'My bricks');
  await page.click('#u-send');
  await page.waitForFunction(() => /upload failed/.test(document.querySelector('#u-status').textContent));
  assert.match(await page.textContent('#u-status'), /token/);
  // The right one: progress, then the new texture is selected and its tiles load.
  await page.fill('#u-token', process.env.TEXTILE_ADMIN_TOKEN);
  await page.click('#u-send');
  await page.waitForFunction(() => /added/.test(document.querySelector('#u-status').textContent), null, { timeout: 60000 });
  assert.equal(await page.inputValue('#texture'), 'my-bricks');
  assert.match(page.url(), /t=my-bricks/);
  await settled(page, 4);
  const stats = await tileStats(page);
  assert.ok(stats.every((t) => t.src.includes('/tiles/my-bricks/')), JSON.stringify(stats.map((t) => t.src)));
  assertTexture(stats);
  assert.deepEqual(errors, []);
  await page.close();
});
