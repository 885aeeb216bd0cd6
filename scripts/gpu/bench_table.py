#!/usr/bin/env python3
"""Markdown table of an sf_bench JSON (the median of the repetitions): time, fraction of the
device's measured copy bandwidth (bw_fraction), GB/s and, for the ESM pipeline, fps.
Usage: scripts/gpu/bench_table.py bench.json"""
import json
import re
import sys

d = json.load(open(sys.argv[1]))
ctx = d.get("context", {})
print(f"device: {ctx.get('opencl_device', '?')}, reference copy {float(ctx.get('reference_copy_GBps', 0)):.0f} GB/s "
      f"(read + write), compute units {ctx.get('opencl_compute_units', '?')}\n")
print("| benchmark | median | of copy bandwidth | GB/s | fps |")
print("| --- | ---: | ---: | ---: | ---: |")
rows = [b for b in d["benchmarks"] if b.get("aggregate_name", "median") == "median"]
for b in rows:
    name = re.sub(r"/min_time:[^/]*|/repeats:\d+|/manual_time|_median$", "", b["name"])
    t = f"{b['real_time']:.4g} {b['time_unit']}"
    frac = f"{100 * b['bw_fraction']:.1f} %" if "bw_fraction" in b else ""
    gbs = f"{b['bytes_per_second'] * 1e-9:.0f}" if "bytes_per_second" in b else ""
    fps = f"{b['fps']:.0f}" if "fps" in b else ""
    print(f"| {name} | {t} | {frac} | {gbs} | {fps} |")
