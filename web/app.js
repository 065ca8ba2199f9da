// textile viewer: a Leaflet map (CRS.Simple, so tile coordinates are unbounded and may be
// negative) over the infinite texture, with the synthesis controls and a permalink in the URL hash.
// The mode's controls are built from the parameter specs of /textures/{id} (type, range,
// default, which modes accept each): a new mode or parameter needs no change here.
'use strict';

// p: the parameters the user changed, by name, as the query string carries them.
// a: the map shown (albedo, a material map, or 'lit': colour shaded by the normal map); l: the
// light's direction in degrees for 'lit'; o: the splat overlay of a landscape shown.
const state = { t: null, m: null, s: 0, p: {}, z: null, x: 0, y: 0, g: false, a: 'albedo', l: 135, o: false, k: false };
let catalog = null, meta = null, map = null, layer = null, grid = null, latticeLayer = null, debounce = null;
let splatLayer = null;
const $ = (id) => document.getElementById(id);

// A landscape (several textures by a splat: GET /textures/{id} says kind "landscape") has no
// mode, parameters or exemplar of its own: only a seed, its maps and its splat.
function isLandscape() { return Boolean(meta && meta.kind === 'landscape'); }

function readHash() {
  const p = new URLSearchParams(location.hash.slice(1));
  if (p.has('t')) state.t = p.get('t');
  if (p.has('m')) state.m = p.get('m');
  if (p.has('s') && /^\d+$/.test(p.get('s'))) state.s = p.get('s');
  for (const [k, v] of p) if (k.startsWith('p.')) state.p[k.slice(2)] = v;
  if (p.has('z')) state.z = Number(p.get('z'));
  if (p.has('x')) state.x = Number(p.get('x'));
  if (p.has('y')) state.y = Number(p.get('y'));
  state.g = p.get('g') === '1';
  if (p.has('a')) state.a = p.get('a');
  if (p.has('l') && /^\d+$/.test(p.get('l'))) state.l = Number(p.get('l')) % 360;
  state.o = p.get('o') === '1';
  state.k = p.get('k') === '1';
}

function hash() {
  const p = new URLSearchParams();
  p.set('t', state.t); p.set('m', state.m); p.set('s', state.s);
  for (const [k, v] of Object.entries(state.p)) p.set(`p.${k}`, v);
  p.set('z', state.z); p.set('x', Math.round(state.x)); p.set('y', Math.round(state.y));
  if (state.g) p.set('g', '1');
  if (state.a !== 'albedo') p.set('a', state.a);
  if (state.a === 'lit') p.set('l', state.l);
  if (state.o && isLandscape()) p.set('o', '1');
  if (state.k && !isLandscape()) p.set('k', '1');
  return '#' + p.toString();
}

function writeHash() {
  const h = hash();
  history.replaceState(null, '', h);
  $('permalink').href = h;
}

function native() { return meta ? meta.native_zoom : 0; }

// Texel (native-zoom pixel) coordinates <-> CRS.Simple lat/lng.
function toLatLng(x, y) { const s = 2 ** native(); return L.latLng(-y / s, x / s); }
function fromLatLng(ll) { const s = 2 ** native(); return { x: ll.lng * s, y: -ll.lat * s }; }

// The tile URL template of the current view, showing `mapName` (default: the picked map; the
// lit view fetches the colour and the normals).
function tileUrl(mapName) {
  const q = new URLSearchParams();
  if (isLandscape()) {
    // Seed 0 is the landscape as configured; another reseeds the splat and every layer.
    if (String(state.s) !== '0') q.set('seed', state.s);
  } else {
    q.set('mode', state.m);
    q.set('seed', state.s);
    for (const [k, v] of Object.entries(state.p)) q.set(k, v);
  }
  const shown = mapName || state.a;
  if (shown !== 'albedo' && shown !== 'lit') q.set('map', shown);
  return `/tiles/${encodeURIComponent(state.t)}/{z}/{x}/{y}.png?` + q.toString();
}

// The maps the current texture offers in the current mode (from /textures/{id}), plus 'lit'
// when it has a normal map; the coordinates (uv) are for programs, not for looking at.
function mapChoices() {
  if (isLandscape()) return meta.maps.filter((m) => m !== 'splat');
  const maps = (meta.maps || []).filter((m) => m.name === 'albedo' || (m.kind !== 'coordinates' && m.modes.includes(state.m)));
  const names = maps.map((m) => m.name);
  if (maps.some((m) => m.kind === 'normal')) names.push('lit');
  return names;
}

function buildMapPicker() {
  const sel = $('mapsel');
  sel.textContent = '';
  const names = mapChoices();
  for (const n of names) sel.append(new Option(n === 'lit' ? 'lit (colour × normals)' : n, n));
  if (!names.includes(state.a)) state.a = 'albedo';
  sel.value = state.a;
  sel.disabled = names.length < 2;
  $('lightrow').hidden = state.a !== 'lit';
  $('light').value = state.l;
}

// Shade colour by normals under a light from `deg` (azimuth, 45° up), in the page: served
// normals are OpenGL (+Y up in the image), so the image's up is the light's +Y.
function shade(out, colour, normal, deg) {
  const a = (deg * Math.PI) / 180, c = Math.SQRT1_2;
  const l = [Math.cos(a) * c, Math.sin(a) * c, c];
  for (let i = 0; i < out.data.length; i += 4) {
    const n = [normal[i] / 127.5 - 1, normal[i + 1] / 127.5 - 1, normal[i + 2] / 127.5 - 1];
    const d = Math.max(0, n[0] * l[0] + n[1] * l[1] + n[2] * l[2]);
    const k = 0.25 + 0.9 * d;
    for (let j = 0; j < 3; j++) out.data[i + j] = Math.min(255, colour[i + j] * k);
    out.data[i + 3] = 255;
  }
}

// The lit view: each tile a canvas drawn from the colour and normal tiles of the same place.
const LitLayer = L.GridLayer.extend({
  createTile(coords, done) {
    const tile = document.createElement('canvas');
    tile.width = tile.height = 256;
    const url = (m) => L.Util.template(tileUrl(m), coords);
    const load = (src) => new Promise((ok, fail) => {
      const img = new Image();
      img.onload = () => ok(img);
      img.onerror = () => fail(new Error(`tile ${src}`));
      img.src = src;
    });
    Promise.all([load(url('albedo')), load(url('normal'))]).then(([a, n]) => {
      const ctx = tile.getContext('2d');
      const pixels = (img) => { ctx.drawImage(img, 0, 0); return ctx.getImageData(0, 0, 256, 256).data; };
      tile._colour = pixels(a);
      tile._normal = pixels(n);
      drawLit(tile);
      tile.dataset.lit = '1';
      done(null, tile);
    }, (e) => done(e, tile));
    return tile;
  },
});

function drawLit(tile) {
  const ctx = tile.getContext('2d');
  const out = ctx.createImageData(256, 256);
  shade(out, tile._colour, tile._normal, state.l);
  ctx.putImageData(out, 0, 0);
}

// A tile the server shed under load (503 + Retry-After) is asked for again after a growing,
// jittered delay (about 1, 2, 4, 8 s; at most 4 times) instead of leaving a hole. `v` is the
// API's cache-busting parameter: same tile, same bytes, a new request for the browser.
function retryShedTile(e) {
  const img = e.tile;
  const n = Number(img.dataset.retries || 0) + 1;
  if (n > 4) return;
  img.dataset.retries = String(n);
  const delay = 1000 * 2 ** (n - 1) * (0.5 + Math.random());
  setTimeout(() => {
    if (!img.isConnected || !layer) return;
    img.src = `${layer.getTileUrl(e.coords)}&v=retry${n}`;
  }, delay);
}

function refreshLayer() {
  const url = tileUrl();
  const options = {
    tileSize: 256, noWrap: true, minZoom: meta.minzoom, maxZoom: meta.maxzoom + 2,
    minNativeZoom: meta.minzoom, maxNativeZoom: meta.maxzoom, keepBuffer: 1,
    attribution: meta.attribution || '',
  };
  // The lit layer draws from the current URLs when it is made: a change makes a new one.
  const lit = state.a === 'lit';
  if (layer && (lit || layer instanceof LitLayer)) { map.removeLayer(layer); layer = null; }
  if (lit) {
    layer = new LitLayer(options).addTo(map);
    writeHash();
    return;
  }
  if (!layer) {
    layer = L.tileLayer(url, options).addTo(map);
    layer.on('tileerror', retryShedTile);
  } else if (layer._url !== url) {
    layer.setUrl(url);
  }
  if (splatLayer && splatLayer._url !== tileUrl('splat')) splatLayer.setUrl(tileUrl('splat'));
  writeHash();
}

// A number as short text: at most 4 decimals, no trailing zeros (0.475 stays 0.475).
const num = (v) => String(Number(Number(v).toFixed(4)));

// The request parameters of the current mode, from the specs (common ones have their own
// controls: mode and seed; world is for wrapped web maps).
function modeParams() {
  return Object.entries(meta.parameters).filter(([, s]) => s.modes && s.modes.includes(state.m) && s.scope === 'request');
}

function changed() {
  clearTimeout(debounce);
  debounce = setTimeout(refreshLayer, 120);
}

// One slider: label, range input and live value; `set` receives the new value.
function slider(id, text, min, max, step, value, aria, set) {
  const row = document.createElement('div');
  row.className = 'slider';
  const label = document.createElement('label');
  label.htmlFor = id;
  label.textContent = text;
  const input = document.createElement('input');
  Object.assign(input, { type: 'range', id, min, max, step, value });
  input.setAttribute('aria-label', aria);
  const out = document.createElement('output');
  out.htmlFor = id;
  out.textContent = num(value);
  input.addEventListener('input', () => { out.textContent = num(input.value); set(Number(input.value)); changed(); });
  row.append(label, input, out);
  return row;
}

// Controls for one parameter spec; values the user did not touch keep their exact defaults.
function control(name, spec) {
  const box = document.createElement('div');
  box.className = 'param';
  box.title = spec.description;
  const given = state.p[name];
  if (spec.type === 'levels') {
    const values = given ? given.split(',').map(Number) : spec.default.slice();
    if (values.length !== spec.default.length || values.some((v) => !(v >= 0 && v <= 1))) {
      delete state.p[name];
      values.splice(0, values.length, ...spec.default);
    }
    const title = document.createElement('p');
    title.textContent = `${name} per level, coarse → fine`;
    box.append(title);
    values.forEach((v, l) => box.append(slider(`p-${name}-${l}`, `level ${l}`, spec.min, spec.max, 0.05, v,
      `${name} of level ${l} of ${values.length - 1} (0 is coarsest)`,
      (x) => { values[l] = x; state.p[name] = values.map(num).join(','); })));
  } else if (spec.type === 'interval') {
    const values = given ? given.split(',').map(Number) : spec.default.slice();
    ['low', 'high'].forEach((end, i) => box.append(slider(`p-${name}-${i}`, `${name} ${end}`, spec.min, spec.max, 0.05,
      values[i], `${name}, ${end} end`, (x) => {
        values[i] = x;
        if (values[0] > values[1]) values[1 - i] = x;
        state.p[name] = values.map(num).join(',');
      })));
  } else if (spec.type === 'text' && name === 'controls') {
    // Synth's spatial controls: noise, features dragged from the thumbnail, painted strokes
    // (web/controls.js).
    box.append(TextileControls.editor({
      map, width: meta.exemplar.width, height: meta.exemplar.height, scale: 2 ** native(), thumb: $('thumb'), value: given, slider, changed,
      set: (v) => { if (v) state.p[name] = v; else delete state.p[name]; },
    }));
  } else if (spec.type === 'choice') {
    const row = document.createElement('div');
    row.className = 'row';
    const label = document.createElement('label');
    label.htmlFor = `p-${name}`;
    label.textContent = name;
    const select = document.createElement('select');
    select.id = `p-${name}`;
    for (const v of spec.values) select.append(new Option(v, v));
    select.value = given ?? spec.default;
    select.addEventListener('change', () => { state.p[name] = select.value; changed(); });
    row.append(label, select);
    box.append(row);
  } else if (spec.type === 'integer' || spec.type === 'number') {
    const step = spec.type === 'integer' ? 1 : 0.05;
    box.append(slider(`p-${name}`, name, spec.min, spec.max, step, given ?? spec.default, spec.description,
      (x) => { state.p[name] = num(x); }));
  }
  return box;
}

function buildControls() {
  TextileControls.dispose();
  const box = $('controls');
  box.textContent = '';
  const params = modeParams();
  for (const k of Object.keys(state.p)) if (!params.some(([n]) => n === k)) delete state.p[k];
  for (const [name, spec] of params) box.append(control(name, spec));
  $('modename').textContent = `mode=${state.m}`;
  $('modesummary').textContent = meta.mode_info[state.m] ? meta.mode_info[state.m].summary : '';
  $('params').hidden = false;
  if (!params.length) box.textContent = 'This mode has no parameters besides the seed.';
}

// The splat of a landscape over the map, half transparent, and its legend.
function setSplat(on) {
  state.o = on;
  $('splat').checked = on;
  if (splatLayer) { map.removeLayer(splatLayer); splatLayer = null; }
  if (on && isLandscape()) {
    splatLayer = L.tileLayer(tileUrl('splat'), {
      tileSize: 256, noWrap: true, opacity: 0.5, zIndex: 5, className: 'splat-tile',
      minZoom: meta.minzoom, maxZoom: meta.maxzoom + 2, minNativeZoom: meta.minzoom, maxNativeZoom: meta.maxzoom,
    }).addTo(map);
  }
  writeHash();
}

function showLandscape() {
  const land = isLandscape();
  for (const id of ['moderow', 'params', 'thumbbox', 'structureinfo']) $(id).hidden = land;
  $('landscapebox').hidden = !land;
  const legend = $('legend');
  legend.textContent = '';
  if (!land) { setSplat(false); return; }
  for (const l of meta.layers) {
    const li = document.createElement('li');
    const sw = document.createElement('span');
    sw.className = 'swatch';
    sw.style.background = l.colour;
    li.append(sw, `${l.name} (${l.mode}${l.scale ? `, scale ${l.scale}` : ''})`);
    legend.append(li);
  }
  $('landscapeinfo').textContent = `A landscape of ${meta.layers.length} textures: a ${meta.splat.kind} splat, ${meta.blend.kind} blend.`;
}

async function selectTexture(id, keepView) {
  const r = await fetch(`/textures/${encodeURIComponent(id)}`);
  if (!r.ok) throw new Error(`texture ${id}: ${r.status}`);
  meta = await r.json();
  state.t = id;
  $('texture').value = id;
  if (isLandscape()) {
    showLandscape();
    buildMapPicker();
    setLattice(false);
    $('latticerow').hidden = true;
    showView(keepView);
    setSplat(state.o);
    return;
  }
  showLandscape();
  const entry = catalog.textures.find((t) => t.id === id);
  $('thumb').src = entry ? entry.exemplar : '';
  state.m = window.TextileModes.fill($('mode'), meta, state.m);
  buildMapPicker();
  buildControls();
  showLatticeRow();
  showStructure();
  showView(keepView);
}

// The map for the texture just described: its zooms, the view (kept, or at its native zoom),
// and its tiles.
function showView(keepView) {
  map.setMinZoom(meta.minzoom);
  map.setMaxZoom(meta.maxzoom + 2);
  if (layer) { map.removeLayer(layer); layer = null; }
  if (!keepView || state.z === null || Number.isNaN(state.z)) state.z = meta.native_zoom;
  map.setView(toLatLng(state.x, state.y), state.z, { animate: false });
  refreshLayer();
}

function setGrid(on) {
  state.g = on;
  $('grid').checked = on;
  if (on && !grid) {
    grid = L.gridLayer({ tileSize: 256, noWrap: true, zIndex: 10 });
    grid.createTile = (c) => {
      const d = document.createElement('div');
      d.className = 'grid-tile';
      d.textContent = `${c.z}/${c.x}/${c.y}`;
      return d;
    };
    grid.addTo(map);
  } else if (!on && grid) {
    map.removeLayer(grid);
    grid = null;
  }
  writeHash();
}

// The texture's lattice drawn over the map: for each wave (period p texels, normal at angle a)
// the lines where the texel coordinates' projection on the normal is a multiple of p — the
// spacing and direction the modes keep (their phase is the texture's own).
function latticeLines(canvas, c) {
  const lat = meta && meta.exemplar.lattice;
  const ctx = canvas.getContext('2d');
  if (!lat) return;
  const per = 2 ** (native() - c.z); // texels per screen pixel
  const x0 = c.x * 256 * per, y0 = c.y * 256 * per;
  ctx.strokeStyle = 'rgba(0, 255, 255, 0.85)';
  ctx.lineWidth = 1;
  for (const w of lat.waves) {
    const spacing = w.period / per; // screen pixels between lines
    if (spacing < 4) continue;
    const t = (w.angle * Math.PI) / 180, nx = Math.cos(t), ny = Math.sin(t);
    // Projections of the tile's corners on the normal bound the lines that cross it.
    const ds = [[0, 0], [256, 0], [0, 256], [256, 256]].map(([u, v]) => (x0 / per + u) * nx + (y0 / per + v) * ny);
    const first = Math.ceil(Math.min(...ds) / spacing), last = Math.floor(Math.max(...ds) / spacing);
    ctx.beginPath();
    for (let k = first; k <= last; k++) {
      const d = k * spacing - (x0 / per) * nx - (y0 / per) * ny; // line: u nx + v ny = d
      const big = 1024;
      ctx.moveTo(d * nx - big * ny, d * ny + big * nx);
      ctx.lineTo(d * nx + big * ny, d * ny - big * nx);
    }
    ctx.stroke();
  }
}

// The exemplar's structure over its thumbnail (GET /textures/{id} `structure`): for a tile
// repeated, the copies' lattice (yellow: each parallelogram is one tile); for a near-regular
// exemplar, its lattice lines (cyan; for a tile repeated, the lattice inside it). The line
// under the thumbnail says what was found.
function latticeFamily(ctx, side, k, a, b) {
  // Lines along `b` through every multiple of `a` ([dy, dx] texels), across the exemplar.
  const len = Math.hypot(a[0], a[1]);
  if (len < 1) return;
  const reach = Math.ceil((2 * side) / Math.max(1, Math.abs(a[1] * b[0] - a[0] * b[1]) / Math.hypot(b[0], b[1]))) + 1;
  const bl = Math.hypot(b[0], b[1]) || 1, ux = b[1] / bl, uy = b[0] / bl;
  ctx.beginPath();
  for (let i = -reach; i <= reach; i++) {
    const x = i * a[1], y = i * a[0];
    ctx.moveTo((x - 3 * side * ux) * k, (y - 3 * side * uy) * k);
    ctx.lineTo((x + 3 * side * ux) * k, (y + 3 * side * uy) * k);
  }
  ctx.stroke();
}

function drawLatticeOn(ctx, side, k, lat) {
  const basis = lat.basis;
  if (basis.length === 1) {
    const a = basis[0];
    latticeFamily(ctx, side, k, a, [a[1], -a[0]]); // lines across the one translation
  } else if (basis.length === 2) {
    latticeFamily(ctx, side, k, basis[0], basis[1]);
    latticeFamily(ctx, side, k, basis[1], basis[0]);
  }
}

function showStructure() {
  const canvas = $('thumblattice');
  // The thumbnail keeps the exemplar's shape: its longer side 64 px, the overlay at twice that.
  const [w, h] = meta ? [meta.exemplar.width, meta.exemplar.height] : [1, 1];
  const [tw, th] = [Math.round((64 * w) / Math.max(w, h)), Math.round((64 * h) / Math.max(w, h))];
  $('thumb').width = tw;
  $('thumb').height = th;
  Object.assign(canvas.style, { width: `${tw}px`, height: `${th}px` });
  [canvas.width, canvas.height] = [2 * tw, 2 * th];
  const ctx = canvas.getContext('2d');
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  const st = meta && meta.structure;
  const side = Math.max(w, h);
  const k = canvas.width / w;
  ctx.lineWidth = 2;
  let text = '';
  if (!st) {
    text = 'Structure not detected (lattice = none).';
  } else if (st.class === 'exact') {
    ctx.strokeStyle = 'rgba(255, 220, 0, 0.95)';
    drawLatticeOn(ctx, side, k, st);
    const t = st.tile;
    const size = t.width && t.height ? `a ${t.width}×${t.height} px tile` : `a tile of ${t.area || '?'} px²`;
    text = `Exact repeat: ${size} repeated (copies ${st.basis.map((v) => `[${v.join(', ')}]`).join(' × ')}, score ${st.scores.repeat.toFixed(3)}).`;
    if (st.inner && st.inner.class === 'lattice') {
      ctx.strokeStyle = 'rgba(0, 255, 255, 0.85)';
      ctx.lineWidth = 1;
      drawLatticeOn(ctx, side, k, st.inner);
      text += ` Inside it: a ${st.inner.dimensions}-D lattice.`;
    }
  } else if (st.class === 'lattice') {
    ctx.strokeStyle = 'rgba(0, 255, 255, 0.95)';
    drawLatticeOn(ctx, side, k, st);
    const vs = st.basis.map((v) => `[${v.map((c) => c.toFixed(1)).join(', ')}]`).join(' × ');
    text = `Near-regular: a ${st.dimensions}-D lattice, basis [dy, dx] ${vs} px (confidence ${st.confidence}).`;
  } else {
    text = 'No lattice: stochastic.';
  }
  canvas.dataset.structure = st ? st.class : 'off';
  $('structureinfo').textContent = text;
}

function showLatticeRow() {
  const lat = meta && meta.exemplar.lattice;
  $('latticerow').hidden = !lat;
  if (!lat) { setLattice(false); return; }
  if (state.k && !latticeLayer) setLattice(true);
  const waves = lat.waves.map((w) => `${w.period.toFixed(2)} px at ${w.angle.toFixed(1)}°`).join(', ');
  $('latticeinfo').textContent = `${lat.kind}: ${waves} (${lat.origin}, confidence ${lat.confidence})`;
  if (latticeLayer) latticeLayer.redraw();
}

function setLattice(on) {
  $('lattice').checked = on;
  state.k = on;
  if (on && !latticeLayer) {
    latticeLayer = L.gridLayer({ tileSize: 256, noWrap: true, zIndex: 11 });
    latticeLayer.createTile = (c) => {
      const canvas = document.createElement('canvas');
      canvas.width = canvas.height = 256;
      canvas.className = 'lattice-tile';
      latticeLines(canvas, c);
      return canvas;
    };
    latticeLayer.addTo(map);
  } else if (!on && latticeLayer) {
    map.removeLayer(latticeLayer);
    latticeLayer = null;
  }
}

function onMove() {
  const c = fromLatLng(map.getCenter());
  state.x = c.x; state.y = c.y; state.z = map.getZoom();
  $('readout').textContent = `x ${Math.round(c.x)}, y ${Math.round(c.y)} texels · zoom ${state.z} (native ${native()})`;
  writeHash();
}

// The upload form (shown when the server has an admin API): the token is kept for this tab only
// (sessionStorage); the upload's status is polled at its Location until it is ready, then the
// new texture is added to the list and shown.
function setupUpload() {
  if (!catalog.uploads) return;
  $('upload').hidden = false;
  const token = $('u-token');
  token.value = sessionStorage.getItem('textile-admin-token') || '';
  $('u-file').addEventListener('change', (e) => {
    const f = e.target.files[0];
    if (f && !$('u-id').value) {
      $('u-id').value = f.name.replace(/\.[^.]*$/, '').toLowerCase().replace(/[^a-z0-9_-]+/g, '-').slice(0, 64);
    }
  });
  const status = (text) => { $('u-status').textContent = text; };
  $('uploadform').addEventListener('submit', async (e) => {
    e.preventDefault();
    const file = $('u-file').files[0];
    if (!file) return;
    sessionStorage.setItem('textile-admin-token', token.value);
    const q = new URLSearchParams({ id: $('u-id').value, toroidal: $('u-toroidal').value });
    if ($('u-name').value) q.set('name', $('u-name').value);
    $('u-send').disabled = true;
    status('uploading…');
    try {
      const r = await fetch(`/admin/textures?${q}`, {
        method: 'POST', body: file,
        headers: { Authorization: `Bearer ${token.value}`, 'Content-Type': file.type || 'application/octet-stream' },
      });
      const body = await r.json().catch(() => ({}));
      if (r.status !== 202) throw new Error(body.message || `HTTP ${r.status}`);
      const where = r.headers.get('Location') || `/textures/${encodeURIComponent(body.id)}`;
      const bar = $('u-progress');
      bar.hidden = false;
      for (;;) {
        const m = await (await fetch(where)).json();
        bar.value = m.progress || 0;
        if (m.status === 'ready') break;
        if (m.status !== 'analysing') throw new Error((m.analysis && m.analysis.error) || `analysis ${m.status}`);
        status(`analysing… ${m.progress} %`);
        await new Promise((ok) => setTimeout(ok, 400));
      }
      bar.hidden = true;
      catalog = await (await fetch('/catalog')).json();
      const entry = catalog.textures.find((t) => t.id === body.id);
      $('texture').append(new Option(entry ? entry.name : body.id, body.id));
      await selectTexture(body.id, false);
      status(`added “${entry ? entry.name : body.id}”`);
    } catch (err) {
      status(`upload failed: ${err.message}`);
    } finally {
      $('u-send').disabled = false;
    }
  });
}

async function init() {
  readHash();
  catalog = await (await fetch('/catalog')).json();
  const sel = $('texture');
  state.t = window.TextileModes.pick(sel, catalog, state.t);
  map = L.map('map', { crs: L.CRS.Simple, zoomSnap: 1, keyboard: true, worldCopyJump: false });
  window.textileMap = map;
  map.on('moveend', onMove);
  await selectTexture(state.t, true);
  $('seed').value = state.s;
  setGrid(state.g);
  onMove();
  sel.addEventListener('change', () => selectTexture(sel.value, true));
  $('mode').addEventListener('change', (e) => { state.m = e.target.value; buildMapPicker(); buildControls(); refreshLayer(); });
  $('mapsel').addEventListener('change', (e) => {
    state.a = e.target.value;
    $('lightrow').hidden = state.a !== 'lit';
    refreshLayer();
  });
  $('light').addEventListener('input', (e) => {
    state.l = Number(e.target.value);
    if (layer instanceof LitLayer) {
      for (const t of document.querySelectorAll('canvas[data-lit="1"]')) drawLit(t);
    }
    writeHash();
  });
  $('seed').addEventListener('change', (e) => {
    const v = String(e.target.value).trim();
    if (/^\d+$/.test(v)) { state.s = v; refreshLayer(); } else { e.target.value = state.s; }
  });
  $('newseed').addEventListener('click', () => {
    state.s = String(Math.floor(Math.random() * 2 ** 32));
    $('seed').value = state.s;
    refreshLayer();
  });
  $('resetp').addEventListener('click', () => { state.p = {}; buildControls(); refreshLayer(); });
  $('grid').addEventListener('change', (e) => setGrid(e.target.checked));
  $('lattice').addEventListener('change', (e) => { setLattice(e.target.checked); writeHash(); });
  $('splat').addEventListener('change', (e) => setSplat(e.target.checked));
  setupUpload();
  $('terrainlink').addEventListener('click', (e) => {
    e.currentTarget.href = `/terrain.html#t=${encodeURIComponent(state.t)}`;
  });
  $('worldlink').addEventListener('click', (e) => {
    e.currentTarget.href = `/world.html#t=${encodeURIComponent(state.t)}&m=${state.m}&s=${state.s}`;
  });
  document.body.dataset.ready = '1';
}

init().catch((e) => { console.error(e); $('readout').textContent = `error: ${e.message}`; });
