// In-page half of the X_ITE test of clients3d.test.mjs: decode screenshots and compare them
// with tile images, in the page (no pixel arrays cross to node).

async function rgbOf(url, w, h) {
  const img = new Image();
  img.src = url;
  await img.decode();
  const c = document.createElement('canvas');
  c.width = w ?? img.width;
  c.height = h ?? img.height;
  const ctx = c.getContext('2d');
  ctx.imageSmoothingQuality = 'high';
  ctx.drawImage(img, 0, 0, c.width, c.height);
  const d = ctx.getImageData(0, 0, c.width, c.height).data;
  const rgb = new Float32Array((d.length / 4) * 3);
  for (let i = 0, j = 0; i < d.length; i += 4, j += 3) [rgb[j], rgb[j + 1], rgb[j + 2]] = [d[i], d[i + 1], d[i + 2]];
  return { w: c.width, h: c.height, rgb };
}

let shot;

/** Decode a screenshot (base64 PNG), keep it, and say its size and mean level. */
export async function look(b64) {
  const url = `data:image/png;base64,${b64}`;
  shot = await rgbOf(url);
  let sum = 0;
  for (const v of shot.rgb) sum += v;
  return { w: shot.w, h: shot.h, mean: sum / shot.rgb.length, url };
}

/** RGB (w×h) averaged over k×k blocks. */
function shrink({ w, h, rgb }, k) {
  const W = Math.floor(w / k), H = Math.floor(h / k);
  const out = new Float32Array(W * H * 3);
  for (let y = 0; y < H * k; y++) {
    for (let x = 0; x < W * k; x++) {
      for (let c = 0; c < 3; c++) out[3 * (Math.floor(y / k) * W + Math.floor(x / k)) + c] += rgb[3 * (y * w + x) + c] / (k * k);
    }
  }
  return { w: W, h: H, rgb: out };
}

function crop({ w, rgb }, x0, y0, cw, ch) {
  const out = new Float32Array(cw * ch * 3);
  for (let y = 0; y < ch; y++) out.set(rgb.subarray(3 * ((y0 + y) * w + x0), 3 * ((y0 + y) * w + x0 + cw)), 3 * y * cw);
  return { w: cw, h: ch, rgb: out };
}

/** Pearson correlation of luminance between the middle cell of the last screenshot cut into
 * n×n cells and the image at `url` drawn at that cell's size, both averaged over k×k blocks. */
export async function correlate(url, n, k) {
  const side = Math.floor(shot.w / n);
  const a = shrink(crop(shot, side * Math.floor(n / 2), side * Math.floor(n / 2), side, side), k);
  const b = shrink(await rgbOf(url, side, side), k);
  const lum = (v, i) => 0.299 * v[i] + 0.587 * v[i + 1] + 0.114 * v[i + 2];
  let m = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (let i = 0; i < a.rgb.length; i += 3) {
    const x = lum(a.rgb, i), y = lum(b.rgb, i);
    m++; sa += x; sb += y; saa += x * x; sbb += y * y; sab += x * y;
  }
  const cov = sab / m - (sa / m) * (sb / m);
  return cov / Math.sqrt((saa / m - (sa / m) ** 2) * (sbb / m - (sb / m) ** 2));
}

const kept = {};

/** Keep the last screenshot under `name`. */
export function keep(name) {
  kept[name] = shot;
}

/** Pearson correlation, over k×k blocks, of the luminance of kept screenshot `a` less that of
 * kept `b` with channel `c` of the image at `url` drawn at the screenshots' size: how far what
 * changed between two lights follows a map (a normal map's x or y). */
export async function change(a, b, url, c, k) {
  const [sa, sb] = [shrink(kept[a], k), shrink(kept[b], k)];
  const m = shrink(await rgbOf(url, kept[a].w, kept[a].h), k);
  const lum = (v, i) => 0.299 * v[i] + 0.587 * v[i + 1] + 0.114 * v[i + 2];
  let n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (let i = 0; i < sa.rgb.length; i += 3) {
    const x = lum(sa.rgb, i) - lum(sb.rgb, i), y = m.rgb[i + c];
    n++; sx += x; sy += y; sxx += x * x; syy += y * y; sxy += x * y;
  }
  const cov = sxy / n - (sx / n) * (sy / n);
  return cov / Math.sqrt((sxx / n - (sx / n) ** 2) * (syy / n - (sy / n) ** 2));
}
