// textile 3D viewer: the texture's OGC 3D Tiles tileset (/3dtiles/{id}/tileset.json) streamed by
// 3DTilesRendererJS into a three.js scene, with a map-style camera (pan, orbit, dolly) and the
// texture, mode, seed and mode-parameter pickers built from /catalog and the texture's parameter
// specs, as the 2D viewer's are; landscapes (several textures in one ground) are offered beside
// the textures, with their seed and relief. The view and the choices live in the URL hash (the
// permalink; its keys are listed in the README's "3D viewer" section).
import * as THREE from 'three';
import { MapControls } from 'three/addons/controls/MapControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { TilesRenderer } from '3d-tiles-renderer';
import { ImplicitTilingPlugin } from '3d-tiles-renderer/core/plugins';

const $ = (id) => document.getElementById(id);
const num = (v) => String(Number(Number(v).toFixed(3)));

// t: texture or landscape, m: mode (textures), seed, p: mode parameters as given, cam: eye and
// target, sun: the sun's direction in degrees (materials with normals), relief: the height
// map's white in texels (textures with a height map, and landscapes; 0: flat tiles).
const MAX_RELIEF = 32;
const state = { t: null, m: null, seed: '0', p: {}, cam: null, sun: 135, relief: 0 };
let catalog = null, meta = null, tiles = null, debounce = null, retry = null;
// Every content tile the renderer asked for, by level (the test and the readout use them).
const requested = [];

function readHash() {
  const h = new URLSearchParams(location.hash.slice(1));
  state.t = h.get('t');
  state.m = h.get('m');
  state.seed = h.get('seed') ?? '0';
  state.p = {};
  for (const [k, v] of h) if (k.startsWith('p.')) state.p[k.slice(2)] = v;
  const sun = Number(h.get('sun'));
  if (h.has('sun') && Number.isFinite(sun)) state.sun = ((Math.round(sun) % 360) + 360) % 360;
  const relief = Number(h.get('relief'));
  state.relief = h.has('relief') && Number.isFinite(relief) ? Math.min(MAX_RELIEF, Math.max(0, Math.round(relief))) : 0;
  const cam = (h.get('cam') || '').split(',').map(Number);
  state.cam = cam.length === 6 && cam.every(Number.isFinite) ? cam : null;
}

function writeHash() {
  const h = new URLSearchParams();
  h.set('t', state.t);
  if (!landscape()) h.set('m', state.m);
  h.set('seed', state.seed);
  for (const [k, v] of Object.entries(state.p)) h.set(`p.${k}`, v);
  if (lit()) h.set('sun', state.sun);
  if (raised()) h.set('relief', state.relief);
  const e = camera.position, g = controls.target;
  h.set('cam', [e.x, e.y, e.z, g.x, g.y, g.z].map(num).join(','));
  history.replaceState(null, '', `#${h.toString().replace(/%2C/g, ',')}`);
  $('permalink').href = location.href;
}

/** The tileset URL of the current choices: the tiles' query parameters. */
function tilesetUrl() {
  const q = new URLSearchParams();
  if (!landscape() && state.m !== meta.default_mode) q.set('mode', state.m);
  if (state.seed !== '0') q.set('seed', state.seed);
  for (const [k, v] of Object.entries(state.p)) q.set(k, v);
  if (raised()) q.set('relief', state.relief);
  const qs = q.toString();
  return `/3dtiles/${encodeURIComponent(state.t)}/tileset.json${qs ? `?${qs}` : ''}`;
}

// The scene: Y up; the tileset (Z up) turned so that its east-north-up frame shows with north
// away from the default camera, which makes the ground frame of the glTF tiles (X east, Z south).
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
$('view').append(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xbfd1e5);
// A rough, non-metallic ground under ambient light of intensity π shows its texture as it is.
// A material with normals is lit instead by a sun 35° up (its direction a slider) and less
// ambient light, so that its relief shows.
const ambient = new THREE.AmbientLight(0xffffff, Math.PI);
const sun = new THREE.DirectionalLight(0xffffff, 0);
scene.add(ambient, sun, sun.target);

/** Whether a landscape is shown (its maps are names; a texture's are objects with modes). */
function landscape() {
  return meta?.kind === 'landscape';
}

/** Whether the texture or landscape has map `name` (for a texture, one the mode renders). */
function hasMap(test) {
  if (landscape()) return (meta.maps || []).some((n) => test({ name: n, kind: n }));
  return Boolean(meta && (meta.maps || []).some((m) => test(m) && (m.modes || []).includes(state.m)));
}

/** Whether the tiles can be displaced: a texture's height map the mode renders, or a landscape's
 * blended heights. */
function hasHeight() {
  return hasMap((m) => m.name === 'height');
}

/** Whether the tiles are displaced: a relief asked for, on a texture with a height map. */
function raised() {
  return hasHeight() && state.relief > 0;
}

/** Whether the current texture and mode show a lit material (a normal map the mode renders). */
function lit() {
  return hasMap((m) => m.kind === 'normal');
}

function placeSun() {
  const on = lit();
  $('sunrow').hidden = !on;
  $('reliefrow').hidden = !hasHeight();
  $('sunvalue').textContent = `${state.sun}°`;
  $('reliefvalue').textContent = state.relief > 0 ? `${state.relief} texels` : 'flat';
  ambient.intensity = on ? 0.9 : Math.PI;
  sun.intensity = on ? 2.6 : 0;
  // Azimuth from east, counter-clockwise seen from above (north is −Z).
  const a = (state.sun * Math.PI) / 180, g = controls.target;
  sun.target.position.copy(g);
  sun.position.set(g.x + Math.cos(a) * 0.82, 0.57, g.z - Math.sin(a) * 0.82);
}
// The world (server/src/tileset.rs): a square of 2^26 texels around texel (0, 0), seen from at
// most MAX_HEIGHT above the ground and out to FAR; the target stays within PAN of the centre,
// so the ground's far end is always beyond the far plane: no edge in view, and the far plane
// cuts the ground within a hundredth of a degree of the horizon.
const WORLD = 2 ** 26, MAX_HEIGHT = 20000, FAR = 3e7;
const PAN = WORLD / 2 - FAR - MAX_HEIGHT;
const camera = new THREE.PerspectiveCamera(50, 1, 0.5, FAR);
const controls = new MapControls(camera, renderer.domElement);
controls.screenSpacePanning = false;
controls.maxPolarAngle = Math.PI / 2 - 0.02;
controls.minDistance = 2;
controls.maxDistance = MAX_HEIGHT;
controls.addEventListener('end', () => { clearTimeout(debounce); debounce = setTimeout(writeHash, 200); });
/** Keep the target within PAN of the world's centre, moving the camera with it. */
function keepInWorld() {
  const t = controls.target;
  const dx = Math.min(PAN, Math.max(-PAN, t.x)) - t.x, dz = Math.min(PAN, Math.max(-PAN, t.z)) - t.z;
  if (dx || dz) {
    t.x += dx; t.z += dz;
    camera.position.x += dx; camera.position.z += dz;
  }
}
controls.addEventListener('change', keepInWorld);

function resize() {
  const el = $('view');
  renderer.setSize(el.clientWidth, el.clientHeight);
  camera.aspect = el.clientWidth / Math.max(1, el.clientHeight);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);

/**
 * GLTFLoader plugin: a GLB's embedded images decoded straight from its buffer
 * (`createImageBitmap` of a Blob, with the options of three.js's ImageBitmapLoader), where
 * GLTFLoader makes an object URL of each and fetches it back. A flagstones tile holds three
 * images; registering and fetching back some 400 object URLs cost the page's main thread and the
 * browser process about a second of a cold view's CPU (bench/README.md, "The first 3D view").
 * Images by URI, and browsers without createImageBitmap, take GLTFLoader's own way.
 */
class EmbeddedImages {
  constructor(parser) {
    this.name = 'textile_embedded_images';
    const load = parser.loadImageSource.bind(parser);
    parser.loadImageSource = (index, loader) => {
      const def = parser.json.images[index];
      if (def.bufferView === undefined || !loader.isImageBitmapLoader) return load(index, loader);
      // As GLTFLoader does: the first use of an image gets its texture, later ones a clone.
      const cached = parser.sourceCache[index];
      if (cached) return cached.then((t) => t.clone());
      return (parser.sourceCache[index] = parser.getDependency('bufferView', def.bufferView)
        .then((view) => createImageBitmap(new Blob([view], { type: def.mimeType }), { premultiplyAlpha: 'none', colorSpaceConversion: 'none' }))
        .then((bitmap) => {
          const texture = new THREE.Texture(bitmap);
          texture.needsUpdate = true;
          texture.userData.mimeType = def.mimeType;
          return texture;
        }));
    };
  }
}

function loadTiles() {
  if (tiles) {
    scene.remove(tiles.group);
    tiles.dispose();
  }
  const url = tilesetUrl();
  $('tilesetlink').href = url;
  tiles = new TilesRenderer(url);
  tiles.registerPlugin(new ImplicitTilingPlugin());
  const gltf = new GLTFLoader(tiles.manager);
  gltf.register((parser) => new EmbeddedImages(parser));
  tiles.manager.addHandler(/\.(gltf|glb)$/, gltf);
  // A few requests at a time: a burst of hundreds would only queue (or be shed) at the server.
  tiles.downloadQueue.maxJobsPerOrigin = 8;
  tiles.loadAncestors = false;
  tiles.group.rotation.x = -Math.PI / 2;
  tiles.setCamera(camera);
  tiles.setResolutionFromRenderer(camera, renderer);
  tiles.addEventListener('load-error', (e) => {
    // A busy server sheds with 503: ask again a little later, as the 2D viewer does.
    if (/\b503\b/.test(String(e.error))) {
      clearTimeout(retry);
      retry = setTimeout(() => tiles?.resetFailedTiles(), 1000 + 1000 * Math.random());
    } else {
      console.error(`tile load failed: ${e.url}: ${e.error}`);
    }
  });
  tiles.addEventListener('load-tileset', () => { document.body.dataset.ready = '1'; });
  // A tile loaded or a view to traverse again; what changes on screen, changes in update().
  tiles.addEventListener('needs-update', () => { needsUpdate = true; });
  invalidate();
  scene.add(tiles.group);
  writeHash();
}

/** Place the camera: from the hash, or above the middle of the root tile, looking down at 45°. */
function placeCamera() {
  const side = 256 * 2 ** meta.native_zoom;
  const [ex, ey, ez, tx, ty, tz] = state.cam ?? [side / 2, 700, side / 2 + 700, side / 2, 0, side / 2];
  camera.position.set(ex, ey, ez);
  controls.target.set(tx, ty, tz);
  keepInWorld();
  controls.update();
}

function changed() {
  clearTimeout(debounce);
  debounce = setTimeout(loadTiles, 250);
}

/** A control for one request parameter of the mode: numbers and integers as sliders, a
 * per-level list as one slider for every level (the server takes one number for all), choices
 * as a select; other kinds (intervals, controls) are the 2D viewer's. */
function control(name, spec) {
  const row = document.createElement('div');
  row.className = 'slider';
  row.title = spec.description;
  const label = document.createElement('label');
  label.textContent = name;
  label.htmlFor = `p-${name}`;
  let input;
  if (spec.type === 'choice') {
    input = document.createElement('select');
    for (const v of spec.values) input.append(new Option(v, v));
  } else if (spec.type === 'number' || spec.type === 'integer' || spec.type === 'levels') {
    input = document.createElement('input');
    Object.assign(input, { type: 'range', min: spec.min, max: spec.max, step: spec.type === 'integer' ? 1 : (spec.max - spec.min) / 100 });
    if (spec.type === 'levels') label.textContent = `${name} (all levels)`;
  } else {
    return null;
  }
  input.id = `p-${name}`;
  // A per-level default (a schedule, not one number) shows as "default" until the slider moves.
  const initial = state.p[name] ?? (typeof spec.default === 'object' ? undefined : spec.default);
  if (initial !== undefined && initial !== null) input.value = initial;
  const out = document.createElement('output');
  out.textContent = initial ?? 'default';
  input.addEventListener('input', () => {
    out.textContent = input.value;
    state.p[name] = spec.type === 'choice' ? input.value : num(input.value);
    changed();
  });
  row.append(label, input, out);
  return row;
}

function buildParams() {
  const box = $('controls');
  box.textContent = '';
  $('moderow').hidden = landscape();
  $('params').hidden = landscape();
  if (landscape()) return;
  $('modename').textContent = state.m;
  const specs = Object.entries(meta.parameters).filter(([, s]) => s.modes && s.modes.includes(state.m) && s.scope === 'request');
  for (const name of Object.keys(state.p)) if (!specs.some(([n]) => n === name)) delete state.p[name];
  for (const [name, spec] of specs) {
    const c = control(name, spec);
    if (c) box.append(c);
  }
}

async function selectTexture(id, keepView) {
  const r = await fetch(`/textures/${encodeURIComponent(id)}`);
  if (!r.ok) throw new Error(`texture ${id}: HTTP ${r.status}`);
  meta = await r.json();
  state.t = id;
  if (!landscape()) state.m = window.TextileModes.fill($('mode'), meta, state.m);
  buildParams();
  $('sun').value = state.sun;
  $('relief').value = state.relief;
  placeSun();
  if (!keepView) state.cam = null;
  placeCamera();
  loadTiles();
}

// Frames are drawn when something changed, not 60 times a second: the tiles are traversed when
// the camera moved or a tile arrived ('needs-update'). A move of the camera or a control is
// drawn at once; arriving tiles at most every RENDER_GAP ms while more are loading. A software
// renderer (SwiftShader, as in headless Chromium; llvmpipe) shares the cores with the server
// and draws a frame of this scene in a few hundred milliseconds: drawing an unchanged scene over
// and over took most of the machine while the first view loaded, and a drawing every 300 ms
// still a quarter of it (bench/README.md, "The first 3D view"), so it shows arriving tiles once
// a second. A GPU draws them as they come.
const RENDER_GAP = softwareRenderer() ? 1000 : 0;
/** Whether WebGL draws on the CPU. */
function softwareRenderer() {
  const gl = renderer.getContext();
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  return /swiftshader|llvmpipe|software/i.test(String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER)));
}
let needsUpdate = true, needsRender = true, urgent = true, lastRender = 0;
/** Traverse the tiles and draw again, now. */
function invalidate() {
  needsUpdate = true;
  needsRender = true;
  urgent = true;
}
for (const type of ['input', 'change', 'pointermove', 'wheel']) document.addEventListener(type, invalidate, true);
window.addEventListener('resize', invalidate);

function frame(now) {
  requestAnimationFrame(frame);
  if (controls.update()) invalidate();
  if (tiles && needsUpdate) {
    needsUpdate = false;
    camera.updateMatrixWorld();
    if (sun.intensity > 0) placeSun();
    tiles.update();
    needsRender = true;
  }
  const s = tiles?.stats;
  const loading = s && (s.downloading > 0 || s.parsing > 0);
  if (!needsRender || (loading && !urgent && now - lastRender < RENDER_GAP)) return;
  needsRender = false;
  urgent = false;
  lastRender = now;
  if (s) $('tilestats').textContent = `${s.visible ?? '–'} visible, ${s.downloading ?? 0} loading`;
  $('readout').textContent = `height ${num(camera.position.y)}`;
  renderer.render(scene, camera);
}

async function main() {
  readHash();
  resize();
  catalog = await (await fetch('/catalog')).json();
  const sel = $('texture');
  state.t = window.TextileModes.pick(sel, catalog, state.t);
  sel.value = state.t;
  $('seed').value = state.seed;
  sel.addEventListener('change', () => { state.p = {}; selectTexture(sel.value, false); });
  $('mode').addEventListener('change', () => { state.m = $('mode').value; buildParams(); placeSun(); changed(); });
  $('sun').addEventListener('input', () => { state.sun = Number($('sun').value); placeSun(); writeHash(); });
  $('relief').addEventListener('input', () => { state.relief = Number($('relief').value); placeSun(); });
  $('relief').addEventListener('change', () => { state.relief = Number($('relief').value); changed(); });
  $('seed').addEventListener('change', () => { state.seed = String(Math.max(0, Math.floor(Number($('seed').value) || 0))); changed(); });
  $('newseed').addEventListener('click', () => {
    state.seed = String(Math.floor(Math.random() * 2 ** 31));
    $('seed').value = state.seed;
    changed();
  });
  await selectTexture(state.t, true);
  requestAnimationFrame(frame);
}

// Content requests by level, for the readout and the browser test.
new PerformanceObserver((list) => {
  for (const e of list.getEntries()) {
    const m = e.name.match(/\/3dtiles\/[^/]+\/tiles\/(\d+)\/(\d+)\/(\d+)\.glb/);
    if (m) requested.push({ level: Number(m[1]), x: Number(m[2]), y: Number(m[3]) });
  }
}).observe({ type: 'resource', buffered: true });

window.textile3d = {
  camera, controls, requested, state, sun,
  get tiles() { return tiles; },
  /** Move the camera (eye and target) and let the tiles follow. */
  look(eye, target) {
    camera.position.set(...eye);
    controls.target.set(...target);
    keepInWorld();
    controls.update();
    invalidate();
    writeHash();
  },
  /** The levels of the tiles on screen, with how many of each. */
  visibleLevels() {
    const n = {};
    for (const t of tiles?.visibleTiles ?? []) {
      const m = (t.content?.uri ?? '').match(/tiles\/(\d+)\//);
      if (m) n[m[1]] = (n[m[1]] ?? 0) + 1;
    }
    return n;
  },
  /** Whether every tile the view needs is loaded and nothing is in flight (and the view shows
   * tiles: just after the tileset arrives, nothing is in flight yet either). */
  settled() {
    const s = tiles?.stats;
    return !!s && tiles.root && s.downloading === 0 && s.parsing === 0 && tiles.loadProgress === 1 && tiles.visibleTiles.size > 0;
  },
};

main().catch((e) => console.error(String(e)));
