// textile's 3D documents in the clients users run, in headless Chromium (WebGL on SwiftShader):
// three.js GLTFLoader on bordered, mipmapped glTF tiles; X_ITE on X3D documents; the 3D viewer
// page (/3d.html: 3DTilesRendererJS on the 3D Tiles tileset); CesiumJS on the tileset anchored
// on the globe. Run by tests/browser.rs against the real binary (TEXTILE_URL, a server that
// queues rather than sheds); pictures go to TEXTILE_ARTEFACTS.
//
// The libraries come from this folder's node_modules (pinned by package-lock.json) and are
// served on the server's own origin under /__3d/ by Playwright's request routing, so every
// request the page makes is same-origin; nothing of textile is mocked.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync, mkdirSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const BASE = process.env.TEXTILE_URL;
const ARTEFACTS = process.env.TEXTILE_ARTEFACTS;
const HERE = dirname(fileURLToPath(import.meta.url));
const MODULES = join(HERE, 'node_modules');
let browser;

const TYPES = { js: 'text/javascript', mjs: 'text/javascript', html: 'text/html', css: 'text/css' };

const THREE_PAGE = `<!doctype html><html><head><meta charset="utf-8">
<script type="importmap">{"imports": {"three": "/__3d/three/build/three.module.js",
  "three/addons/": "/__3d/three/examples/jsm/"}}</script></head>
<body><script type="module">
  import * as scenes from '/__3d/clients3d/three-scenes.js';
  window.scenes = scenes;
  document.body.dataset.ready = '1';
</script></body></html>`;

const X3D_PAGE = `<!doctype html><html><head><meta charset="utf-8">
<script src="/__3d/x_ite/dist/x_ite.min.js"></script>
<script type="module">import * as pixels from '/__3d/clients3d/pixels.js'; window.pixels = pixels;</script>
<style>body { margin: 0 } x3d-canvas { display: block; width: 512px; height: 512px }</style></head>
<body><x3d-canvas splashScreen="false" contextMenu="false" notifications="false"></x3d-canvas></body></html>`;

const CESIUM_PAGE = `<!doctype html><html><head><meta charset="utf-8">
<script>window.CESIUM_BASE_URL = '/__3d/cesium/Build/Cesium/';</script>
<script src="/__3d/cesium/Build/Cesium/Cesium.js"></script>
<link rel="stylesheet" href="/__3d/cesium/Build/Cesium/Widgets/widgets.css">
<style>html, body, #globe { margin: 0; width: 100%; height: 100%; }</style></head>
<body><div id="globe"></div>
<script>
  // The README's recipe: a viewer on the bare ellipsoid, lit by the real sun at the clock's
  // time, set to midday at the anchor (Paris: solar noon about 11:50 UTC), else a night view
  // is dark.
  window.dayViewer = () => {
    const viewer = new Cesium.Viewer('globe', {
      baseLayer: false, baseLayerPicker: false, geocoder: false, timeline: false, animation: false,
      homeButton: false, sceneModePicker: false, navigationHelpButton: false, fullscreenButton: false,
      infoBox: false, selectionIndicator: false, terrainProvider: new Cesium.EllipsoidTerrainProvider(),
    });
    viewer.clock.currentTime = Cesium.JulianDate.fromIso8601('2026-06-21T11:50:00Z');
    viewer.clock.shouldAnimate = false;
    viewer.scene.screenSpaceCameraController.maximumZoomDistance = 20000;
    return viewer;
  };
</script></body></html>`;

before(async () => {
  assert.ok(BASE, 'TEXTILE_URL must name the server under test');
  browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
      '--ignore-gpu-blocklist', '--disable-background-networking', '--disable-component-update',
      '--disable-sync', '--no-first-run'],
  });
});

after(async () => { await browser?.close(); });

/** A page on the server's origin whose /__3d/ paths are this folder's files. */
async function open(html, viewport = { width: 800, height: 600 }) {
  const page = await browser.newPage({ viewport });
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.route(`${BASE}/__3d/**`, (route) => {
    const path = new URL(route.request().url()).pathname.slice('/__3d/'.length);
    if (path === 'page.html') return route.fulfill({ body: html, contentType: 'text/html' });
    const file = path.startsWith('clients3d/') ? join(HERE, path) : join(MODULES, path);
    const ext = path.split('.').pop();
    return route.fulfill({ body: readFileSync(file), contentType: TYPES[ext] ?? 'application/octet-stream' });
  });
  await page.goto(`${BASE}/__3d/page.html`);
  return { page, errors };
}

function save(name, dataUrl) {
  if (!ARTEFACTS) return;
  mkdirSync(ARTEFACTS, { recursive: true });
  writeFileSync(join(ARTEFACTS, name), Buffer.from(dataUrl.split(',')[1], 'base64'));
}

/** A screenshot of the page (base64 PNG) and the RGBA pixels of a part of it: `[x, y, w, h]`
 * as shares of its width and height. */
async function screenshot(page, [fx, fy, fw, fh]) {
  const png = (await page.screenshot()).toString('base64');
  const data = await page.evaluate(async ([src, fx, fy, fw, fh]) => {
    const img = new Image();
    img.src = src;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width; c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const [x, y] = [Math.floor(fx * img.width), Math.floor(fy * img.height)];
    return Array.from(g.getImageData(x, y, Math.floor(fw * img.width), Math.floor(fh * img.height)).data);
  }, [`data:image/png;base64,${png}`, fx, fy, fw, fh]);
  return { png, data };
}

/** /3d.html at `hash` in a page of its own, once its tileset has loaded; its console errors. */
async function open3d(hash, viewport = { width: 800, height: 560 }) {
  const page = await browser.newPage({ viewport });
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(`${BASE}/3d.html#${hash}`);
  await page.waitForSelector('body[data-ready="1"]', { state: 'attached', timeout: 30000 });
  return { page, errors };
}

function fmt(s) {
  return `edges ${s.edges.mean.toFixed(2)} levels (${(100 * s.edges.over8).toFixed(2)} % > 8, ${s.edges.pixels} px), ` +
    `elsewhere ${s.elsewhere.mean.toFixed(2)} (${(100 * s.elsewhere.over8).toFixed(2)} % > 8, ${s.elsewhere.pixels} px)`;
}

// Up close, from a camera 12 texels above tile (0, 0) near its north-west corner, looking
// north-west across the two tile edges that meet there.
const CLOSE = { eye: [6, 12, 30], at: [-40, 0, -50], fov: 60 };
// Far: a 7×7 ring at a grazing angle; the distant tiles are minified 10× and more.
const FAR = { eye: [0, 40, 890], at: [0, 0, -400], fov: 60 };

test('three.js: bordered tiles filter like one texture up close', async () => {
  const { page, errors } = await open(THREE_PAGE);
  await page.waitForFunction(() => window.scenes);
  const r = await page.evaluate((args) => window.scenes.closeView(args),
    { base: BASE, id: 'gravel', z: 7, query: '?seed=4', view: CLOSE, w: 640, h: 400, reach: 2 });
  for (const [k, v] of Object.entries(r.pictures)) save(`three-close-${k}.png`, v);
  console.log(`close view, bordered mipmapped tiles vs one texture: ${fmt(r.tiles)}`);
  console.log(`close view, bare tiles (before) vs one texture:      ${fmt(r.bare)}`);
  assert.ok(r.tiles.edges.pixels > 2000 && r.tiles.elsewhere.pixels > 50000, 'the view shows edges and tiles');
  // The bound: along edges no worse than elsewhere plus a quarter level on average, and no more
  // pixels off by over 8 levels than elsewhere plus 0.1 % (rounding in the two mip chains).
  assert.ok(r.tiles.edges.mean <= r.tiles.elsewhere.mean + 0.25, fmt(r.tiles));
  assert.ok(r.tiles.edges.over8 <= r.tiles.elsewhere.over8 + 0.001, fmt(r.tiles));
  // The comparison sees seams where they exist: the bare tiles' edges stand out.
  assert.ok(r.bare.edges.over8 > r.bare.elsewhere.over8 + 0.01, `bare tiles: ${fmt(r.bare)}`);
  assert.deepEqual(errors, []);
  await page.close();
});

test('three.js: mipmapped tiles far away are closer to a supersampled reference', async () => {
  const { page, errors } = await open(THREE_PAGE);
  await page.waitForFunction(() => window.scenes);
  const r = await page.evaluate((args) => window.scenes.farView(args),
    { base: BASE, id: 'gravel', z: 7, query: '?seed=4', view: FAR, w: 480, h: 300, n: 7 });
  for (const [k, v] of Object.entries(r.pictures)) save(`three-far-${k}.png`, v);
  const m = (s) => `${s.elsewhere.mean.toFixed(2)} levels mean, ${(100 * s.elsewhere.over8).toFixed(1)} % > 8`;
  console.log(`far view vs 4x-supersampled reference: mipmapped tiles ${m(r.tiles)}; bare tiles (before) ${m(r.bare)}`);
  assert.ok(r.tiles.elsewhere.pixels > 50000);
  assert.ok(r.tiles.elsewhere.mean < r.bare.elsewhere.mean, `${m(r.tiles)} vs ${m(r.bare)}`);
  assert.deepEqual(errors, []);
  await page.close();
});

test('three.js: a material tile is lit by its normal map, the right way round', async () => {
  const { page, errors } = await open(THREE_PAGE);
  await page.waitForFunction(() => window.scenes);
  const r = await page.evaluate((args) => window.scenes.litView(args),
    { base: BASE, id: 'flagstones', z: 8, x: 3, y: -2, query: '?seed=2' });
  console.log(`lit flagstones tile: material ${JSON.stringify(r.holds)}; correlation of east-west light with normal x ` +
    `${r.ew.toFixed(3)}, north-south with normal y ${r.ns.toFixed(3)} (east-west with y: ${r.swapped.toFixed(3)})`);
  assert.ok(r.holds.normalMap && r.holds.specular, JSON.stringify(r.holds));
  assert.ok(r.ew > 0.5 && r.ns > 0.5, `normals light the wrong way: ${r.ew}, ${r.ns}`);
  assert.ok(Math.abs(r.swapped) < r.ew / 2, `x and y mixed up: ${r.swapped}`);
  assert.deepEqual(errors, []);
  await page.close();
});

/** Load an X3D document into the page's X_ITE canvas and wait until its texture has arrived
 * (the canvas is not black and two looks in a row agree); the last look stays in the page as
 * `window.shot` (see clients3d/pixels.js). Returns its size, mean level and PNG data URL. */
async function x3dShot(page, path) {
  await page.evaluate(async (url) => {
    const canvas = document.querySelector('x3d-canvas');
    await canvas.browser.loadURL(new X3D.MFString(url));
  }, BASE + path);
  let last;
  for (let i = 0; i < 80; i++) {
    await page.waitForTimeout(250);
    const png = await page.locator('x3d-canvas').screenshot();
    const next = await page.evaluate((b64) => window.pixels.look(b64), png.toString('base64'));
    if (last && next.mean > 10 && next.mean === last.mean) return next;
    last = next;
  }
  return last;
}

test('X_ITE: a tile document shows the tile, seen from above', async () => {
  const { page, errors } = await open(X3D_PAGE);
  await page.waitForFunction(() => window.X3D && window.pixels && document.querySelector('x3d-canvas')?.browser);
  const shot = await x3dShot(page, '/x3d/gravel/7/1/2.x3d?seed=3');
  save('x3d-tile.png', shot.url);
  assert.ok(shot.mean > 10, `the canvas is black (mean level ${shot.mean})`);
  const tile = `${BASE}/tiles/gravel/7/1/2.png?seed=3`;
  const r = await page.evaluate((url) => window.pixels.correlate(url, 1, 1), tile);
  console.log(`X_ITE top-down render vs the tile image: correlation ${r.toFixed(3)}, mean level ${shot.mean.toFixed(1)}`);
  assert.ok(r > 0.9, `correlation ${r}`);
  // A 3×3 patch document: the centre third of the view is the centre tile (compared at a
  // quarter of its size: the render is minified 1.5×, through mipmaps).
  const patch = await x3dShot(page, '/x3d/gravel/patch.x3d?z=7&x=0&y=1&tiles=3&seed=3');
  save('x3d-patch.png', patch.url);
  const rp = await page.evaluate((url) => window.pixels.correlate(url, 3, 4), tile);
  console.log(`X_ITE patch: centre tile correlation ${rp.toFixed(3)}`);
  assert.ok(rp > 0.8, `patch centre correlation ${rp}`);
  // A landscape's tile document (the meadow, where its layers meet): the landscape's tile.
  const land = await x3dShot(page, '/x3d/meadow/8/3/4.x3d?seed=3');
  save('x3d-landscape.png', land.url);
  const rl = await page.evaluate((url) => window.pixels.correlate(url, 1, 1), `${BASE}/tiles/meadow/8/3/4.png?seed=3`);
  console.log(`X_ITE landscape tile vs the landscape's tile image: correlation ${rl.toFixed(3)}`);
  assert.ok(rl > 0.9, `landscape correlation ${rl}`);
  assert.deepEqual(errors, []);
  await page.close();
});

test('X_ITE: a material tile document is lit by its normal map, the right way round', async () => {
  const { page, errors } = await open(X3D_PAGE);
  await page.waitForFunction(() => window.X3D && window.pixels && document.querySelector('x3d-canvas')?.browser);
  const doc = '/x3d/flagstones/8/3/-2.x3d?seed=2';
  // The document's own light, from above: a level surface shows at its albedo (X_ITE's
  // headlight alone, of intensity 1, showed 92 against the tile's 158).
  const shot = await x3dShot(page, doc);
  const albedo = await page.evaluate(async (url) => {
    const img = new Image();
    img.src = url;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width; c.height = img.height;
    c.getContext('2d').drawImage(img, 0, 0);
    const d = c.getContext('2d').getImageData(0, 0, img.width, img.height).data;
    let sum = 0;
    for (let i = 0; i < d.length; i += 4) sum += (d[i] + d[i + 1] + d[i + 2]) / 3;
    return sum / (d.length / 4);
  }, `${BASE}/tiles/flagstones/8/3/-2.png?seed=2`);
  console.log(`X_ITE flagstones from above: mean level ${shot.mean.toFixed(1)}, the albedo tile's ${albedo.toFixed(1)}`);
  assert.ok(Math.abs(shot.mean / albedo - 1) < 0.15, `lit ${shot.mean} against albedo ${albedo}`);
  // The headlight off, a low sun from each side in turn (X east, Y up, Z south).
  const lit = async (name, direction) => {
    await page.evaluate((d) => {
      const scene = document.querySelector('x3d-canvas').browser.currentScene;
      if (!window.sun) {
        for (const n of scene.rootNodes) if (n.getNodeTypeName() === 'NavigationInfo') n.headlight = false;
        window.sun = scene.createNode('DirectionalLight');
        scene.addRootNode(window.sun);
      }
      window.sun.direction = new X3D.SFVec3f(...d);
      window.sun.intensity = 1;
    }, direction);
    let last;
    for (let i = 0; i < 40; i++) {
      await page.waitForTimeout(250);
      const png = await page.locator('x3d-canvas').screenshot();
      const next = await page.evaluate((b64) => window.pixels.look(b64), png.toString('base64'));
      if (last && next.mean === last.mean) break;
      last = next;
    }
    await page.evaluate((n) => window.pixels.keep(n), name);
    return last;
  };
  const east = await lit('east', [-1, -0.6, 0]);
  save('x3d-material-east.png', east.url);
  await lit('west', [1, -0.6, 0]);
  await lit('north', [0, -0.6, 1]);
  await lit('south', [0, -0.6, -1]);
  const normals = `${BASE}/tiles/flagstones/8/3/-2.png?seed=2&map=normal`;
  const ew = await page.evaluate((u) => window.pixels.change('east', 'west', u, 0, 4), normals);
  const ns = await page.evaluate((u) => window.pixels.change('north', 'south', u, 1, 4), normals);
  const swapped = await page.evaluate((u) => window.pixels.change('east', 'west', u, 1, 4), normals);
  console.log(`X_ITE lit flagstones: east-west light vs normal x ${ew.toFixed(3)}, north-south vs y ${ns.toFixed(3)} ` +
    `(east-west vs y ${swapped.toFixed(3)})`);
  assert.ok(ew > 0.5 && ns > 0.5, `normals light the wrong way: ${ew}, ${ns}`);
  assert.ok(Math.abs(swapped) < ew / 2, `x and y mixed up: ${swapped}`);
  assert.deepEqual(errors, []);
  await page.close();
});

/** Wait until the 3D page's tiles are all loaded for the current view (two looks in a row). */
async function settled3d(page, timeout = 180000) {
  await page.waitForFunction(() => window.textile3d?.settled(), null, { timeout, polling: 200 });
  await page.waitForTimeout(300);
  await page.waitForFunction(() => window.textile3d.settled(), null, { timeout, polling: 200 });
}

test('3DTilesRendererJS on /3d.html: the tileset streams, and LOD follows the camera', async () => {
  const page = await browser.newPage({ viewport: { width: 1000, height: 640 } });
  const errors = [];
  const warnings = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); if (m.type() === 'warning') warnings.push(m.text()); });
  page.on('pageerror', (e) => errors.push(String(e)));
  const failed = [];
  page.on('response', (r) => { if (r.url().includes('/3dtiles/') && r.status() !== 200) failed.push(`${r.status()} ${r.url()}`); });
  const t0 = Date.now();
  // Low over the ground, near the middle of the root tile (gravel: 32768 texels wide).
  await page.goto(`${BASE}/3d.html#t=gravel&m=synth&seed=4&cam=16384,150,16534,16384,0,16384`);
  await page.waitForSelector('body[data-ready="1"]', { state: 'attached', timeout: 30000 });
  await settled3d(page);
  console.log(`3D page: first full view (150 texels up) in ${Date.now() - t0} ms`);
  save('3d-page-low.png', `data:image/png;base64,${(await page.screenshot()).toString('base64')}`);
  // Rise: coarser levels replace finer ones on screen.
  const visible = async () => page.evaluate(() => window.textile3d.visibleLevels());
  const finest = (v) => Math.max(...Object.keys(v).map(Number));
  const views = [await visible()];
  for (const h of [1200, 5000, 14000]) {
    await page.evaluate((h) => window.textile3d.look([16384, h, 16384 + h], [16384, 0, 16384]), h);
    await settled3d(page);
    views.push(await visible());
  }
  save('3d-page-high.png', `data:image/png;base64,${(await page.screenshot()).toString('base64')}`);
  const requested = await page.evaluate(() => window.textile3d.requested.length);
  console.log(`3D page: ${requested} content tiles requested; tiles on screen by level as the camera rises ` +
    `(150, 1200, 5000, 14000): ${views.map((v) => JSON.stringify(v)).join(' → ')}`);
  const shown = new Set(views.flatMap((v) => Object.keys(v)));
  assert.ok(shown.size >= 3, `tiles of ${shown.size} levels shown: ${[...shown]}`);
  for (let i = 1; i < views.length; i++) {
    assert.ok(finest(views[i]) <= finest(views[i - 1]), `rising never shows finer tiles: ${JSON.stringify(views)}`);
  }
  assert.ok(finest(views.at(-1)) < finest(views[0]), 'the high view shows coarser tiles than the low one');
  assert.deepEqual(failed, []);
  assert.deepEqual(errors, []);
  // The permalink holds the view.
  assert.match(page.url(), /cam=16384,14000,30384,16384,0,16384/);
  // The mode's parameters are offered (synth: its randomness, one value for every level), and
  // moving one reloads the tileset with it.
  assert.ok(await page.$('#p-randomness'), `synth's parameters on the 3D page: ${await page.innerText('#controls')}`);
  await page.evaluate(() => { const s = document.querySelector('#p-randomness'); s.value = '0.5'; s.dispatchEvent(new Event('input')); });
  await page.waitForFunction(() => document.querySelector('#tilesetlink').href.includes('randomness=0.5'), null, { timeout: 5000 });
  assert.deepEqual(warnings.filter((w) => /maxJobs|deprecat/i.test(w)), [], 'no deprecation warnings');
  await page.close();
});

test('/3d.html lights a material with a sun whose direction a slider turns', async () => {
  const { page, errors } = await open3d('t=flagstones&m=synth&seed=2&sun=0&cam=32768,200,32868,32768,0,32768');
  await settled3d(page);
  assert.equal(await page.isVisible('#sunrow'), true, 'a material with normals offers the sun');
  const grab = () => page.evaluate(() => {
    const c = document.querySelector('#view canvas');
    const g = document.createElement('canvas');
    g.width = 200; g.height = 140;
    g.getContext('2d').drawImage(c, c.width / 2 - 200, c.height / 2 - 140, 400, 280, 0, 0, 200, 140);
    return Array.from(g.getContext('2d').getImageData(0, 0, 200, 140).data);
  });
  const east = await grab();
  await page.evaluate(() => { const s = document.querySelector('#sun'); s.value = '180'; s.dispatchEvent(new Event('input')); });
  await page.waitForTimeout(300);
  const west = await grab();
  let diff = 0;
  for (let i = 0; i < east.length; i += 4) diff += Math.abs(east[i] - west[i]) / (east.length / 4);
  console.log(`3D page, flagstones: the sun from the east vs the west changes pixels by ${diff.toFixed(1)} levels on average`);
  assert.ok(diff > 6, `turning the sun barely changes the relief: ${diff}`);
  assert.match(page.url(), /sun=180/);
  assert.equal(await page.textContent('#sunvalue'), '180°', 'the sun slider shows its value');
  save('3d-page-material.png', `data:image/png;base64,${(await page.screenshot()).toString('base64')}`);
  // A texture without maps is shown as it is: no sun.
  await page.selectOption('#texture', 'gravel');
  await page.waitForFunction(() => window.textile3d.state.t === 'gravel');
  assert.equal(await page.isVisible('#sunrow'), false);
  assert.doesNotMatch(page.url(), /sun=/);
  assert.deepEqual(errors, []);
  await page.close();
});

/** Open /3d.html at `hash` (relief 8, camera near texel (32768, 32768)) and count the
 * background pixels through the ground in a near, an oblique and a horizon view. */
async function reliefCracks(hash, label) {
  // A smaller page with the panel still beside the view, which keeps its shape (368×400 against
  // 512×560): a crack runs along a tile's edge, tens of pixels long at this size too, and the
  // views settle in about half the time.
  const { page, errors } = await open3d(`${hash}&relief=8&cam=32768,30,32800,32768,0,32768`, { width: 656, height: 400 });
  assert.match(await page.evaluate(() => document.querySelector('#tilesetlink').href), /relief=8/);
  assert.equal(await page.isVisible('#reliefrow'), true, `${label} offers relief`);
  assert.equal(await page.inputValue('#relief'), '8');
  assert.equal(await page.textContent('#reliefvalue'), '8 texels', 'the relief slider shows its value');
  // The scene's background (0xbfd1e5) where the ground should be: the rows below `from` (a
  // share of the height: the oblique and horizon views show the sky above the horizon).
  const sky = (from) => page.evaluate((from) => {
    const c = document.querySelector('#view canvas');
    const g = document.createElement('canvas');
    g.width = c.width; g.height = c.height;
    const ctx = g.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, Math.floor(from * c.height), c.width, c.height - Math.floor(from * c.height)).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - 191) + Math.abs(d[i + 1] - 209) + Math.abs(d[i + 2] - 229) <= 9) n++;
    }
    return n;
  }, from);
  const views = [
    ['near', [32768, 30, 32800], [32768, 0, 32768], 0],
    ['oblique', [32768, 160, 33100], [32768, 0, 32700], 0.2],
    ['horizon', [32768, 24, 33600], [32768, 14, 32400], 0.6],
  ];
  const found = {};
  for (const [name, eye, target, from] of views) {
    await page.evaluate(([e, t]) => window.textile3d.look(e, t), [eye, target]);
    await settled3d(page);
    found[name] = await sky(from);
    save(`3d-relief-${label}-${name}.png`, `data:image/png;base64,${(await page.screenshot()).toString('base64')}`);
  }
  console.log(`3D page, ${label} relief=8: background pixels through the ground ${JSON.stringify(found)}`);
  save(`3d-relief-${label}.png`, `data:image/png;base64,${(await page.screenshot()).toString('base64')}`);
  await page.close();
  return { found, errors };
}

test('/3d.html shows relief without cracks: no sky through the ground near, oblique or at the horizon', async () => {
  // Flagstones (65 536 texels across), relief 8 texels high: tiles of several levels meet in
  // every view, their edges at other heights; the skirts must close every gap.
  const { found, errors } = await reliefCracks('t=flagstones&m=synth&seed=2', 'flagstones');
  assert.deepEqual(found, { near: 0, oblique: 0, horizon: 0 });
  assert.deepEqual(errors, []);
});

test('/3d.html lists landscapes and shows one with relief by its blended heights, without cracks', async () => {
  const { page, errors } = await open3d('t=gravel&m=synth&seed=4');
  const groups = await page.$$eval('#texture optgroup', (gs) => gs.map((g) => [g.label, [...g.children].map((o) => o.value)]));
  assert.ok(groups.some(([l, ids]) => l === 'Landscapes' && ids.includes('meadow')), JSON.stringify(groups));
  await page.close();
  assert.deepEqual(errors, []);
  // The meadow: grass, gravel and flagstones, their heights (the flagstones' map, the others'
  // luma) blended; the mode row and parameters are a texture's, not shown.
  const r = await reliefCracks('t=meadow&seed=0', 'meadow');
  assert.deepEqual(r.found, { near: 0, oblique: 0, horizon: 0 });
  assert.deepEqual(r.errors, []);
});

test('/3d.html: the world has no edge, from the highest the page allows and at the end of panning', async () => {
  // The page's limits: the camera at most 20 000 texels from its target, the target panned at
  // most about 3.5 million texels from the world's centre. Each view asks for more than that
  // (the page clamps it) and looks across the ground: straight down, at 60°, at the horizon
  // (0.02 rad below it: the horizon 12 px above the middle row), and at the horizon outwards
  // from the farthest the target can be. The old world (32 768 texels) ended 16 384 texels
  // beyond its middle: sky where its ground stopped.
  const { page, errors } = await open3d('t=gravel&m=synth&seed=4');
  const views = [
    ['down', [16384, 90000, 16384.5], [16384, 0, 16384]],
    ['60°', [16384, 50000, 16384 + 86600], [16384, 0, 16384]],
    ['horizon', [16384, 800, 16384 + 4e6], [16384, 0, 16384]],
    ['farthest', [1e9 - 3e6, 800, 1e9 - 3e6], [1e9, 0, 1e9]],
  ];
  const found = {};
  for (const [name, eye, target] of views) {
    await page.evaluate(([e, t]) => window.textile3d.look(e, t), [eye, target]);
    await settled3d(page);
    const r = await page.evaluate(() => {
      const { camera, controls } = window.textile3d;
      const c = document.querySelector('#view canvas');
      const g = document.createElement('canvas');
      g.width = c.width; g.height = c.height;
      const ctx = g.getContext('2d');
      ctx.drawImage(c, 0, 0);
      // The ground's part: below the middle row and a margin (every view here looks down at
      // least 0.02 rad, so the horizon is above the middle).
      const from = Math.floor(c.height / 2) + 4;
      const d = ctx.getImageData(0, from, c.width, c.height - from).data;
      let sky = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (Math.abs(d[i] - 191) + Math.abs(d[i + 1] - 209) + Math.abs(d[i + 2] - 229) <= 9) sky++;
      }
      return { sky, height: camera.position.y, distance: camera.position.distanceTo(controls.target), target: [controls.target.x, controls.target.z] };
    });
    found[name] = r.sky;
    console.log(`3D page, ${name}: camera ${r.height.toFixed(0)} up, ${r.distance.toFixed(0)} from the target at ` +
      `(${r.target.map((v) => v.toFixed(0)).join(', ')}); sky pixels in the ground's part ${r.sky}`);
    assert.ok(r.distance <= 20001, `the page keeps the camera within 20 000 of its target: ${r.distance}`);
    save(`3d-world-${name.replace('°', '')}.png`, `data:image/png;base64,${(await page.screenshot()).toString('base64')}`);
  }
  assert.deepEqual(found, { down: 0, '60°': 0, horizon: 0, farthest: 0 });
  assert.deepEqual(errors, []);
  await page.close();
});

test('CesiumJS loads the tileset anchored on the globe and requests its content', async () => {
  const { page, errors } = await open(CESIUM_PAGE);
  const failed = [];
  const content = new Set();
  page.on('response', (r) => {
    const m = r.url().match(/\/3dtiles\/gravel\/tiles\/(\d+)\//);
    if (m) content.add(Number(m[1]));
    if (r.url().includes('/3dtiles/') && r.status() !== 200) failed.push(`${r.status()} ${r.url()}`);
  });
  await page.waitForFunction(() => window.Cesium && window.dayViewer);
  // Paris, 35 m above the ellipsoid: 1 texel = 1 m, east-north-up.
  const r = await page.evaluate(async (base) => {
    const viewer = window.dayViewer();
    const failures = [];
    // The README's options: foveated screen-space error left on, the view's upper corners were
    // never refined, and the globe showed there.
    const tileset = await Cesium.Cesium3DTileset.fromUrl(`${base}/3dtiles/gravel/tileset.json?lon=2.35&lat=48.85&height=35&seed=4`,
      { skipLevelOfDetail: true, foveatedScreenSpaceError: false });
    tileset.tileFailed.addEventListener((e) => failures.push(`${e.url}: ${e.message}`));
    viewer.scene.primitives.add(tileset);
    const centre = Cesium.Cartesian3.fromDegrees(2.35, 48.85, 35);
    // 900 m from a point 300 m east and south of the anchor, looking down at about 45°.
    viewer.camera.lookAt(Cesium.Matrix4.multiplyByPoint(tileset.root.computedTransform,
      new Cesium.Cartesian3(300, -300, 0), new Cesium.Cartesian3()), new Cesium.HeadingPitchRange(0.6, -0.8, 900));
    await new Promise((resolve) => {
      const t = setTimeout(resolve, 60000);
      tileset.allTilesLoaded.addEventListener(() => { clearTimeout(t); resolve(); });
    });
    viewer.render();
    const where = Cesium.Cartographic.fromCartesian(tileset.boundingSphere.center);
    return {
      failures,
      loaded: tileset.tilesLoaded,
      anchor: Cesium.Cartesian3.distance(Cesium.Matrix4.getTranslation(tileset.root.computedTransform, new Cesium.Cartesian3()), centre),
      lon: Cesium.Math.toDegrees(where.longitude), lat: Cesium.Math.toDegrees(where.latitude),
    };
  }, BASE);
  // The middle of the view is the texture, lit by day: about as bright as the tile itself (a
  // night-time clock gave 45–66 against the tile's 130).
  const { png, data: d } = await screenshot(page, [3 / 8, 3 / 8, 1 / 4, 1 / 4]);
  save('cesium.png', `data:image/png;base64,${png}`);
  let sum = 0;
  for (let i = 0; i < d.length; i += 4) sum += (d[i] + d[i + 1] + d[i + 2]) / 3;
  const lit = sum / (d.length / 4);
  console.log(`CesiumJS: the middle of the view at midday has mean luminance ${lit.toFixed(1)}`);
  assert.ok(lit > 85, `the texture is lit by day: mean ${lit}`);
  // The upper corners of the view (an eighth of its width and height each) are gravel too, not
  // the bare globe: the globe is one flat colour (standard deviation of the luminance about 1),
  // gravel a field of stones (about 14 at this distance).
  const spread = async (box) => {
    const { data } = await screenshot(page, box);
    const l = [];
    for (let i = 0; i < data.length; i += 4) l.push((data[i] + data[i + 1] + data[i + 2]) / 3);
    const mean = l.reduce((a, b) => a + b, 0) / l.length;
    return Math.sqrt(l.reduce((a, b) => a + (b - mean) ** 2, 0) / l.length);
  };
  const corners = { left: await spread([0, 0, 1 / 8, 1 / 8]), right: await spread([7 / 8, 0, 1 / 8, 1 / 8]) };
  console.log(`CesiumJS: luminance spread in the view's upper corners ${JSON.stringify(corners)} (bare globe: about 1)`);
  assert.ok(corners.left > 8 && corners.right > 8, `an upper corner shows no ground: ${JSON.stringify(corners)}`);
  const levels = [...content].sort((a, b) => a - b);
  console.log(`CesiumJS: tileset loaded ${r.loaded}, content levels requested [${levels}], bounding sphere at ` +
    `${r.lon.toFixed(4)}°, ${r.lat.toFixed(4)}°; root transform ${r.anchor.toFixed(3)} m from the anchor`);
  assert.ok(r.loaded, 'every tile of the view loaded');
  assert.ok(r.anchor < 0.01, 'the root transform sits at lon, lat, height');
  // The anchor is texel (0, 0), the centre of the root square (2^26 m a side).
  assert.ok(Math.abs(r.lon - 2.35) < 0.001 && Math.abs(r.lat - 48.85) < 0.001, `${r.lon}, ${r.lat}`);
  assert.ok(levels.length >= 2, `content requested at levels [${levels}]`);
  assert.deepEqual(r.failures, []);
  assert.deepEqual(failed, []);
  assert.deepEqual(errors, []);
  await page.close();
});

/** The README recipe's CesiumJS viewer on a globe painted magenta (no imagery, ground
 * atmosphere or fog: wherever the ground is missing, the globe shows), with the tileset at
 * `path` (anchored in Paris, 35 m above the ellipsoid) kept as `window.globe`. */
async function onMagentaGlobe(path) {
  // Half the usual view a side: a crack runs along a tile's edge, tens of pixels long at this
  // size too, and SwiftShader draws a quarter of the pixels from coarser tiles: at 800×600 a
  // relief view took 1–3 s a frame and the two tests 6 minutes; at 400×300, 2 minutes.
  const { page, errors } = await open(CESIUM_PAGE, { width: 400, height: 300 });
  await page.waitForFunction(() => window.Cesium && window.dayViewer);
  const failures = await page.evaluate(async (url) => {
    const viewer = window.dayViewer();
    viewer.scene.globe.baseColor = Cesium.Color.MAGENTA;
    viewer.scene.globe.showGroundAtmosphere = false;
    viewer.scene.fog.enabled = false;
    const failures = [];
    const tileset = await Cesium.Cesium3DTileset.fromUrl(url);
    tileset.tileFailed.addEventListener((e) => failures.push(`${e.url}: ${e.message}`));
    viewer.scene.primitives.add(tileset);
    window.globe = { viewer, tileset };
    return failures;
  }, BASE + path);
  return { page, errors, failures };
}

/** Look at texel `(x, y)` of `window.globe`'s tileset from `heading`, `pitch` and `range`
 * (metres), wait until its tiles are loaded, and count the magenta pixels below `from` (a
 * share of the height: the sky above the horizon is left out). Returns [PNG, count]. */
async function magentaSeen(page, [x, y], [heading, pitch, range], from) {
  await page.evaluate(async ([x, y, heading, pitch, range]) => {
    const { viewer, tileset } = window.globe;
    const target = Cesium.Matrix4.multiplyByPoint(tileset.root.computedTransform, new Cesium.Cartesian3(x, -y, 0), new Cesium.Cartesian3());
    viewer.camera.lookAt(target, new Cesium.HeadingPitchRange(heading, pitch, range));
    // Settled: five frames in a row with every tile of the view loaded, counted from the third
    // frame after the move (`allTilesLoaded` can fire for the view before it).
    const t0 = performance.now();
    let frames = 0;
    await new Promise((resolve) => {
      let loaded = 0;
      const done = viewer.scene.postRender.addEventListener(() => {
        frames++;
        loaded = frames > 2 && tileset.tilesLoaded ? loaded + 1 : 0;
        if (loaded >= 5 || performance.now() - t0 > 120000) { done(); resolve(); }
      });
    });
    viewer.render();
    return { ms: Math.round(performance.now() - t0), frames, loaded: tileset.tilesLoaded };
  }, [x, y, heading, pitch, range]).then((r) => console.log(`CesiumJS view ${[heading, pitch, range]}: ${JSON.stringify(r)}`));
  const { png, data: d } = await screenshot(page, [0, from, 1, 1 - from]);
  let n = 0;
  for (let i = 0; i < d.length; i += 4) if (d[i] > 180 && d[i + 1] < 90 && d[i + 2] > 180) n++;
  return [png, n];
}

test('CesiumJS with the README recipe: no edge of the world from the highest the recipe allows', async () => {
  // Gravel, the camera at the recipe's largest distance, 20 km, looking straight down, at 60°
  // and just below the horizon. The old world (32 768 m) ended 16 km from its anchor: the globe
  // showed beyond it.
  const { page, errors, failures } = await onMagentaGlobe('/3dtiles/gravel/tileset.json?lon=2.35&lat=48.85&height=35&seed=4');
  const views = [['down', 0, -1.5, 0], ['60°', 0.4, -0.52, 0], ['horizon', 0.9, -0.03, 0.6]];
  const found = {};
  for (const [name, heading, pitch, from] of views) {
    const [png, n] = await magentaSeen(page, [0, 0], [heading, pitch, 20000], from);
    found[name] = n;
    save(`cesium-world-${name.replace('°', '')}.png`, `data:image/png;base64,${png}`);
  }
  console.log(`CesiumJS, the recipe's highest views: globe pixels in the ground's part ${JSON.stringify(found)}`);
  assert.deepEqual(found, { down: 0, '60°': 0, horizon: 0 });
  assert.deepEqual(failures, []);
  assert.deepEqual(errors, []);
  await page.close();
});

test('CesiumJS shows relief without cracks: no globe through the ground near, oblique or at the horizon', async () => {
  // Flagstones with relief 8: a crack between tiles shows the globe.
  const { page, errors, failures } = await onMagentaGlobe('/3dtiles/flagstones/tileset.json?lon=2.35&lat=48.85&height=35&seed=2&relief=8');
  const views = [['near', 0.3, -1.2, 60, 0], ['oblique', 0.6, -0.5, 400, 0.2], ['horizon', 0.9, -0.1, 300, 0.6]];
  const found = {};
  for (const [name, heading, pitch, range, from] of views) {
    const [png, n] = await magentaSeen(page, [2000, 2000], [heading, pitch, range], from);
    found[name] = n;
    save(`cesium-relief-${name}.png`, `data:image/png;base64,${png}`);
  }
  console.log(`CesiumJS, flagstones relief=8: globe pixels through the ground ${JSON.stringify(found)}`);
  assert.deepEqual(found, { near: 0, oblique: 0, horizon: 0 });
  assert.deepEqual(failures, []);
  assert.deepEqual(errors, []);
  await page.close();
});
