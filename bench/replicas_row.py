#!/usr/bin/env python3
"""One markdown row of bench/replicas.sh from `textile loadtest --json` on stdin; argv[1]: the row name."""
import json
import sys

r = json.load(sys.stdin)
lat = r.get("latency_ms", {})
status = " ".join(f"{k}×{v}" for k, v in sorted(r.get("status", {}).items()))
print(f"| {sys.argv[1]} | {r.get('requests')} | {r.get('requests_per_second', 0):.0f} | "
      f"{lat.get('p50', 0):.1f} | {lat.get('p99', 0):.1f} | {status} |")
