#!/usr/bin/env python3
"""One markdown table row from a `textile loadtest --json` report on stdin. Usage: load_row.py NAME"""
import json
import sys

r = json.load(sys.stdin)
lat, ok = r["latency_ms"], r["latency_ms_200"]
statuses = " ".join(f"{k}×{v}" for k, v in sorted(r["status"].items()))
print(
    f"| {sys.argv[1]} | {r['concurrency']} | {r['requests']} | {r['requests_per_second']:.1f} | "
    f"{lat['p50']:.2f} | {lat['p99']:.2f} | {ok['p50']:.2f} | {ok['p99']:.2f} | {statuses} | {r['server_cache_hit_ratio']:.3f} | "
    f"{r['server_computation_ratio']:.3f} |"
)
