// textile viewer: the editor of synth's `controls` parameter (design note §1.9) — the noise
// modulation toggle, features dragged from the exemplar thumbnail onto the map (moved by their
// handles, resized and deleted in the panel), and a brush that paints strokes of randomness
// ("calm here, wild there"). The controls live in the tile URLs (base64url JSON, at most 2 KiB)
// and so in the permalink; this file only edits them and draws them over the map.
'use strict';

window.TextileControls = (() => {
  const MAX_LEN = 2048, MAX_STROKES = 64, MAX_FEATURES = 32;
  let current = null; // the live editor: { dispose }

  // Unpadded base64url <-> ASCII JSON text.
  const toB64 = (text) => btoa(text).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
  function fromB64(s) {
    const b = s.replace(/-/g, '+').replace(/_/g, '/');
    return atob(b + '='.repeat((4 - (b.length % 4)) % 4));
  }

  /** The controls a parameter value carries ({noise, strokes, features}); empty when unreadable. */
  function decode(value) {
    const empty = { noise: null, strokes: [], features: [] };
    if (!value) return empty;
    try {
      const j = JSON.parse(fromB64(value));
      return { noise: j.noise || null, strokes: j.strokes || [], features: j.features || [] };
    } catch (e) {
      return empty;
    }
  }

  /** The parameter value of controls, or null when there are none. */
  function encode(ctl) {
    const j = {};
    if (ctl.noise) j.noise = ctl.noise;
    if (ctl.strokes.length) j.strokes = ctl.strokes;
    if (ctl.features.length) j.features = ctl.features;
    return Object.keys(j).length ? toB64(JSON.stringify(j)) : null;
  }

  function dispose() {
    if (current) current.dispose();
    current = null;
  }

  /**
   * Build the editor for the current texture. `o`: map, width and height (exemplar texels), scale
   * (texels per map unit), thumb (the exemplar image element), value (the parameter as given),
   * set(value|null) (store it, no refresh), changed() (refresh the tiles, debounced) and
   * slider(...) (the panel's slider maker). Returns the panel element.
   */
  function editor(o) {
    dispose();
    const ac = new AbortController();
    const on = (el, type, fn) => el.addEventListener(type, fn, { signal: ac.signal });
    const ctl = decode(o.value);
    // Features of another exemplar (a larger one) cannot be served here.
    const given = ctl.features.length;
    ctl.features = ctl.features.filter((f) => f.source && f.source[0] < o.width && f.source[1] < o.height);
    const overlay = L.layerGroup().addTo(o.map);
    const toLatLng = (x, y) => L.latLng(-y / o.scale, x / o.scale);
    const texel = (ll) => [Math.round(ll.lng * o.scale), Math.round(-ll.lat * o.scale)];
    let featureRadius = 16, brushValue = 0, brushSize = 32, brushOn = false;

    const box = document.createElement('div');
    box.className = 'controls-editor';
    const status = document.createElement('output');
    status.id = 'p-controls-status';
    status.setAttribute('aria-live', 'polite');
    const say = (text) => { status.textContent = text; };

    // Store the controls; false (and nothing stored) when they would not fit in a request.
    function store() {
      const v = encode(ctl);
      if (v && v.length > MAX_LEN) { say(`too many controls: ${v.length} of at most ${MAX_LEN} characters`); return false; }
      o.set(v);
      return true;
    }
    const apply = () => { if (store()) { draw(); list(); o.changed(); } };

    // Noise modulation.
    const noiseRow = document.createElement('div');
    noiseRow.className = 'toggle';
    const noise = document.createElement('input');
    Object.assign(noise, { type: 'checkbox', id: 'p-controls', checked: Boolean(ctl.noise) });
    const noiseLabel = document.createElement('label');
    noiseLabel.htmlFor = noise.id;
    noiseLabel.textContent = 'calm and wild regions (noise modulation)';
    on(noise, 'change', () => { ctl.noise = noise.checked ? { scale: 256, range: [0, 1] } : null; apply(); });
    noiseRow.append(noise, noiseLabel);

    // Features.
    const hint = document.createElement('p');
    hint.className = 'hint';
    hint.textContent = 'Drag a point of the exemplar above onto the map: the texture shows it there, exactly. Drag a handle to move it.';
    const features = document.createElement('ul');
    features.id = 'p-controls-features';
    features.setAttribute('aria-label', 'placed features');
    function list() {
      features.textContent = '';
      ctl.features.forEach((f, i) => {
        const li = document.createElement('li');
        const text = document.createElement('span');
        text.textContent = `exemplar (${f.source[0]}, ${f.source[1]}) → (${f.at[0]}, ${f.at[1]})`;
        const del = document.createElement('button');
        Object.assign(del, { type: 'button', id: `p-controls-f${i}-delete`, textContent: '×' });
        del.setAttribute('aria-label', `delete feature ${i + 1}`);
        on(del, 'click', () => { ctl.features.splice(i, 1); apply(); });
        li.append(text, del, o.slider(`p-controls-f${i}-radius`, 'radius', 2, 128, 1, f.inner,
          `radius of feature ${i + 1} in texels`, (r) => { f.inner = r; f.outer = 3 * r; if (store()) draw(); }));
        features.append(li);
      });
    }

    // Thumbnail → map: the exemplar texel under the pointer is dropped where it is released.
    o.thumb.draggable = false;
    o.thumb.classList.add('draggable');
    let picked = null;
    on(o.thumb, 'pointerdown', (e) => {
      e.preventDefault();
      const r = o.thumb.getBoundingClientRect();
      const u = Math.min(o.width - 1, Math.max(0, Math.floor(((e.clientX - r.left) / r.width) * o.width)));
      const v = Math.min(o.height - 1, Math.max(0, Math.floor(((e.clientY - r.top) / r.height) * o.height)));
      picked = [u, v];
      o.thumb.setPointerCapture(e.pointerId);
      document.body.classList.add('placing');
    });
    on(o.thumb, 'pointerup', (e) => {
      document.body.classList.remove('placing');
      if (!picked) return;
      const source = picked;
      picked = null;
      const r = o.map.getContainer().getBoundingClientRect();
      if (e.clientX < r.left || e.clientX > r.right || e.clientY < r.top || e.clientY > r.bottom) return;
      if (ctl.features.length >= MAX_FEATURES) { say(`at most ${MAX_FEATURES} features`); return; }
      const at = texel(o.map.mouseEventToLatLng(e));
      ctl.features.push({ at, source, inner: featureRadius, outer: 3 * featureRadius });
      if (!store()) { ctl.features.pop(); return; }
      say(`feature ${ctl.features.length} placed`);
      apply();
    });
    on(o.thumb, 'pointercancel', () => { picked = null; document.body.classList.remove('placing'); });

    // Brush: strokes of randomness painted on the map while it is on (the map does not pan).
    const brushRow = document.createElement('div');
    brushRow.className = 'toggle';
    const brush = document.createElement('input');
    Object.assign(brush, { type: 'checkbox', id: 'p-controls-brush' });
    const brushLabel = document.createElement('label');
    brushLabel.htmlFor = brush.id;
    brushLabel.textContent = 'paint randomness on the map';
    brushRow.append(brush, brushLabel);
    const container = o.map.getContainer();
    on(brush, 'change', () => {
      brushOn = brush.checked;
      container.classList.toggle('painting', brushOn);
      if (brushOn) o.map.dragging.disable(); else o.map.dragging.enable();
    });
    let last = null;
    const dab = (e) => {
      const at = texel(o.map.mouseEventToLatLng(e));
      if (last && Math.hypot(at[0] - last[0], at[1] - last[1]) < brushSize * 0.75) return;
      if (ctl.strokes.length >= MAX_STROKES) { say(`at most ${MAX_STROKES} strokes`); return; }
      ctl.strokes.push({ at, radius: brushSize, soft: Math.round(brushSize / 2), value: brushValue });
      const v = encode(ctl);
      if (v.length > MAX_LEN) { ctl.strokes.pop(); say('the strokes are full (2 KiB of controls)'); return; }
      last = at;
      draw();
    };
    on(container, 'pointerdown', (e) => {
      if (!brushOn || e.button !== 0 || e.target.closest('.leaflet-control, .feature-handle')) return;
      last = null;
      container.setPointerCapture(e.pointerId);
      dab(e);
    });
    on(container, 'pointermove', (e) => { if (brushOn && container.hasPointerCapture(e.pointerId)) dab(e); });
    on(container, 'pointerup', (e) => {
      if (!brushOn || last === null) return;
      if (container.hasPointerCapture(e.pointerId)) container.releasePointerCapture(e.pointerId);
      last = null;
      apply();
    });

    const clear = document.createElement('button');
    Object.assign(clear, { type: 'button', id: 'p-controls-clear', textContent: 'Clear features and strokes' });
    on(clear, 'click', () => { ctl.features = []; ctl.strokes = []; say(''); apply(); });

    // The overlay: strokes (blue calm … red wild), features' discs and their handles.
    function draw() {
      overlay.clearLayers();
      for (const s of ctl.strokes) {
        const hue = Math.round(240 * (1 - s.value));
        L.circle(toLatLng(s.at[0], s.at[1]), {
          radius: (s.radius + s.soft / 2) / o.scale, stroke: false, fillColor: `hsl(${hue} 80% 50%)`,
          fillOpacity: 0.15, interactive: false,
        }).addTo(overlay);
      }
      ctl.features.forEach((f, i) => {
        const c = toLatLng(f.at[0], f.at[1]);
        L.circle(c, { radius: f.inner / o.scale, weight: 2, color: '#ff0', fill: false, interactive: false }).addTo(overlay);
        L.circle(c, { radius: f.outer / o.scale, weight: 1, color: '#ff0', dashArray: '4 4', fill: false, interactive: false }).addTo(overlay);
        const handle = L.marker(c, {
          draggable: true, keyboard: false, title: `feature ${i + 1}`,
          icon: L.divIcon({ className: 'feature-handle', iconSize: [14, 14] }),
        }).addTo(overlay);
        handle.on('dragend', () => { f.at = texel(handle.getLatLng()); apply(); });
      });
    }

    box.append(noiseRow, hint,
      o.slider('p-controls-radius', 'new feature radius', 2, 128, 1, featureRadius, 'radius of new features in texels',
        (r) => { featureRadius = r; }),
      features, brushRow,
      o.slider('p-controls-strength', 'brush randomness', 0, 1, 0.05, brushValue,
        'randomness the brush paints: 0 keeps the texture calm, 1 wild', (x) => { brushValue = x; }),
      o.slider('p-controls-size', 'brush size', 8, 128, 1, brushSize, 'brush radius in texels', (x) => { brushSize = x; }),
      clear, status);
    if (ctl.features.length !== given) store();
    draw();
    list();
    current = {
      dispose() {
        ac.abort();
        overlay.remove();
        container.classList.remove('painting');
        o.map.dragging.enable();
        o.thumb.classList.remove('draggable');
      },
    };
    return box;
  }

  return { editor, dispose, decode, encode };
})();
