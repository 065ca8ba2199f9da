"""Near-regular exemplars made in code for bench/lattice_auto.sh (issue 60): 256² images whose
cells are filled with real texture from the development set (../shared/exemplars).

  tiles    square tiles, pitch 32, granite cells of varied tint, light grout
  grating  bars every 16 texels over gravel
  bond     a running bond: courses 16 high, bricks 32 long, each course shifted by half a brick
  planks   a 1-D plank floor, spacing 256/6 = 42.67 texels (non-integer), grain along the planks
  tread    a diagonal tread plate: lugs along alternate diagonals on the lattice (17.5, ±17.5),
           over the gravel material (issue 70)

Usage: python3 bench/lattice_exemplars.py SHARED_DIR OUT_DIR"""
import sys
import numpy as np
from PIL import Image
E = sys.argv[1] + '/exemplars/'
OUT = sys.argv[2]
def tex(name, side=256):
    return np.asarray(Image.open(E + name).convert('RGB').resize((side, side), Image.BICUBIC)).astype(float)
S = 256
yy, xx = np.mgrid[0:S, 0:S].astype(float)
def save(name, img):
    Image.fromarray(np.clip(img, 0, 255).astype(np.uint8)).save(f'{OUT}/{name}.png')
# Square tiles: pitch 32 (8 per side, toroidal), granite cells with varied tint, light grout.
g = tex('granite_256.png')
rng = np.random.default_rng(1)
tint = rng.uniform(0.8, 1.2, size=(8, 8, 1))
img = (g * 1.3 + 30) * tint[(yy // 32).astype(int), (xx // 32).astype(int)]
grout = ((xx % 32) < 3) | ((yy % 32) < 3)
img[grout] = 190 + 0.15 * (g[grout] - 128)
save('tiles', img)
# Grating: bars every 16 texels (16 per side), gravel between.
v = tex('gravel_256.png')
img = v * 0.6
bar = (xx % 16) < 5
img[bar] = 180 + 0.2 * (v[bar] - 128)
save('grating', img)
# Running bond: courses 16 high, bricks 32 long, shifted by half each course; bark-ish cells.
b = tex('smallstone_256.png')
course = (yy // 16)
along = xx + 16 * (course % 2)
tint = rng.uniform(0.75, 1.25, size=(16, 16, 1))
img = b * tint[course.astype(int), ((along // 32) % 8).astype(int)] * np.array([1.1, 0.75, 0.6])
mortar = ((yy % 16) < 2) | ((along % 32) < 2)
img[mortar] = 200 + 0.1 * (b[mortar] - 128)
save('bond', img)
# Plank floor: 1-D, spacing 256/6 = 42.67 (non-integer), bark texture stretched along planks.
k = np.asarray(Image.open(E + 'granite_256.png').convert('RGB').resize((1024, 256), Image.BICUBIC)).astype(float)[:, 300:556] * 1.4 + 40
tint = rng.uniform(0.92, 1.08, size=(6, 1))
plank = np.floor(yy / (S / 6)).astype(int)
k = k.mean() + 0.6 * (k - k.mean())
img = k * tint[plank] * np.array([1.0, 0.85, 0.65])
gap = (yy % (S / 6)) < 4
img[gap] = 12
save('planks', img)
# Diagonal tread: lugs (bright ellipses along a diagonal) on the lattice a = (p, p), b = (p, -p),
# p = 17.5 (non-integer), over the gravel material.
m = np.asarray(Image.open(E + 'materials/gravel/albedo.png').convert('RGB')).astype(float)
p = 17.5
u, v = ((xx + 0.5) / p + (yy + 0.5) / p) / 2, ((xx + 0.5) / p - (yy + 0.5) / p) / 2
fu, fv = u - np.round(u), v - np.round(v)
dx, dy = p * (fu + fv), p * (fu - fv)
along, across = (dx + dy) / np.sqrt(2), (dx - dy) / np.sqrt(2)
lug = (along / (0.45 * p)) ** 2 + (across / (0.15 * p)) ** 2 <= 1
img = m * 0.7
img[lug] = np.minimum(m[lug] + 90, 255)
save('tread', img)
