#!/usr/bin/env python3
"""Contact sheet: each exemplar (128 px) beside a 256 px crop of its synthesized output, same scale.

Usage: contact_sheet.py EXEMPLAR_DIR OUTPUT_DIR SHEET.png
"""
import os
import sys

from PIL import Image, ImageDraw

ex_dir, out_dir, sheet = sys.argv[1:4]
names = sorted(n for n in os.listdir(ex_dir) if n.endswith(".png"))
cols, cell_w, cell_h = 2, 128 + 8 + 256 + 24, 256 + 22
rows = (len(names) + cols - 1) // cols
img = Image.new("RGB", (cols * cell_w, rows * cell_h), "white")
draw = ImageDraw.Draw(img)
for i, n in enumerate(names):
    x, y = (i % cols) * cell_w, (i // cols) * cell_h
    ex = Image.open(os.path.join(ex_dir, n)).convert("RGB")
    out = Image.open(os.path.join(out_dir, n)).convert("RGB").crop((0, 0, 256, 256))
    img.paste(ex, (x, y + 20))
    img.paste(out, (x + 136, y + 20))
    draw.text((x, y + 4), n[:-4], fill="black")
os.makedirs(os.path.dirname(sheet) or ".", exist_ok=True)
img.save(sheet)
print("wrote", sheet)
