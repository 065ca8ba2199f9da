#!/usr/bin/env python3
"""One zoom step in pictures (issue 41): the same area of a texture at z = native − 1, scaled ×2
as a map viewer shows it just before the finer tiles arrive, beside the native tiles that
replace it. Renders with the textile binary and writes one JPEG per texture.

Usage: bench/zoom_pictures.py OUT_DIR [BIN, default target/release/textile] [TEXTURE ...]
"""
import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image, ImageDraw


def render(binary, texture, z, window, out):
    subprocess.run([binary, "render", "--texture", texture, "--z", str(z), f"--window={window}", "-o", out],
                   check=True, stdout=subprocess.DEVNULL)
    return Image.open(out).convert("RGB")


def main():
    out_dir = Path(sys.argv[1])
    binary = sys.argv[2] if len(sys.argv) > 2 else "target/release/textile"
    textures = sys.argv[3:] or ["gravel", "brick"]
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for tex in textures:
            # A 256² area at z6 (512² native texels at z7), away from the origin.
            coarse = render(binary, tex, 6, "1024,768,256,256", f"{tmp}/c.png")
            fine = render(binary, tex, 7, "2048,1536,512,512", f"{tmp}/f.png")
            before = coarse.resize((512, 512), Image.BILINEAR)
            sheet = Image.new("RGB", (512 * 2 + 16, 512 + 28), "white")
            sheet.paste(before, (0, 28))
            sheet.paste(fine, (512 + 16, 28))
            d = ImageDraw.Draw(sheet)
            d.text((4, 8), f"{tex}: z6 scaled x2 (before the step)", fill="black")
            d.text((512 + 20, 8), "z7 (after the step)", fill="black")
            sheet.save(out_dir / f"{tex}.jpg", quality=90)
            print(out_dir / f"{tex}.jpg")


if __name__ == "__main__":
    main()
