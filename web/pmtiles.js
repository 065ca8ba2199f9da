// textile archive page: an exported PMTiles archive (`?url=`) shown with OpenLayers, every tile
// read by byte range through the pmtiles library. Sets body[data-ready] once the header is read
// and counts tiles in window.textileArchive for tests.
(async () => {
  const info = document.getElementById('info');
  const url = new URLSearchParams(location.search).get('url');
  const state = { loaded: 0, missing: 0, failed: 0, header: null, metadata: null };
  window.textileArchive = state;
  if (!url) {
    info.textContent = 'Give the archive: ?url=/archives/NAME.pmtiles';
    document.body.dataset.ready = '1';
    return;
  }
  const archive = new pmtiles.PMTiles(url);
  try {
    state.header = await archive.getHeader();
    state.metadata = await archive.getMetadata();
  } catch (e) {
    info.textContent = `Cannot read ${url}: ${e}`;
    document.body.dataset.ready = '1';
    return;
  }
  const h = state.header;
  const types = { 2: 'image/png', 3: 'image/jpeg', 4: 'image/webp' };
  const mime = types[h.tileType] || 'application/octet-stream';
  const source = new ol.source.XYZ({
    minZoom: h.minZoom,
    maxZoom: h.maxZoom,
    wrapX: true,
    crossOrigin: 'anonymous',
    tileUrlFunction: (c) => `${c[0]}/${c[1]}/${c[2]}`,
    tileLoadFunction: (tile, key) => {
      const [z, x, y] = key.split('/').map(Number);
      archive.getZxy(z, x, y).then((r) => {
        if (!r) { state.missing++; tile.setState(4); return; }
        const img = tile.getImage();
        const blobUrl = URL.createObjectURL(new Blob([r.data], { type: mime }));
        img.onload = () => { URL.revokeObjectURL(blobUrl); state.loaded++; };
        img.src = blobUrl;
      }).catch(() => { state.failed++; tile.setState(3); });
    },
  });
  const attribution = state.metadata && state.metadata.attribution;
  if (attribution) source.setAttributions(attribution);
  // The view starts where the archive says: its centre and centre zoom, and an archive of part
  // of the world (`textile export --bbox`) fitted to its bounds instead of an empty [0, 0].
  const view = new ol.View({
    center: ol.proj.fromLonLat([h.centerLon, h.centerLat]),
    zoom: Math.max(h.minZoom, Math.min(h.maxZoom, h.centerZoom)),
    minZoom: h.minZoom,
    maxZoom: h.maxZoom,
  });
  const whole = h.minLon <= -179.9 && h.maxLon >= 179.9 && h.minLat <= -85 && h.maxLat >= 85;
  const map = new ol.Map({ target: 'map', layers: [new ol.layer.Tile({ source })], view });
  if (!whole && h.minLon < h.maxLon && h.minLat < h.maxLat) {
    const extent = ol.proj.transformExtent([h.minLon, h.minLat, h.maxLon, h.maxLat], 'EPSG:4326', 'EPSG:3857');
    view.fit(extent, { size: map.getSize(), maxZoom: h.maxZoom });
  }
  state.view = () => ({ center: ol.proj.toLonLat(view.getCenter()), zoom: view.getZoom() });
  const t = (state.metadata && state.metadata.textile) || {};
  info.textContent = `${state.metadata.name || url}: zooms ${h.minZoom}–${h.maxZoom}, ${h.numAddressedTiles} tiles`
    + (t.texture ? `, texture '${t.texture}${t.query ? `?${t.query}` : ''}'` : '');
  document.body.dataset.ready = '1';
})();
