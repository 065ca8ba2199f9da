// The README's CesiumJS recipe, timed (issue 61 item 1: "CesiumJS recipe view ≤ 6 s"): a cold
// server, headless Chromium (SwiftShader, on the same cores), a page with CesiumJS from
// tests/browser's node_modules built as the recipe says (daylight clock, camera capped at 20 km,
// looking at the middle from 900 m at about 45°), timed from the tileset's URL given to CesiumJS
// until `allTilesLoaded`; the content tiles it fetched and the frames CesiumJS drew meanwhile.
//
// Usage (from the repository root, a server running):
//   node bench/first_view_cesium.mjs URL [TEXTURE …]
// e.g. node bench/first_view_cesium.mjs http://127.0.0.1:8080 gravel flagstones
// (CESIUM_OPTIONS='{…}' replaces the recipe's options to Cesium3DTileset.fromUrl, by default
// {"skipLevelOfDetail": true, "foveatedScreenSpaceError": false}; SCENE='statements' runs them with `viewer` set up, before the
// tileset, e.g. SCENE='viewer.resolutionScale = 0.2'; SHOTS=DIR saves each settled view there)
import { readFileSync } from 'node:fs';
import { join } from 'node:path';

import { chromium } from './browser_libs.mjs';
const MODULES = new URL('../tests/browser/node_modules/', import.meta.url).pathname;
const TYPES = { js: 'text/javascript', css: 'text/css', json: 'application/json', wasm: 'application/wasm', png: 'image/png', jpg: 'image/jpeg', glb: 'model/gltf-binary' };

const [base, ...textures] = process.argv.slice(2);
// Cesium3DTileset options (JSON): the recipe's unless given.
const OPTIONS = JSON.parse(process.env.CESIUM_OPTIONS || '{"skipLevelOfDetail": true, "foveatedScreenSpaceError": false}');
const SCENE = process.env.SCENE || '';
const PAGE = `<!doctype html><html><head><meta charset="utf-8">
<script>window.CESIUM_BASE_URL = '/__3d/cesium/Build/Cesium/';</script>
<script src="/__3d/cesium/Build/Cesium/Cesium.js"></script>
<link rel="stylesheet" href="/__3d/cesium/Build/Cesium/Widgets/widgets.css">
<style>html, body, #globe { margin: 0; width: 100%; height: 100%; }</style></head>
<body><div id="globe"></div></body></html>`;
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
console.log('| texture | settled in | content tiles | frames |');
console.log('|---|---|---|---|');
for (const id of textures.length ? textures : ['gravel', 'flagstones']) {
  const page = await browser.newPage({ viewport: { width: 1000, height: 640 } });
  await page.route(`${base}/__3d/**`, (route) => {
    const path = new URL(route.request().url()).pathname.slice('/__3d/'.length);
    if (path === 'page.html') return route.fulfill({ body: PAGE, contentType: 'text/html' });
    return route.fulfill({ body: readFileSync(join(MODULES, path)), contentType: TYPES[path.split('.').pop()] ?? 'application/octet-stream' });
  });
  let tiles = 0;
  page.on('request', (r) => { if (/\/3dtiles\/[^/]+\/tiles\//.test(r.url())) tiles++; });
  await page.goto(`${base}/__3d/page.html`);
  await page.waitForFunction(() => window.Cesium);
  const [ms, frames] = await page.evaluate(async ([base, id, options, scene]) => {
    const viewer = new Cesium.Viewer('globe', {
      baseLayer: false, baseLayerPicker: false, geocoder: false, timeline: false, animation: false,
      homeButton: false, sceneModePicker: false, navigationHelpButton: false, fullscreenButton: false,
      infoBox: false, selectionIndicator: false, terrainProvider: new Cesium.EllipsoidTerrainProvider(),
    });
    viewer.clock.currentTime = Cesium.JulianDate.fromIso8601('2026-06-21T11:50:00Z');
    viewer.clock.shouldAnimate = false;
    viewer.scene.screenSpaceCameraController.maximumZoomDistance = 20000;
    new Function('viewer', 'Cesium', scene)(viewer, Cesium);
    let frames = 0;
    viewer.scene.postRender.addEventListener(() => { frames++; });
    const t0 = performance.now();
    const tileset = await Cesium.Cesium3DTileset.fromUrl(`${base}/3dtiles/${id}/tileset.json?lon=2.35&lat=48.85&height=35`, options);
    viewer.scene.primitives.add(tileset);
    viewer.camera.lookAt(Cesium.Matrix4.multiplyByPoint(tileset.root.computedTransform,
      new Cesium.Cartesian3(300, -300, 0), new Cesium.Cartesian3()), new Cesium.HeadingPitchRange(0.6, -0.8, 900));
    await new Promise((resolve) => {
      const t = setTimeout(resolve, 120000);
      const done = tileset.allTilesLoaded.addEventListener(() => { clearTimeout(t); done(); resolve(); });
    });
    return [performance.now() - t0, frames];
  }, [base, id, OPTIONS, SCENE]);
  console.log(`| ${id} | ${(ms / 1000).toFixed(1)} s | ${tiles} | ${frames} |`);
  if (process.env.SHOTS) await page.screenshot({ path: `${process.env.SHOTS}/cesium-${id}.png` });
  await page.close();
}
await browser.close();
