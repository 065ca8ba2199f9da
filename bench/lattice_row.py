"""One row of bench/lattice.sh: how near-regular a render is.

Usage: lattice_row.py TEXQ_DIR IMAGE CELL_W CELL_H EXEMPLAR_SIDE
Prints: autocorrelation of the luma at the lattice vectors (cw, 0) and (0, ch) and at a
half-cell offset (cw/2, 0) for contrast; texq `streak`; and the same streak statistic with the
lattice's own frequencies (every (a·n/cw, b·n/ch) and an 8-bin disc around it, past the skirt of texq's σ = 2 smoothing) masked out —
what regularity is left that the lattice does not explain.
"""
import sys

import numpy as np
from PIL import Image

sys.path.insert(0, sys.argv[1])
import texq  # noqa: E402
from scipy.ndimage import gaussian_filter  # noqa: E402

img = np.asarray(Image.open(sys.argv[2]).convert("RGB"))
cw, ch, m = int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])


def autocorr(g, dx, dy):
    a = g[dy:, dx:]
    b = g[: g.shape[0] - dy, : g.shape[1] - dx]
    return float((a * b).mean() / (g * g).mean())


g = texq.luma(img).astype(np.float64)
g -= g.mean()
full = texq.streaks_array(img, m)["streak"]

# texq's streak statistic, lattice frequencies excluded.
n = min(g.shape)
gg = g[:n, :n] - g[:n, :n].mean()
P = gaussian_filter(np.abs(np.fft.fftshift(np.fft.fft2(gg))) ** 2, 2.0)
fy, fx = np.meshgrid(np.arange(n) - n // 2, np.arange(n) - n // 2, indexing="ij")
r = np.hypot(fx, fy)
ri = np.rint(r).astype(np.int64)
ring = (r >= n / (2.0 * m)) & (r <= 2.0 * n / m)
ux, uy = n / cw, n / ch
near = (np.hypot(fx - ux * np.rint(fx / ux), fy - uy * np.rint(fy / uy)) <= 8)
Q = np.zeros_like(P)
for k in np.unique(ri[ring]):
    sel = ri == k
    med = np.median(P[sel])
    Q[sel] = P[sel] / med if med > 0 else 0.0
outside = float(np.where(ring & ~near, Q, 0.0).max())
print(f"{autocorr(g, cw, 0):.3f} | {autocorr(g, 0, ch):.3f} | {autocorr(g, cw // 2, 0):.3f} | {full:.2f} | {outside:.2f}")
