#!/usr/bin/env python3
"""Contact sheet of a material texture (issue 39), from a running textile server.

Row 1: the prepared exemplar maps (`/textures/{id}/maps/{name}.png`: colour, normals in glTF's
convention, height, specular) and the exemplar lit; row 2: the same 256² window of the infinite
texture in each map (`/windows/{id}.png?map=NAME`) and it lit. "Lit" is a small software shader:
colour × (0.3 + 0.9 · max(0, n · l)), light from the north-west, 45° up — the viewer's lit preview.

Usage: bench/material_sheet.py BASE_URL ID OUT.jpg [X Y SEED]   (needs pillow and numpy)
"""
import io
import sys
import urllib.request

import numpy as np
from PIL import Image, ImageDraw

MAPS = ["albedo", "normal", "height", "specular"]


def get(url):
    with urllib.request.urlopen(url) as r:
        return np.asarray(Image.open(io.BytesIO(r.read())).convert("RGB")).astype(np.float64)


def lit(colour, normal, azimuth_deg=135.0):
    a = np.radians(azimuth_deg)
    light = np.array([np.cos(a), np.sin(a), 1.0]) / np.sqrt(2.0)
    n = normal / 127.5 - 1.0
    d = np.clip((n * light).sum(-1), 0.0, None)
    return np.clip(colour * (0.3 + 0.9 * d)[..., None], 0, 255)


def main():
    base, tid, out = sys.argv[1].rstrip("/"), sys.argv[2], sys.argv[3]
    x, y, seed = (int(v) for v in (sys.argv[4:7] if len(sys.argv) >= 7 else (5000, -3000, 1)))
    ex = {m: get(f"{base}/textures/{tid}/maps/{m}.png") for m in MAPS}
    side = ex["albedo"].shape[0]
    q = f"x={x}&y={y}&w={side}&h={side}&seed={seed}"
    syn = {m: get(f"{base}/windows/{tid}.png?{q}&map={m}") for m in MAPS}
    rows = [[ex[m] for m in MAPS] + [lit(ex["albedo"], ex["normal"])],
            [syn[m] for m in MAPS] + [lit(syn["albedo"], syn["normal"])]]
    pad, label = 8, 18
    w = len(rows[0]) * (side + pad) + pad
    h = len(rows) * (side + pad + label) + pad
    sheet = Image.new("RGB", (w, h), (24, 24, 24))
    draw = ImageDraw.Draw(sheet)
    names = MAPS + ["lit"]
    for r, row in enumerate(rows):
        for c, img in enumerate(row):
            px, py = pad + c * (side + pad), pad + r * (side + pad + label)
            what = ("exemplar " if r == 0 else "synthesized ") + names[c]
            draw.text((px, py), what, fill=(230, 230, 230))
            sheet.paste(Image.fromarray(img.astype(np.uint8)), (px, py + label))
    sheet.save(out, quality=88)
    print(f"wrote {out} ({w}x{h})")


if __name__ == "__main__":
    main()
