#!/usr/bin/env python3
"""Checks of replicas behind nginx (run by deploy/test.sh, which starts and stops everything).

usage: check.py NGINX_URL REPLICA_URL REPLICA_URL REPLICA_URL --kill-pid PID

(a) ~50 URLs (zooms, negative coordinates, every format, @2x, world, modes) are byte-identical
    with identical ETags from each replica and through nginx;
(b) the same URI always reaches the same replica, and distinct URIs spread over all three
    (tiles of one 10 × 10 block share a replica: the nginx configuration's affinity key);
(c) kill -9 of the replica with PID during a 16-client load over ~2000 cold URIs: zero failed
    requests, every body equal to the reference;
(d) 100 concurrent requests for one fresh URI: exactly one synthesis over the live replicas;
(e) If-None-Match through nginx: 304.
"""
import hashlib
import os
import signal
import sys
import threading
import time
import urllib.error
import urllib.request
from concurrent.futures import ThreadPoolExecutor


def get(url, headers=None):
    req = urllib.request.Request(url, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=120) as r:
            return r.status, dict((k.lower(), v) for k, v in r.headers.items()), r.read()
    except urllib.error.HTTPError as e:
        return e.code, dict((k.lower(), v) for k, v in e.headers.items()), e.read()


def syntheses(base):
    _, _, body = get(base + "/metrics")
    total = 0
    for line in body.decode().splitlines():
        if line.startswith("textile_syntheses_total{") or line.startswith("syntheses_total{"):
            total += int(float(line.rsplit(" ", 1)[1]))
    return total


def fail(msg):
    print("FAILED:", msg, file=sys.stderr)
    sys.exit(1)


def main():
    args = sys.argv[1:]
    kill_pid = int(args[args.index("--kill-pid") + 1])
    nginx, replicas = args[0], args[1:4]

    # (a) The same bytes and ETags everywhere.
    urls = []
    for tex in ("gravel", "brick"):
        for z, x, y in ((7, 0, 0), (7, -3, 5), (6, -1, -1), (5, 2, -7), (3, 0, 0), (7, -(2**31), 2**31 - 1)):
            for fmt in ("png", "jpg", "webp"):
                urls.append(f"/tiles/{tex}/{z}/{x}/{y}.{fmt}")
        urls.append(f"/tiles/{tex}/6/1/1@2x.png")
        urls.append(f"/tiles/{tex}/7/1/1.png?world=4")
        urls.append(f"/tiles/{tex}/7/2/3.png?mode=mosaic&seed=3")
        urls.append(f"/tiles/{tex}/5/0/1.webp?mode=tiling")
    urls.append("/windows/grass.png?x=-100&y=40&w=300&h=200")
    for u in urls:
        answers = [get(r + u) for r in replicas] + [get(nginx + u)]
        statuses = {a[0] for a in answers}
        bodies = {hashlib.sha256(a[2]).hexdigest() for a in answers}
        etags = {a[1].get("etag") for a in answers}
        if statuses != {200} or len(bodies) != 1 or len(etags) != 1:
            fail(f"(a) {u}: statuses {statuses}, {len(bodies)} bodies, etags {etags}")
    print(f"(a) {len(urls)} URLs: identical bytes and ETags from 3 replicas and nginx")

    # (b) URI affinity.
    seen = {}
    for i in range(60):
        u = f"/tiles/gravel/7/{37 * i}/{-53 * i}.png?mode=mosaic"
        ups = set()
        for _ in range(3):
            s, h, _ = get(nginx + u, {"X-Cache-Bypass": "1"})
            if s != 200:
                fail(f"(b) {u}: {s}")
            ups.add(h.get("x-upstream"))
        if len(ups) != 1:
            fail(f"(b) {u} reached {ups}")
        seen[u] = ups.pop()
    spread = {v: list(seen.values()).count(v) for v in set(seen.values())}
    if len(spread) != 3:
        fail(f"(b) 60 URIs reached only {spread}")
    # Neighbours in one 10 × 10 block of tiles share a replica (the affinity key).
    block = {get(nginx + f"/tiles/brick/7/{40 + d}/{-21 - d}.png", {"X-Cache-Bypass": "1"})[1].get("x-upstream") for d in range(7)}
    if len(block) != 1:
        fail(f"(b) one block of tiles reached {block}")
    print(f"(b) each URI always reaches one replica; 60 URIs spread {sorted(spread.values())}; a block shares one")

    # (d) 100 concurrent requests for one fresh URI: one synthesis (before any replica dies).
    before = sum(syntheses(r) for r in replicas)
    fresh = "/tiles/grass/7/12345/-6789.png?seed=99"
    with ThreadPoolExecutor(100) as ex:
        answers = list(ex.map(lambda _: get(nginx + fresh), range(100)))
    if {a[0] for a in answers} != {200} or len({a[2] for a in answers}) != 1:
        fail(f"(d) statuses {set(a[0] for a in answers)}")
    after = sum(syntheses(r) for r in replicas)
    if after - before != 1:
        fail(f"(d) {after - before} syntheses for 100 concurrent requests of one URI")
    print("(d) 100 concurrent requests of one fresh URI: exactly 1 synthesis")

    # (e) If-None-Match through nginx.
    s, h, _ = get(nginx + fresh)
    s2, _, body = get(nginx + fresh, {"If-None-Match": h["etag"]})
    if s2 != 304 or body:
        fail(f"(e) If-None-Match answered {s2}")
    print("(e) If-None-Match through nginx: 304")

    # (c) kill -9 during load: no failure, every body as the reference.
    load = [f"/tiles/{t}/{z}/{x}/{y}.png?mode=mosaic&seed=11"
            for t in ("gravel", "brick") for z in (7, 6) for x in range(-12, 13) for y in range(-10, 10)]
    load += [f"/tiles/grass/7/{x}/{y}.png?seed=5" for x in range(40, 50) for y in range(10)]
    done, failures, lock = [0], [], threading.Lock()
    results = {}

    def fetch(u):
        s, _, body = get(nginx + u)
        with lock:
            done[0] += 1
            if s != 200:
                failures.append((u, s))
            results[u] = hashlib.sha256(body).hexdigest()

    def killer():
        while done[0] < len(load) // 4:
            time.sleep(0.01)
        os.kill(kill_pid, signal.SIGKILL)
        print(f"(c) killed replica pid {kill_pid} after {done[0]} of {len(load)} requests")

    k = threading.Thread(target=killer)
    k.start()
    t0 = time.time()
    with ThreadPoolExecutor(16) as ex:
        list(ex.map(fetch, load))
    k.join()
    if failures:
        fail(f"(c) {len(failures)} failed requests, e.g. {failures[:3]}")
    live = replicas[:2]
    for i, u in enumerate(load):
        ref = hashlib.sha256(get(live[i % 2] + u)[2]).hexdigest()
        if results[u] != ref:
            fail(f"(c) {u}: body differs from the reference")
    print(f"(c) {len(load)} cold URIs, 16 clients, a replica killed: 0 failures, all bodies equal ({time.time() - t0:.1f} s)")


if __name__ == "__main__":
    main()
