// textile world page: OpenLayers in Web Mercator with `world=2^native` so the texture repeats
// exactly once around the world at every zoom (toroidal synthesis) and wraps without a seam.
'use strict';

const p = new URLSearchParams(location.hash.slice(1));
let map = null;

async function show(id) {
  const meta = await (await fetch(`/textures/${encodeURIComponent(id)}`)).json();
  const world = 2 ** meta.native_zoom;
  const q = new URLSearchParams({ world: String(world), mode: p.get('m') || meta.default_mode, seed: p.get('s') || '0' });
  const source = new ol.source.XYZ({
    url: `/tiles/${encodeURIComponent(id)}/{z}/{x}/{y}.png?` + q.toString(),
    wrapX: true, minZoom: meta.minzoom, maxZoom: meta.maxzoom, crossOrigin: 'anonymous',
  });
  const layer = new ol.layer.Tile({ source });
  if (!map) {
    map = new ol.Map({ target: 'map', layers: [layer], view: new ol.View({ center: [0, 0], zoom: Math.max(2, meta.native_zoom - 2), maxZoom: meta.maxzoom }) });
    window.textileWorld = map;
  } else {
    map.setLayers([layer]);
  }
  document.getElementById('info').textContent =
    `world=${world} native tiles: at zoom z the texture period is 2^z tiles, exactly the wrapped world.`;
}

async function init() {
  const cat = await (await fetch('/catalog')).json();
  const sel = document.getElementById('texture');
  for (const t of cat.textures) sel.append(new Option(t.name, t.id));
  const id = cat.textures.some((t) => t.id === p.get('t')) ? p.get('t') : cat.textures[0].id;
  sel.value = id;
  sel.addEventListener('change', () => show(sel.value));
  await show(id);
  document.body.dataset.ready = '1';
}

init().catch((e) => console.error(e));
