#!/usr/bin/env python3
"""Ratios OpenCV / ours of the esm_vs_opencv benchmarks (bench_opencv_esm.cpp), per stage and end
to end, from one or more sf_bench JSON files (--benchmark_out=FILE --benchmark_out_format=json).

    python3 bench/opencv_ratio.py run1.json [run2.json ...] [--stat median|min|mean]

Each file gives one ratio per (size, R, rx) and stage, from the chosen aggregate of each
benchmark's repetitions (default: median); with several files (interleaved runs) the table shows
the median over the files of each ratio and its range. Stages: transform, blur, mips (the
pyramid), lookup (lookup + reconstruction), the sum of the four, and e2e (wall time of the
whole frame: ours prefilter + reconstruct + wait, OpenCV its four stages in a row). Ours' stages
are OpenCL profiling event times, OpenCV's host wall times.
"""
import argparse
import json
import re
import statistics
import sys

STAGES = [("transform", "transform_ms"), ("blur", "blur_ms"), ("mips", "mips_ms"),
          ("lookup", "lookup_ms"), ("stage sum", "stage_sum_ms"), ("e2e", "e2e_ms")]
NAME = re.compile(r"^esm_vs_opencv/(ours|opencv)/size:(\d+)/R:(\d+)/rx:(\d+)")


def load(path, stat):
    """{(size, R, rx): {"ours": counters, "opencv": counters}} of one JSON file."""
    with open(path) as f:
        data = json.load(f)
    out, errors = {}, []
    for b in data["benchmarks"]:
        m = NAME.match(b.get("run_name", b["name"]))
        if not m:
            continue
        key = (int(m.group(2)), int(m.group(3)), int(m.group(4)))
        if b.get("error_occurred"):
            errors.append(f"{b['name']}: {b.get('error_message', '')}")
            continue
        # Aggregates (ReportAggregatesOnly) carry aggregate_name; a plain run counts as any.
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != stat:
            continue
        # e2e from the manual time of the aggregate (same as e2e_ms per repetition).
        counters = dict(b)
        counters["e2e_ms"] = b["real_time"] * {"ms": 1, "us": 1e-3, "ns": 1e-6, "s": 1e3}[b["time_unit"]]
        out.setdefault(key, {})[m.group(1)] = counters
    return out, errors


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("json", nargs="+")
    ap.add_argument("--stat", default="median", choices=["median", "min", "mean"])
    args = ap.parse_args()
    runs, all_errors = [], []
    for path in args.json:
        r, e = load(path, args.stat)
        runs.append(r)
        all_errors += [f"{path}: {x}" for x in e]
    keys = sorted({k for r in runs for k, v in r.items() if "ours" in v and "opencv" in v})
    if not keys:
        print("opencv_ratio: no pair of esm_vs_opencv/ours and /opencv results", file=sys.stderr)
        for e in all_errors:
            print("  " + e, file=sys.stderr)
        return 1
    print(f"OpenCV / ours, {args.stat} of each benchmark's repetitions, "
          f"{len(runs)} file(s){' (median over files [min .. max])' if len(runs) > 1 else ''}")
    head = "| size | R | rx | " + " | ".join(s for s, _ in STAGES) + " | ours e2e ms | OpenCV e2e ms | max abs diff: exact lookup, cv::remap |"
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for key in keys:
        cells = []
        for _, counter in STAGES:
            ratios = [r[key]["opencv"][counter] / r[key]["ours"][counter] for r in runs
                      if key in r and len(r[key]) == 2 and r[key]["ours"].get(counter, 0) > 0]
            if not ratios:
                cells.append("-")
            elif len(ratios) == 1:
                cells.append(f"{ratios[0]:.2f}")
            else:
                cells.append(f"{statistics.median(ratios):.2f} [{min(ratios):.2f} .. {max(ratios):.2f}]")
        pairs = [r[key] for r in runs if key in r and len(r[key]) == 2]
        ours_ms = statistics.median(p["ours"]["e2e_ms"] for p in pairs)
        cv_ms = statistics.median(p["opencv"]["e2e_ms"] for p in pairs)
        diff = max(p["opencv"].get("max_abs_diff", float("nan")) for p in pairs)
        exact = max(p["opencv"].get("max_abs_diff_exact", float("nan")) for p in pairs)
        size, radius, rx = key
        print(f"| {size} | {radius} | {rx} | " + " | ".join(cells) +
              f" | {ours_ms:.1f} | {cv_ms:.1f} | {exact:.2g}, {diff:.2g} |")
    for e in all_errors:
        print("error: " + e, file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
