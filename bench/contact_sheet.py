#!/usr/bin/env python3
"""Contact sheet: per exemplar, the exemplar (128 px), a 256 px crop of its synthesized output at
the same scale, and — what a user sees when zoomed out — a 2048 px render box-filtered to 256 px
(one pixel per 8×8 texels), where large-scale streaks and look-alike blocks show.

Usage: contact_sheet.py EXEMPLAR_DIR OUTPUT_DIR BIG_DIR SHEET.png
"""
import os
import sys

from PIL import Image, ImageDraw

ex_dir, out_dir, big_dir, sheet = sys.argv[1:5]
names = sorted(n for n in os.listdir(ex_dir) if n.endswith(".png"))
cols, cell_w, cell_h = 2, 128 + 8 + 256 + 8 + 256 + 24, 256 + 22
rows = (len(names) + cols - 1) // cols
img = Image.new("RGB", (cols * cell_w, rows * cell_h), "white")
draw = ImageDraw.Draw(img)
for i, n in enumerate(names):
    x, y = (i % cols) * cell_w, (i // cols) * cell_h
    ex = Image.open(os.path.join(ex_dir, n)).convert("RGB")
    out = Image.open(os.path.join(out_dir, n)).convert("RGB").crop((0, 0, 256, 256))
    big = Image.open(os.path.join(big_dir, n)).convert("RGB").resize((256, 256), Image.BOX)
    img.paste(ex, (x, y + 20))
    img.paste(out, (x + 136, y + 20))
    img.paste(big, (x + 400, y + 20))
    draw.text((x, y + 4), n[:-4], fill="black")
    draw.text((x + 400, y + 4), "2048 px, zoomed out 8x", fill="black")
os.makedirs(os.path.dirname(sheet) or ".", exist_ok=True)
img.save(sheet)
print("wrote", sheet)
