#!/usr/bin/env python3
"""Peak resident memory of textile under the worst request mix found: four loops of cold 4096²
windows, four loops of full 262 144-footprint scattered sample batches, 8×8 glTF patches, sixteen
loops of random tiles and a 1024² upload analysed in the background, all at once.

    bench/memory_mix.py BINARY WORKERS SECONDS [extra serve flags…]
    BUDGET=256 bench/memory_mix.py target/release/textile 4 100

Analyses are copied from $TEXTILE_DATA_DIR (default ~/.local/share/textile) when present.
Prints the requests served, the caches' bytes and the peak RSS (VmHWM) to compare with the bound
25 MiB + cache_mib + level_cache_mib + 8 MiB × workers + memory_budget_mib."""
import json, os, random, socket, struct, subprocess, sys, tempfile, threading, time, urllib.request, zlib

BIN, WORKERS, DURATION = sys.argv[1], sys.argv[2], float(sys.argv[3])
s = socket.socket(); s.bind(("127.0.0.1", 0)); port = s.getsockname()[1]; s.close()
base = f"http://127.0.0.1:{port}"
data = tempfile.mkdtemp()
src = os.environ.get("TEXTILE_DATA_DIR", os.path.expanduser("~/.local/share/textile"))
for f in os.listdir(src) if os.path.isdir(src) else []:
    if f.endswith(".tex"):
        subprocess.run(["cp", os.path.join(src, f), data])
env = dict(os.environ, TEXTILE_MEMORY_BUDGET_MIB=os.environ.get("BUDGET", "1024"), TEXTILE_ADMIN_TOKEN="worst-mix-token-0123456789", TEXTILE_MAX_QUEUE_WAIT_MS="600000", TEXTILE_REQUEST_TIMEOUT_SECS="3600")
p = subprocess.Popen([BIN, "serve", "--bind", f"127.0.0.1:{port}", "--data-dir", data, "--workers", WORKERS,
                      "--max-in-flight", "256"] + sys.argv[4:], env=env, stdout=subprocess.DEVNULL, stderr=open(f"{data}/log", "w"))
def status(key):
    for line in open(f"/proc/{p.pid}/status"):
        if line.startswith(key):
            return int(line.split()[1]) / 1024
for _ in range(300):
    try:
        urllib.request.urlopen(base + "/ready"); break
    except Exception:
        time.sleep(0.2)
print(f"ready: RSS {status('VmRSS'):.0f} MiB")
stop = time.time() + DURATION
counts = {}
def loop(name, fn):
    n = 0
    while time.time() < stop:
        try:
            fn(n)
            counts[name] = counts.get(name, 0) + 1
        except Exception as e:
            counts[name + "_err"] = counts.get(name + "_err", 0) + 1
        n += 1
def get(path):
    return urllib.request.urlopen(base + path, timeout=600).read()
def window(i, k):
    get(f"/windows/gravel.png?x={i*5000}&y={k*7919}&w=4096&h=4096&seed={k}")
def samples(i, k):
    rnd = random.Random(i * 1000 + k)
    body = b"".join(struct.pack("<ddf", rnd.uniform(-1e6, 1e6), rnd.uniform(-1e6, 1e6), rnd.uniform(0, 6)) for _ in range(262144))
    req = urllib.request.Request(base + "/samples/grass?records=footprints", data=body,
                                 headers={"Content-Type": "application/octet-stream"})
    urllib.request.urlopen(req, timeout=600).read()
def patch(k):
    get(f"/gltf/brick/patch.glb?z=7&x={k*8}&y={k*3}&tiles=8")
def tile(i, k):
    rnd = random.Random(i * 100000 + k)
    get(f"/tiles/{rnd.choice(['gravel','grass','brick'])}/{rnd.choice([5,6,7])}/{rnd.randint(-10**6,10**6)}/{rnd.randint(-10**6,10**6)}.png?seed={rnd.randint(0,9)}")
def png(w, h, seed):
    rnd = random.Random(seed)
    raw = b"".join(b"\0" + bytes(rnd.getrandbits(8) for _ in range(w * 3)) for _ in range(h))
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
def upload(k):
    if k > 0:
        time.sleep(1); return
    req = urllib.request.Request(base + "/admin/textures?id=big512", data=png(1024, 1024, 1),
                                 headers={"Content-Type": "image/png", "Authorization": "Bearer worst-mix-token-0123456789"})
    urllib.request.urlopen(req, timeout=600).read()
threads = [threading.Thread(daemon=True, target=loop, args=("window", lambda k, i=i: window(i, k))) for i in range(4)]
threads += [threading.Thread(daemon=True, target=loop, args=("samples", lambda k, i=i: samples(i, k))) for i in range(4)]
threads += [threading.Thread(daemon=True, target=loop, args=("patch", patch))]
threads += [threading.Thread(daemon=True, target=loop, args=("tile", lambda k, i=i: tile(i, k))) for i in range(16)]
threads += [threading.Thread(daemon=True, target=loop, args=("upload", upload))]
peak = 0
for t in threads: t.start()
while time.time() < stop:
    peak = max(peak, status("VmRSS")); time.sleep(0.2)
deadline_rss = status("VmRSS")
h = json.loads(urllib.request.urlopen(base + "/health", timeout=10).read())
try:
    m = json.loads(urllib.request.urlopen(base + "/textures/big512", timeout=10).read())
except Exception as e:
    m = {"status": str(e), "progress": "-"}
print("requests:", counts)
print(f"upload: {m['status']} {m['progress']}%")
print(f"reserved at the end {h['memory']['reserved_bytes']/2**20:.0f} MiB of {h['memory']['budget_bytes']/2**20:.0f}")
print(f"tile cache {h['cache']['bytes']/2**20:.0f} MiB (limit {h['cache']['limit_bytes']/2**20:.0f}), level cache {h['level_cache']['bytes']/2**20:.0f} MiB (limit {h['level_cache']['limit_bytes']/2**20:.0f})")
print(f"peak RSS sampled {peak:.0f} MiB, VmHWM {status('VmHWM'):.0f} MiB, at the end {deadline_rss:.0f} MiB")
p.kill(); p.wait(); os._exit(0)
