#!/bin/sh
# What receiver-plane depth and the ESM classification cost per frame (docs/results.md, "The cost
# of the defaults"): a 2048x2048 map of the spheres scene with 1920x1080 camera receivers, each
# configuration ROUNDS times, the configurations interleaved round by round (the machine's load
# changes between rounds, not within one), medians of the device times the CLI reports.
# Usage: scripts/plane_cost.sh [BUILD_DIR] [ROUNDS]   (default build, 5)
set -eu
B=${1:-build}
ROUNDS=${2:-5}
S=$B/cost_scene/spheres
if [ ! -f "$S/receivers.exr" ] || [ "$B/shadowfilter" -nt "$S/receivers.exr" ]; then
  rm -rf "$S"
  "$B/shadowfilter" scene spheres -o "$S" --size 2048 --receivers 1920x1080 --samples 4 --seed 1 -q
fi
export SHADOWFILTER_CACHE_DIR=$B/test_cache
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
# name|command arguments (after the inputs)
set -- \
  "sm, plane off|filter --method sm --receiver-plane off" \
  "sm, plane (default)|filter --method sm" \
  "pcf R=2, plane off|filter --method pcf --blur-radius 2 --receiver-plane off" \
  "pcf R=2, plane (default)|filter --method pcf --blur-radius 2" \
  "pcss, plane off|soft --method pcss --receiver-plane off" \
  "pcss, plane (default)|soft --method pcss" \
  "ssmm, plane off|soft --method ssmm --receiver-plane off" \
  "ssmm, plane (default)|soft --method ssmm" \
  "esm R=2, no classification|filter --method esm --blur-radius 2 --esm-classify none" \
  "esm R=2, zmax classification (default)|filter --method esm --blur-radius 2"
r=0
while [ $r -lt "$ROUNDS" ]; do
  i=0
  for c in "$@"; do
    args=${c#*|}
    # shellcheck disable=SC2086  # args is a word list
    "$B/shadowfilter" $args --shadow-map "$S/shadowmap.exr" --receivers "$S/receivers.exr" -o "$OUT/v.exr" \
      >>"$OUT/$i.log"
    i=$((i + 1))
  done
  r=$((r + 1))
done
echo "| configuration | reconstruct ms | zmax + classify ms | device ms per frame |"
echo "|---|---|---|---|"
i=0
for c in "$@"; do
  python3 - "$OUT/$i.log" "${c%%|*}" <<'PY'
import re, statistics, sys
rec, cls, tot = [], [], []
for line in open(sys.argv[1]):
    f = {k: float(v) for k, v in re.findall(r"(transform|blur|mips|sat|zmax|classify|reconstruct|pyramid) ([0-9.]+)", line)}
    rec.append(f.get("reconstruct", 0.0))
    cls.append(f.get("zmax", 0.0) + f.get("classify", 0.0))
    tot.append(sum(f.values()))
m = statistics.median
print(f"| {sys.argv[2]} | {m(rec):.2f} | {m(cls):.2f} | {m(tot):.2f} |")
PY
  i=$((i + 1))
done
