#!/usr/bin/env python3
"""Markdown tables for docs/results.md from `shadowfilter evaluate` results.csv files.

usage: make_tables.py results.csv [more.csv ...]

Per scene: the Pareto front of (median ms, s_ref RMSE) and of (median ms, reference_soft RMSE),
and each method's most accurate configuration against s_ref.
"""
import csv
import sys
from collections import OrderedDict


def front(rows, key):
    rows = sorted(rows, key=lambda r: (r["time_ms"], r[key]))
    out, best = [], float("inf")
    for r in rows:
        if r[key] < best:
            out.append(r)
            best = r[key]
    return out


def num(v):
    try:
        return float(v)
    except ValueError:
        return float("nan")


def main(paths):
    scenes = OrderedDict()
    for p in paths:
        with open(p) as f:
            for r in csv.DictReader(f):
                for k in ("time_ms", "min_ms", "sref_rmse", "sref_p99", "soft_rmse", "hard_rmse", "device_bytes"):
                    r[k] = num(r[k])
                scenes.setdefault(r["scene"], []).append(r)
    for scene, rows in scenes.items():
        print(f"### {scene} ({len(rows)} configurations)\n")
        print("| Pareto front vs s_ref | median ms | min ms | s_ref RMSE | s_ref p99 | soft RMSE |")
        print("|---|---|---|---|---|---|")
        for r in front(rows, "sref_rmse"):
            print(f"| {r['config']} | {r['time_ms']:.1f} | {r['min_ms']:.1f} | {r['sref_rmse']:.3f} | "
                  f"{r['sref_p99']:.3f} | {r['soft_rmse']:.3f} |")
        print()
        print("| Pareto front vs reference_soft | median ms | min ms | soft RMSE | s_ref RMSE |")
        print("|---|---|---|---|---|")
        for r in front(rows, "soft_rmse"):
            print(f"| {r['config']} | {r['time_ms']:.1f} | {r['min_ms']:.1f} | {r['soft_rmse']:.3f} | "
                  f"{r['sref_rmse']:.3f} |")
        print()
        best = OrderedDict()
        for r in rows:
            if r["method"] in ("sm", "pcf"):
                continue
            b = best.get(r["method"])
            if b is None or r["sref_rmse"] < b["sref_rmse"]:
                best[r["method"]] = r
        print("| method: lowest s_ref RMSE | median ms | s_ref RMSE | p99 | soft RMSE | MiB |")
        print("|---|---|---|---|---|---|")
        for m, r in sorted(best.items(), key=lambda kv: kv[1]["sref_rmse"]):
            print(f"| {r['config']} | {r['time_ms']:.1f} | {r['sref_rmse']:.3f} | {r['sref_p99']:.3f} | "
                  f"{r['soft_rmse']:.3f} | {r['device_bytes'] / 1048576:.1f} |")
        print()


if __name__ == "__main__":
    main(sys.argv[1:])
