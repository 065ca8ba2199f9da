// textile terrain page: MapLibre GL JS showing a texture (or a landscape) draped over its own
// heights — a `raster` source of its tiles and a `raster-dem` source of
// `map=height&encoding=terrarium` (both from TileJSON, which names the encoding), with
// hillshade and 3D terrain. The permalink keeps the texture, the relief and the camera:
// `#t=ID&r=RELIEF&c=ZOOM/LAT/LNG/BEARING/PITCH`.
'use strict';

const $ = (id) => document.getElementById(id);
const state = { t: null, r: 1, c: null };
let map = null;

/** The style: textile's texture over its own raster-dem, with hillshade and terrain. */
function terrainStyle(base, id, relief) {
  const tilejson = `${base}/tiles/${encodeURIComponent(id)}/tilejson.json`;
  return {
    version: 8,
    sources: {
      texture: { type: 'raster', url: tilejson, tileSize: 256 },
      relief: { type: 'raster-dem', url: `${tilejson}?map=height&encoding=terrarium`, tileSize: 256 },
    },
    layers: [
      { id: 'texture', type: 'raster', source: 'texture' },
      { id: 'hillshade', type: 'hillshade', source: 'relief', paint: { 'hillshade-exaggeration': 0.5 } },
    ],
    terrain: { source: 'relief', exaggeration: relief },
  };
}
window.textileTerrainStyle = terrainStyle;

function readHash() {
  const p = new URLSearchParams(location.hash.slice(1));
  if (p.has('t')) state.t = p.get('t');
  if (p.has('r') && Number.isFinite(Number(p.get('r')))) state.r = Math.min(4, Math.max(0, Number(p.get('r'))));
  const c = (p.get('c') || '').split('/').map(Number);
  if (c.length === 5 && c.every(Number.isFinite)) state.c = c;
}

function writeHash() {
  if (!map) return;
  const ctr = map.getCenter();
  const c = [map.getZoom(), ctr.lat, ctr.lng, map.getBearing(), map.getPitch()].map((v) => Number(v.toFixed(5)));
  const p = new URLSearchParams({ t: state.t, r: String(state.r), c: c.join('/') });
  const h = '#' + p.toString().replace(/%2F/g, '/');
  history.replaceState(null, '', h);
  $('permalink').href = h;
}

async function show(id, keepCamera) {
  const meta = await (await fetch(`/textures/${encodeURIComponent(id)}`)).json();
  state.t = id;
  $('texture').value = id;
  const style = terrainStyle(location.origin, id, state.r);
  const [zoom, lat, lng, bearing, pitch] = keepCamera && state.c ? state.c : [meta.native_zoom, 0, 0, 20, 60];
  if (!map) {
    map = new maplibregl.Map({
      container: 'map', style, zoom, center: [lng, lat], bearing, pitch, maxPitch: 85,
      maxZoom: meta.maxzoom, renderWorldCopies: true,
    });
    map.addControl(new maplibregl.NavigationControl({ visualizePitch: true }), 'top-right');
    map.addControl(new maplibregl.TerrainControl({ source: 'relief', exaggeration: state.r }), 'top-right');
    map.on('moveend', writeHash);
    window.textileTerrain = map;
  } else {
    map.setStyle(style);
    map.setMaxZoom(meta.maxzoom);
    if (!keepCamera) map.jumpTo({ zoom, center: [lng, lat], bearing, pitch });
  }
  const heights = meta.kind === 'landscape' || (meta.maps || []).some((m) => m.name === 'height')
    ? 'its height map' : 'its luma (it has no height map)';
  $('info').textContent = `${meta.name}: relief from ${heights}, native zoom ${meta.native_zoom}.`;
  writeHash();
}

async function init() {
  readHash();
  const cat = await (await fetch('/catalog')).json();
  const sel = $('texture');
  for (const t of [...cat.textures, ...(cat.landscapes || [])]) sel.append(new Option(t.name, t.id));
  const known = [...cat.textures, ...(cat.landscapes || [])].map((t) => t.id);
  const id = known.includes(state.t) ? state.t : (known.includes('flagstones') ? 'flagstones' : known[0]);
  $('relief').value = state.r;
  $('reliefvalue').textContent = String(state.r);
  await show(id, true);
  sel.addEventListener('change', () => show(sel.value, false));
  $('relief').addEventListener('input', (e) => {
    state.r = Number(e.target.value);
    $('reliefvalue').textContent = String(state.r);
    map.setTerrain({ source: 'relief', exaggeration: state.r });
    writeHash();
  });
  await new Promise((ok) => (map.loaded() ? ok() : map.once('load', ok)));
  document.body.dataset.ready = '1';
}

init().catch((e) => console.error(e));
