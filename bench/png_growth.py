#!/usr/bin/env python3
"""Where a synth tile's PNG bytes went (issue 71 item 2): the same tiles fetched from two servers
(an old binary and today's), each decoded and re-encoded with both of textile's PNG encoders —
one zlib stream at level 4, unfiltered (the encoder until ENCODER_VERSION 4), and today's
64-row parts, each primed with the 32 KiB before it and ended by a sync flush (pigz's scheme,
`server/src/encode.rs`). The pixels' share of the growth is the difference at one encoder; the
encoder's share the difference on the same pixels.

usage: bench/png_growth.py OLD_URL NEW_URL [--texture gravel] [--zoom 7] [--tiles 300]
"""
import argparse
import io
import statistics
import urllib.request
import zlib

from PIL import Image

PNG_OVERHEAD = 8 + 25 + 12 + 12  # signature, IHDR, one IDAT's framing, IEND
PART_ROWS, WINDOW = 64, 32 * 1024


def raw_rows(img):
    """PNG image data before deflate: each row's filter byte (0, none), then the row."""
    w, h = img.size
    px = img.convert("RGB").tobytes()
    stride = 3 * w
    return b"".join(b"\0" + px[y * stride:(y + 1) * stride] for y in range(h)), stride + 1


def one_stream(raw, _line):
    return PNG_OVERHEAD + len(zlib.compress(raw, 4))


def parts(raw, line):
    part = line * PART_ROWS
    out = 2  # zlib header
    for start in range(0, len(raw), part):
        end = min(start + part, len(raw))
        kw = {"zdict": raw[max(0, start - WINDOW):start]} if start else {}
        z = zlib.compressobj(4, zlib.DEFLATED, -15, **kw)
        data = z.compress(raw[start:end])
        data += z.flush(zlib.Z_FINISH if end == len(raw) else zlib.Z_SYNC_FLUSH)
        out += len(data)
    return PNG_OVERHEAD + out + 4  # Adler-32


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--texture", default="gravel")
    ap.add_argument("--zoom", type=int, default=7)
    ap.add_argument("--tiles", type=int, default=300)
    a = ap.parse_args()
    side = 20
    coords = [(x, y) for y in range(-side // 2, side) for x in range(-side // 2, side)][: a.tiles]
    rows = {k: [] for k in ("served", "one", "parts")}
    table = {(s, k): [] for s in ("old", "new") for k in rows}
    for x, y in coords:
        for name, base in (("old", a.old), ("new", a.new)):
            body = urllib.request.urlopen(f"{base}/tiles/{a.texture}/{a.zoom}/{x}/{y}.png").read()
            raw, line = raw_rows(Image.open(io.BytesIO(body)))
            table[(name, "served")].append(len(body))
            table[(name, "one")].append(one_stream(raw, line))
            table[(name, "parts")].append(parts(raw, line))
    n = len(coords)
    print(f"{n} tiles of {a.texture} at zoom {a.zoom}; mean bytes")
    print("| pixels | served | one stream, level 4 | 64-row parts, level 4 |")
    print("|---|---|---|---|")
    for s in ("old", "new"):
        m = {k: statistics.mean(table[(s, k)]) for k in rows}
        print(f"| {s} | {m['served']:.0f} | {m['one']:.0f} | {m['parts']:.0f} |")
    mo = {k: statistics.mean(table[("old", k)]) for k in rows}
    mn = {k: statistics.mean(table[("new", k)]) for k in rows}
    total = mn["served"] - mo["served"]
    pixels = mn["one"] - mo["one"]
    encoder = mn["parts"] - mn["one"]
    print(f"growth {total:+.0f} bytes: pixels {pixels:+.0f} (one stream, old → new pixels), "
          f"parts {encoder:+.0f} (new pixels, one stream → parts)")


if __name__ == "__main__":
    main()
