#!/usr/bin/env python3
"""Cold and cached GLB tiles of a texture (and its flat and relief 3D Tiles content) through two
builds, side by side: `bench/glb_cost.py OLD_BINARY NEW_BINARY DATA_DIR [ROUNDS]`. Each round
starts both servers on copies of DATA_DIR (analyses present), requests 40 cold GLB tiles at
distinct places from each (alternating which goes first), then the same 40 again (cached), and
prints the medians in ms; the last line is the median of the rounds' new/old ratios."""
import shutil, statistics, subprocess, sys, tempfile, time, urllib.request


def start(binary, data, port):
    p = subprocess.Popen([binary, "serve", "--bind", f"127.0.0.1:{port}", "--data-dir", data],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for _ in range(600):
        try:
            urllib.request.urlopen(f"http://127.0.0.1:{port}/ready", timeout=1)
            return p
        except Exception:
            time.sleep(0.1)
    raise SystemExit(f"{binary} did not become ready")


def times(port, paths):
    out = []
    for path in paths:
        t = time.perf_counter()
        urllib.request.urlopen(f"http://127.0.0.1:{port}{path}").read()
        out.append(1000 * (time.perf_counter() - t))
    return statistics.median(out)


def main():
    old, new, data = sys.argv[1:4]
    rounds = int(sys.argv[4]) if len(sys.argv) > 4 else 3
    ratios = {"cold": [], "cached": [], "relief": []}
    for r in range(rounds):
        row = {}
        order = [("old", old, 8711), ("new", new, 8712)]
        if r % 2:
            order.reverse()
        for name, binary, port in order:
            with tempfile.TemporaryDirectory() as d:
                copy = shutil.copytree(data, f"{d}/data")
                p = start(binary, copy, port)
                try:
                    base = 1000 * r  # the same tiles, cold in each server (its own data copy and cache)
                    glb = [f"/gltf/gravel/7/{base + i}/{3 * i}.glb?seed=4" for i in range(40)]
                    relief = [f"/gltf/flagstones/8/{base + i}/{5 * i}.glb?relief=8" for i in range(20)]
                    row[name] = (times(port, glb), times(port, glb), times(port, relief))
                finally:
                    p.terminate()
                    p.wait()
        for k, i in (("cold", 0), ("cached", 1), ("relief", 2)):
            ratios[k].append(row["new"][i] / row["old"][i])
        print(f"round {r}: old cold {row['old'][0]:.2f} cached {row['old'][1]:.3f} relief {row['old'][2]:.2f} ms; "
              f"new cold {row['new'][0]:.2f} cached {row['new'][1]:.3f} relief {row['new'][2]:.2f} ms")
    print("new/old medians: " + ", ".join(f"{k} {statistics.median(v):.3f}" for k, v in ratios.items()))


main()
