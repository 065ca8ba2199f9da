#!/usr/bin/env python3
"""Exemplars at their own size (issue 72): the development set's seamless `_tile.png` sources
(50², 100², 78×43, 82×90, 64²) against their 128 px crops, rendered by synth with
`textile render --exemplar` at three far offsets, 512² native and 512² two zoom steps out.
Scores with texq (`swd`, `edges`, `nn_err`) against the 128 px crop, the reference texture,
means over the offsets; a contact sheet: per texture, the tile and the crop as given, then
their native renders and their zoomed-out renders side by side.

Usage: bench/shapes.py [EXEMPLAR_DIR] [OUT_DIR]   (defaults ../shared/exemplars, bench/out/shapes)
Prints a markdown table; writes OUT_DIR/shapes-sheet.png.
"""
import json
import math
import os
import subprocess
import sys

from PIL import Image, ImageDraw

ex_dir = sys.argv[1] if len(sys.argv) > 1 else "../shared/exemplars"
out = sys.argv[2] if len(sys.argv) > 2 else "bench/out/shapes"
texq = os.path.join(ex_dir, "..", "tools", "texq.py")
binary = "target/release/textile"
names = ["leaves", "granite", "corkboard", "bark", "smallstone"]
offsets = [(5000, 3000), (-7000, 12000), (40000, -900)]
os.makedirs(out, exist_ok=True)


def render(src, x, y, z, path):
    args = [binary, "render", "--exemplar", os.path.join(ex_dir, src + ".png"), "--mode", "synth"]
    args += ["--window", f"{x},{y},512,512", "-o", path] + (["--z", str(z)] if z is not None else [])
    subprocess.run(args, check=True, capture_output=True)


def score(exemplar, output):
    r = subprocess.run(
        ["python3", texq, "score", "--exemplar", exemplar, "--output", output, "--json"],
        check=True, capture_output=True, text=True,
    )
    return json.loads(r.stdout)


rows = []
for n in names:
    row = {"name": n}
    for src in (n + "_tile", n):
        w, h = Image.open(os.path.join(ex_dir, src + ".png")).size
        native = math.ceil(math.log2(max(w, h)))
        sums = {"swd": 0.0, "edges": 0.0, "nn_err": 0.0}
        for i, (x, y) in enumerate(offsets):
            path = os.path.join(out, f"{src}-{i}.png")
            render(src, x, y, None, path)
            s = score(os.path.join(ex_dir, n + ".png"), path)
            for k in sums:
                sums[k] += s[k] / len(offsets)
        render(src, offsets[0][0] // 4, offsets[0][1] // 4, native - 2, os.path.join(out, f"{src}-far.png"))
        row[src] = {"size": f"{w}x{h}", **sums}
    rows.append(row)

print("| texture | tile (size) | swd tile / crop | ratio | edges tile / crop | nn_err tile / crop |")
print("|---|---|---|---|---|---|")
for r in rows:
    t, c = r[r["name"] + "_tile"], r[r["name"]]
    print(
        f"| {r['name']} | {t['size']} | {t['swd']:.4f} / {c['swd']:.4f} | {t['swd'] / c['swd']:.2f} "
        f"| {t['edges']:.2f} / {c['edges']:.2f} | {t['nn_err']:.4f} / {c['nn_err']:.4f} |"
    )

# The contact sheet: exemplars at 2x, native renders (256² crops), zoomed-out renders.
cell_h = 256 + 24
sheet = Image.new("RGB", (4 * 264 + 2 * 200 + 16, len(names) * cell_h), "white")
draw = ImageDraw.Draw(sheet)
for i, n in enumerate(names):
    y = i * cell_h
    x = 0
    for src in (n + "_tile", n):
        ex = Image.open(os.path.join(ex_dir, src + ".png")).convert("RGB")
        label = f"{src} {ex.width}x{ex.height}"
        ex = ex.resize((ex.width * 3 // 2, ex.height * 3 // 2), Image.NEAREST)
        sheet.paste(ex, (x, y + 20))
        draw.text((x, y + 4), label, fill="black")
        x += 200
    for src in (n + "_tile", n):
        sheet.paste(Image.open(os.path.join(out, f"{src}-0.png")).crop((0, 0, 256, 256)), (x, y + 20))
        draw.text((x, y + 4), f"{src}: native", fill="black")
        x += 264
    for src in (n + "_tile", n):
        sheet.paste(Image.open(os.path.join(out, f"{src}-far.png")).resize((256, 256), Image.BOX), (x, y + 20))
        draw.text((x, y + 4), f"{src}: 2 zooms out", fill="black")
        x += 264
sheet.save(os.path.join(out, "shapes-sheet.png"))
sheet.save("docs/shapes-sheet.jpg", quality=85) if os.path.isdir("docs") else None
