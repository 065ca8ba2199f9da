#!/usr/bin/env python3
"""Read an exported archive with an independent reader and compare it with a running server.

usage: check_archive.py ARCHIVE BASE_URL [SAMPLES]

PMTiles archives are read with the reference `pmtiles` package (PyPI), MBTiles with Python's
sqlite3. Checks the header/metadata (tile type, zoom range, clustering, tile count) and that
SAMPLES tiles picked at random (fixed seed), plus every tile of the lowest zoom, have the bytes
the server answers for the URL the archive's metadata names. Prints one JSON summary line;
exit status 1 on any mismatch.
"""
import json
import random
import sqlite3
import sys
import urllib.request


def fetch(base, texture, z, x, y, fmt, query):
    url = f"{base}/tiles/{texture}/{z}/{x}/{y}.{fmt}" + (f"?{query}" if query else "")
    with urllib.request.urlopen(url, timeout=120) as r:
        return r.read()


def pmtiles_archive(path):
    from pmtiles.reader import MmapSource, Reader, all_tiles

    f = open(path, "rb")
    reader = Reader(MmapSource(f))
    h = reader.header()
    meta = reader.metadata()
    tiles = {}
    for (z, x, y), data in all_tiles(reader.get_bytes):
        tiles[(z, x, y)] = len(data)
    kinds = {1: "mvt", 2: "png", 3: "jpg", 4: "webp"}
    header = {
        "tile_type": kinds.get(int(h["tile_type"].value), "?"),
        "min_zoom": h["min_zoom"],
        "max_zoom": h["max_zoom"],
        "clustered": h["clustered"],
        "addressed": h["addressed_tiles_count"],
    }
    return header, meta, tiles, lambda z, x, y: reader.get(z, x, y)


def mbtiles_archive(path):
    db = sqlite3.connect(path)
    meta = dict(db.execute("SELECT name, value FROM metadata"))
    extra = json.loads(meta.get("json", "{}"))
    meta.update(extra)
    tiles = {}
    for z, col, row, n in db.execute("SELECT zoom_level, tile_column, tile_row, length(tile_data) FROM tiles"):
        tiles[(z, col, (1 << z) - 1 - row)] = n

    def get(z, x, y):
        r = db.execute(
            "SELECT tile_data FROM tiles WHERE zoom_level=? AND tile_column=? AND tile_row=?",
            (z, x, (1 << z) - 1 - y),
        ).fetchone()
        return r[0] if r else None

    header = {
        "tile_type": meta.get("format"),
        "min_zoom": int(meta["minzoom"]),
        "max_zoom": int(meta["maxzoom"]),
        "clustered": True,
        "addressed": len(tiles),
    }
    return header, meta, tiles, get


def main():
    path, base = sys.argv[1], sys.argv[2]
    samples = int(sys.argv[3]) if len(sys.argv) > 3 else 24
    header, meta, tiles, get = (pmtiles_archive if path.endswith(".pmtiles") else mbtiles_archive)(path)
    t = meta["textile"]
    fmt = meta["format"]
    problems = []
    if header["tile_type"] not in (fmt, {"jpg": "jpeg"}.get(fmt)):
        problems.append(f"tile type {header['tile_type']} but format {fmt}")
    zooms = sorted({z for z, _, _ in tiles})
    if (header["min_zoom"], header["max_zoom"]) != (zooms[0], zooms[-1]):
        problems.append(f"header zooms {header['min_zoom']}..{header['max_zoom']} but tiles at {zooms}")
    if not header["clustered"]:
        problems.append("archive not clustered")
    if header["addressed"] != len(tiles):
        problems.append(f"header says {header['addressed']} tiles, archive has {len(tiles)}")
    rng = random.Random(1)
    keys = sorted(tiles)
    picked = [k for k in keys if k[0] == zooms[0]] + rng.sample(keys, min(samples, len(keys)))
    for z, x, y in picked:
        mine = get(z, x, y)
        served = fetch(base, t["texture"], z + t["zoom_offset"], x, y, fmt, t["query"])
        if mine != served:
            problems.append(f"tile {z}/{x}/{y}: {len(mine or b'')} bytes in the archive, {len(served)} served")
    print(json.dumps({"tiles": len(tiles), "zooms": zooms, "compared": len(picked), "problems": problems}))
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
