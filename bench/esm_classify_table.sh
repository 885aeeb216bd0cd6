#!/bin/sh
# Annen 2008 table 7.2 on bundled scenes: flagged fraction of ESM failure classification (zmax and
# threshold) for no convolution and 3x3, 5x5, 7x7 Gaussian prefilters (--blur-radius 0..3), with
# the trilinear (mips) lookup driven by the receivers' footprints, c = 80.
# Usage: [SCENES="spheres backyard fence"] bench/esm_classify_table.sh [build dir] [extra filter options]
# Prints per scene and mode: R=r <% of all receivers> (<% of receivers inside the map>).
set -eu
BUILD=${1:-build}
shift 2>/dev/null || true
SCENES=${SCENES:-spheres backyard fence}
CLI="$BUILD/shadowfilter"
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
for scene in $SCENES; do
  for mode in zmax threshold; do
    line="$scene $mode:"
    for r in 0 1 2 3; do
      pct=$("$CLI" filter --shadow-map "data/$scene/shadowmap.exr" --receivers "data/$scene/receivers.exr" \
        -o "$OUT/v.exr" --method esm --lookup mips --blur-radius "$r" --esm-classify "$mode" "$@" |
        sed -n 's/.*flagged \([0-9.]*\)% of receivers, \([0-9.]*\)% of.*/\1 (\2)/p')
      line="$line  R=$r $pct"
    done
    echo "$line"
  done
done
