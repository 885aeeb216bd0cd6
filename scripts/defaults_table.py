#!/usr/bin/env python3
"""Issue 14's before/after table (docs/results.md, "Acne and leak with the measured defaults"):
the default rows of two defaults-sweep CSVs (scripts/defaults_sweep.sh writes BUILD/defaults_sweep.csv;
docs/results/defaults_before.csv holds the rows of the defaults before the sweep chose them).
Usage: scripts/defaults_table.py BEFORE.csv AFTER.csv   (markdown on stdout, one table per map size)"""
import csv
import sys


def defaults(path):
    rows = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r["default"] == "1":
                rows[(r["scene"], r["method"])] = r
    return rows


def cell(r, key, scale=100.0, fmt="{:.2f}"):
    return fmt.format(scale * float(r[key])) if r else "-"


def main():
    before, after = defaults(sys.argv[1]), defaults(sys.argv[2])
    # Scenes and methods in the order of the first file (the sweep's: built-in scenes, the mesh;
    # the registry's methods, then the soft ones), those only in the second after them.
    scenes, methods = [], []
    for s, m in list(before) + list(after):
        if s not in scenes:
            scenes.append(s)
        if m not in methods:
            methods.append(m)
    for size in sorted({x.rsplit("-", 1)[1] for x in scenes}, key=int):
        print(f"\n{size} maps: acne % / leak % / soft RMSE, before -> after\n")
        print("| scene | method | acne % | leak % | soft RMSE |")
        print("|---|---|---|---|---|")
        for s in (x for x in scenes if x.endswith("-" + size)):
            for m in methods:
                b, a = before.get((s, m)), after.get((s, m))
                if not a:
                    continue
                print(f"| {s.rsplit('-', 1)[0]} | {m} | {cell(b, 'acne')} -> {cell(a, 'acne')} | "
                      f"{cell(b, 'leak')} -> {cell(a, 'leak')} | "
                      f"{cell(b, 'soft_rmse', 1.0, '{:.3f}')} -> {cell(a, 'soft_rmse', 1.0, '{:.3f}')} |")


if __name__ == "__main__":
    main()
