#!/usr/bin/env python3
"""Markdown tables for docs/results.md and the README from `shadowfilter evaluate` results.csv files.

usage: make_tables.py results.csv [more.csv ...]          per-scene tables
       make_tables.py --pick BUDGETS results.csv [...]    the README's picking table

Per scene: the Pareto front of (median ms, RMSE against reference_soft) with the other
references beside it, the front against reference_hard, and each method's configuration of
lowest soft RMSE with its fidelity (self: RMSE against s_ref of its own weights).

--pick BUDGETS (comma-separated ms, e.g. 5,10,20): for each budget, the configuration with the
lowest mean soft RMSE over the scenes among those whose median time over the scenes stays within
the budget (one configuration for every scene, as a renderer would ship it; the median, since
the scenes share their sizes and one disturbed measurement should not move a pick); plus the
cheapest (lowest median time) and the most accurate with no budget. Only configurations measured
on every scene count.

Files written before the target reference called the self columns sref_*; both are read.
"""
import csv
import statistics
import sys
from collections import OrderedDict


def front(rows, key):
    """The non-dominated rows of (time_ms, key), fastest first; equal points are both kept."""
    rows = sorted((r for r in rows if r[key] == r[key]), key=lambda r: (r["time_ms"], r[key]))
    out = []
    for r in rows:
        if not out or r[key] < out[-1][key] or (r[key] == out[-1][key] and r["time_ms"] == out[-1]["time_ms"]):
            out.append(r)
    return out


def num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")


def read(paths):
    scenes = OrderedDict()
    for p in paths:
        with open(p) as f:
            for r in csv.DictReader(f):
                for ref in ("self", "target", "soft", "hard"):
                    for m in ("rmse", "p99"):
                        old = "sref_" + m if ref == "self" else None
                        r[f"{ref}_{m}"] = num(r.get(f"{ref}_{m}", r.get(old) if old else None))
                for k in ("time_ms", "min_ms", "device_bytes"):
                    r[k] = num(r[k])
                scenes.setdefault(r["scene"], []).append(r)
    return scenes


def f3(v):
    return "-" if v != v else f"{v:.3f}"


def tables(scenes):
    for scene, rows in scenes.items():
        target = next((r.get("target_filter") for r in rows if r.get("target_filter")), "")
        print(f"### {scene} ({len(rows)} configurations)\n")
        t = f" | target ({target}) RMSE" if target else ""
        print(f"| Pareto front vs reference_soft | median ms | soft RMSE | hard RMSE{t} | self RMSE (fidelity) |")
        print("|---|---|---|---|" + ("---|" if target else "") + "---|")
        for r in front(rows, "soft_rmse"):
            tt = f" | {f3(r['target_rmse'])}" if target else ""
            print(f"| {r['config']} | {r['time_ms']:.1f} | {f3(r['soft_rmse'])} | {f3(r['hard_rmse'])}{tt} | "
                  f"{f3(r['self_rmse'])} |")
        print()
        print("| Pareto front vs reference_hard | median ms | hard RMSE | soft RMSE |")
        print("|---|---|---|---|")
        for r in front(rows, "hard_rmse"):
            print(f"| {r['config']} | {r['time_ms']:.1f} | {f3(r['hard_rmse'])} | {f3(r['soft_rmse'])} |")
        print()
        best = OrderedDict()
        for r in rows:
            b = best.get(r["method"])
            if b is None or r["soft_rmse"] < b["soft_rmse"]:
                best[r["method"]] = r
        print("| method: lowest soft RMSE | median ms | soft RMSE | soft p99 | self RMSE (fidelity) | MiB |")
        print("|---|---|---|---|---|---|")
        for m, r in sorted(best.items(), key=lambda kv: kv[1]["soft_rmse"]):
            print(f"| {r['config']} | {r['time_ms']:.1f} | {f3(r['soft_rmse'])} | {f3(r['soft_p99'])} | "
                  f"{f3(r['self_rmse'])} | {r['device_bytes'] / 1048576:.1f} |")
        print()


def pick(scenes, budgets):
    configs = OrderedDict()
    for rows in scenes.values():
        for r in rows:
            configs.setdefault(r["config"], []).append(r)
    n = len(scenes)
    everywhere = []
    for label, rs in configs.items():
        if len(rs) != n or any(r["soft_rmse"] != r["soft_rmse"] for r in rs):
            continue
        everywhere.append({
            "config": label, "method": rs[0]["method"],
            "mean": sum(r["soft_rmse"] for r in rs) / n,
            "lo": min(r["soft_rmse"] for r in rs), "hi": max(r["soft_rmse"] for r in rs),
            "tmin": min(r["time_ms"] for r in rs), "tmax": max(r["time_ms"] for r in rs),
            "tmed": statistics.median(r["time_ms"] for r in rs)})
    rows = [("cheapest", min(everywhere, key=lambda c: (c["tmed"], c["mean"])))]
    for b in budgets:
        within = [c for c in everywhere if c["tmed"] <= b]
        if within:
            rows.append((f"<= {b:g} ms", min(within, key=lambda c: (c["mean"], c["tmed"]))))
    rows.append(("best quality", min(everywhere, key=lambda c: (c["mean"], c["tmed"]))))
    print(f"| budget per frame | pick | soft RMSE, mean over {n} scenes (range) | ms, median over scenes (range) |")
    print("|---|---|---|---|")
    seen = set()
    for name, c in rows:
        same = " (as above)" if c["config"] in seen else ""
        seen.add(c["config"])
        print(f"| {name} | {c['config']}{same} | {c['mean']:.3f} ({c['lo']:.3f}-{c['hi']:.3f}) | "
              f"{c['tmed']:.1f} ({c['tmin']:.1f}-{c['tmax']:.1f}) |")


def main(argv):
    if argv[:1] == ["--pick"]:
        pick(read(argv[2:]), [float(b) for b in argv[1].split(",")])
    else:
        tables(read(argv))


if __name__ == "__main__":
    main(sys.argv[1:])
