#!/usr/bin/env python3
"""Before/after sheet: per exemplar, the exemplar, 256 px of the output of the code before and of
the code now at the same window, and a 96 px crop of each magnified 2x (nearest), where patch
seams show.

Usage: before_after.py EXEMPLAR_DIR BEFORE_DIR AFTER_DIR SHEET.png NAME...
"""
import os
import sys

from PIL import Image, ImageDraw

ex_dir, before_dir, after_dir, sheet = sys.argv[1:5]
names = sys.argv[5:]
cell_h = 256 + 22
width = 128 + 8 + 2 * (256 + 8) + 2 * (192 + 8)
img = Image.new("RGB", (width, len(names) * cell_h), "white")
draw = ImageDraw.Draw(img)
for i, n in enumerate(names):
    y = i * cell_h
    ex = Image.open(os.path.join(ex_dir, n + ".png")).convert("RGB")
    outs = [Image.open(os.path.join(d, n + ".png")).convert("RGB") for d in (before_dir, after_dir)]
    img.paste(ex, (0, y + 20))
    draw.text((0, y + 4), n, fill="black")
    x = 136
    for label, out in zip(("before", "now"), outs):
        img.paste(out.crop((0, 0, 256, 256)), (x, y + 20))
        draw.text((x, y + 4), label, fill="black")
        x += 264
    for label, out in zip(("before, 2x", "now, 2x"), outs):
        img.paste(out.crop((0, 0, 96, 96)).resize((192, 192), Image.NEAREST), (x, y + 20))
        draw.text((x, y + 4), label, fill="black")
        x += 200
os.makedirs(os.path.dirname(sheet) or ".", exist_ok=True)
img.save(sheet)
