// In-page half of clients3d.test.mjs: three.js scenes of textile's glTF tiles, rendered
// offscreen and read back, with the masks the comparisons need. Loaded as a module by the test
// page (served by the test itself under /__3d/ on the server's origin, so every request is
// same-origin). Everything a user would do goes through GLTFLoader and the server's URLs.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const loader = new GLTFLoader();

function renderer(w, h) {
  const r = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  r.setPixelRatio(1);
  r.setSize(w, h);
  return r;
}

function scene() {
  const s = new THREE.Scene();
  s.background = new THREE.Color(0x000000);
  // Ambient light of intensity π shows a rough, non-metallic albedo as it is.
  s.add(new THREE.AmbientLight(0xffffff, Math.PI));
  return s;
}

/** The README's recipe: the GLB of every tile of the ring, added as they come. */
async function ring(base, id, z, tiles, query) {
  const group = new THREE.Group();
  const loads = [];
  for (const [x, y] of tiles) {
    loads.push(loader.loadAsync(`${base}/gltf/${id}/${z}/${x}/${y}.glb${query}`).then((g) => group.add(g.scene)));
  }
  await Promise.all(loads);
  return group;
}

function quad(x0, z0, size, texture) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute([0, 0, 0, size, 0, 0, size, 0, size, 0, 0, size], 3));
  g.setAttribute('normal', new THREE.Float32BufferAttribute([0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0], 3));
  g.setAttribute('uv', new THREE.Float32BufferAttribute([0, 0, 1, 0, 1, 1, 0, 1], 2));
  g.setIndex([0, 2, 1, 0, 3, 2]);
  const m = new THREE.MeshStandardMaterial({ map: texture, metalness: 0, roughness: 1 });
  const mesh = new THREE.Mesh(g, m);
  mesh.position.set(x0, 0, z0);
  return mesh;
}

async function texture(url, mipmaps) {
  const t = await new THREE.TextureLoader().loadAsync(url);
  // As GLTFLoader sets them: glTF's image origin is the top-left, colours are sRGB.
  t.flipY = false;
  t.colorSpace = THREE.SRGBColorSpace;
  t.wrapS = t.wrapT = THREE.ClampToEdgeWrapping;
  t.magFilter = THREE.LinearFilter;
  t.minFilter = mipmaps ? THREE.LinearMipmapLinearFilter : THREE.LinearFilter;
  t.generateMipmaps = mipmaps;
  return t;
}

/** One texture of the whole window the tiles cover. */
async function single(base, id, z, x0, y0, n, query, mipmaps) {
  const url = `${base}/windows/${id}.png?x=${256 * x0}&y=${256 * y0}&w=${256 * n}&h=${256 * n}&z=${z}${query.replace('?', '&')}`;
  return quad(256 * x0, 256 * y0, 256 * n, await texture(url, mipmaps));
}

/** Tiles as textile served them before bordered images: the bare tile PNG on a quad mapped
 * 0..1, clamped to its edge, minified without mipmaps (the old sampler, LINEAR). */
async function bare(base, id, z, tiles, query) {
  const group = new THREE.Group();
  for (const [x, y] of tiles) {
    group.add(quad(256 * x, 256 * y, 256, await texture(`${base}/tiles/${id}/${z}/${x}/${y}.png${query}`, false)));
  }
  return group;
}

function camera(w, h, view) {
  const c = new THREE.PerspectiveCamera(view.fov, w / h, 0.5, 20000);
  c.position.set(...view.eye);
  c.lookAt(new THREE.Vector3(...view.at));
  c.updateMatrixWorld();
  return c;
}

/** Render `object` from `view` at w×h (times `ss`, box-filtered back down): RGBA bytes. */
function shoot(object, view, w, h, ss = 1) {
  const W = w * ss, H = h * ss;
  const r = renderer(W, H);
  const s = scene();
  s.add(object);
  r.render(s, camera(W, H, view));
  const gl = r.getContext();
  const px = new Uint8Array(W * H * 4);
  gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE, px);
  r.dispose();
  s.remove(object);
  // readPixels is bottom-up; make rows top-down and average ss×ss blocks.
  const out = new Float32Array(w * h * 3);
  for (let y = 0; y < H; y++) {
    const src = (H - 1 - y) * W * 4, dst = Math.floor(y / ss) * w;
    for (let x = 0; x < W; x++) {
      const o = (dst + Math.floor(x / ss)) * 3;
      for (let c = 0; c < 3; c++) out[o + c] += px[src + 4 * x + c] / (ss * ss);
    }
  }
  return out;
}

/** Where each pixel's ray meets the ground (world x, z), or null above the horizon. */
function ground(view, w, h) {
  const c = camera(w, h, view);
  const at = new Array(w * h);
  const v = new THREE.Vector3();
  for (let y = 0; y < h; y++) {
    for (let x = 0; x < w; x++) {
      v.set(((x + 0.5) / w) * 2 - 1, 1 - ((y + 0.5) / h) * 2, 0.5).unproject(c);
      const d = v.sub(c.position);
      at[y * w + x] = d.y < 0 ? [c.position.x - (c.position.y / d.y) * d.x, c.position.z - (c.position.y / d.y) * d.z] : null;
    }
  }
  return at;
}

/** Pixel classes: 2 = within `reach` pixels of a tile edge, 1 = elsewhere on the covered
 * ground [lo, hi)², 0 = not compared (sky, outside the tiles, the far rim). */
function classes(view, w, h, lo, hi, reach) {
  const at = ground(view, w, h);
  const cls = new Uint8Array(w * h);
  const cell = (p) => (p ? `${Math.floor(p[0] / 256)},${Math.floor(p[1] / 256)}` : null);
  for (let y = reach; y < h - reach; y++) {
    for (let x = reach; x < w - reach; x++) {
      const p = at[y * w + x];
      if (!p || p[0] < lo + 8 || p[1] < lo + 8 || p[0] >= hi - 8 || p[1] >= hi - 8) continue;
      const here = cell(p);
      let edge = false;
      for (let dy = -reach; dy <= reach && !edge; dy++) {
        for (let dx = -reach; dx <= reach && !edge; dx++) {
          if (cell(at[(y + dy) * w + x + dx]) !== here) edge = true;
        }
      }
      cls[y * w + x] = edge ? 2 : 1;
    }
  }
  return cls;
}

/** Per class (1: elsewhere, 2: edges): pixel count, mean absolute difference (levels, over
 * channels) and the share of pixels differing by more than 8 levels in some channel. */
function compare(a, b, cls) {
  const stats = { 1: { n: 0, sum: 0, over8: 0 }, 2: { n: 0, sum: 0, over8: 0 } };
  for (let i = 0; i < cls.length; i++) {
    const s = stats[cls[i]];
    if (!s) continue;
    let worst = 0;
    for (let c = 0; c < 3; c++) {
      const d = Math.abs(a[3 * i + c] - b[3 * i + c]);
      s.sum += d / 3;
      worst = Math.max(worst, d);
    }
    s.n++;
    if (worst > 8) s.over8++;
  }
  const out = {};
  for (const k of [1, 2]) {
    const s = stats[k];
    out[k === 1 ? 'elsewhere' : 'edges'] = { pixels: s.n, mean: s.sum / Math.max(1, s.n), over8: s.over8 / Math.max(1, s.n) };
  }
  return out;
}

function grid(x0, y0, n) {
  const t = [];
  for (let y = y0; y < y0 + n; y++) for (let x = x0; x < x0 + n; x++) t.push([x, y]);
  return t;
}

function png(rgb, w, h) {
  const c = document.createElement('canvas');
  c.width = w;
  c.height = h;
  const ctx = c.getContext('2d');
  const img = ctx.createImageData(w, h);
  for (let i = 0; i < w * h; i++) {
    for (let k = 0; k < 3; k++) img.data[4 * i + k] = Math.round(rgb[3 * i + k]);
    img.data[4 * i + 3] = 255;
  }
  ctx.putImageData(img, 0, 0);
  return c.toDataURL('image/png');
}

/** The close view: the README's 3×3 ring around tile (0, 0) against one texture of the same
 * 768² window, both mipmapped; and the bare tiles of before against the same. */
export async function closeView({ base, id, z, query, view, w, h, reach }) {
  const tiles = grid(-1, -1, 3);
  const cls = classes(view, w, h, -256, 512, reach);
  const one = shoot(await single(base, id, z, -1, -1, 3, query, true), view, w, h);
  const padded = shoot(await ring(base, id, z, tiles, query), view, w, h);
  const old = shoot(await bare(base, id, z, tiles, query), view, w, h);
  const oneNoMip = shoot(await single(base, id, z, -1, -1, 3, query, false), view, w, h);
  return {
    tiles: compare(padded, one, cls),
    bare: compare(old, oneNoMip, cls),
    pictures: { tiles: png(padded, w, h), single: png(one, w, h), bare: png(old, w, h) },
  };
}

/** The far view: an n×n ring seen at a grazing angle, against a 4×-supersampled render of one
 * texture of the same window (no mipmaps: 16 samples per pixel are the reference), for the
 * bordered mipmapped tiles and for the bare tiles of before. */
export async function farView({ base, id, z, query, view, w, h, n }) {
  const x0 = -Math.floor(n / 2);
  const tiles = grid(x0, x0, n);
  const cls = classes(view, w, h, 256 * x0, 256 * (x0 + n), 0);
  const reference = shoot(await single(base, id, z, x0, x0, n, query, false), view, w, h, 4);
  const padded = shoot(await ring(base, id, z, tiles, query), view, w, h);
  const old = shoot(await bare(base, id, z, tiles, query), view, w, h);
  return {
    tiles: compare(padded, reference, cls),
    bare: compare(old, reference, cls),
    pictures: { tiles: png(padded, w, h), reference: png(reference, w, h), bare: png(old, w, h) },
  };
}

/** Pearson correlation of two equally long arrays. */
function correlation(a, b) {
  const n = a.length;
  let ma = 0, mb = 0;
  for (let i = 0; i < n; i++) { ma += a[i] / n; mb += b[i] / n; }
  let ab = 0, aa = 0, bb = 0;
  for (let i = 0; i < n; i++) {
    ab += (a[i] - ma) * (b[i] - mb);
    aa += (a[i] - ma) ** 2;
    bb += (b[i] - mb) ** 2;
  }
  return ab / Math.sqrt(aa * bb);
}

/** The lit material: one tile's GLB as GLTFLoader gives it, seen straight down (north up, one
 * pixel per texel) under a low sun from the east, west, north and south in turn. Where the
 * normal map says the surface faces east, the east sun must light it more than the west one:
 * the east-minus-west brightness is correlated with the served normals' x (red), and
 * north-minus-south with their y (green, +Y up = north). Also says what the material holds. */
export async function litView({ base, id, z, x, y, query }) {
  const gltf = await loader.loadAsync(`${base}/gltf/${id}/${z}/${x}/${y}.glb${query}`);
  const mesh = gltf.scene.getObjectByProperty('type', 'Mesh');
  const m = mesh.material;
  const holds = { normalMap: Boolean(m.normalMap), specular: Boolean(m.specularColorMap), type: m.type };
  const box = new THREE.Box3().setFromObject(gltf.scene);
  const c = box.getCenter(new THREE.Vector3());
  const half = (box.max.x - box.min.x) / 2;
  const W = 256;
  const shot = (dir) => {
    const r = renderer(W, W);
    const s = new THREE.Scene();
    s.background = new THREE.Color(0x000000);
    s.add(new THREE.AmbientLight(0xffffff, 0.3));
    const sun = new THREE.DirectionalLight(0xffffff, 3);
    sun.position.set(c.x + dir[0], 1, c.z + dir[1]);
    sun.target.position.copy(c);
    s.add(sun, sun.target, gltf.scene);
    const cam = new THREE.OrthographicCamera(-half, half, half, -half, 0.1, 1000);
    cam.position.set(c.x, 100, c.z);
    cam.up.set(0, 0, -1);
    cam.lookAt(c);
    cam.updateMatrixWorld();
    r.render(s, cam);
    const gl = r.getContext();
    const px = new Uint8Array(W * W * 4);
    gl.readPixels(0, 0, W, W, gl.RGBA, gl.UNSIGNED_BYTE, px);
    r.dispose();
    s.remove(gltf.scene);
    const lum = new Float32Array(W * W);
    for (let j = 0; j < W; j++) {
      for (let i = 0; i < W; i++) {
        const o = 4 * ((W - 1 - j) * W + i);
        lum[j * W + i] = px[o] + px[o + 1] + px[o + 2];
      }
    }
    return lum;
  };
  // A low sun (height 1 for 3 sideways): slopes matter.
  const [e, w, n, s] = [[3, 0], [-3, 0], [0, -3], [0, 3]].map(shot);
  const img = new Image();
  img.src = `${base}/tiles/${id}/${z}/${x}/${y}.png${query}${query ? '&' : '?'}map=normal`;
  await img.decode();
  const cv = document.createElement('canvas');
  cv.width = cv.height = W;
  const ctx = cv.getContext('2d');
  ctx.drawImage(img, 0, 0);
  const nd = ctx.getImageData(0, 0, W, W).data;
  const nx = new Float32Array(W * W), ny = new Float32Array(W * W);
  for (let i = 0; i < W * W; i++) { nx[i] = nd[4 * i] - 127.5; ny[i] = nd[4 * i + 1] - 127.5; }
  const ew = e.map((v, i) => v - w[i]);
  const ns = n.map((v, i) => v - s[i]);
  return { holds, ew: correlation(ew, nx), ns: correlation(ns, ny), swapped: correlation(ew, ny) };
}
