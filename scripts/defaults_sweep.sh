#!/bin/sh
# Issue 14's defaults sweep (docs/results.md "Defaults sweep"): every method over its table of
# candidate settings (tests/measure/measure_defaults_sweep.cpp) on every built-in scene and one
# scanned mesh, each at a 512 and a 2048 map; acne / leak against reference_hard and RMSE against
# the ray-traced references per row, then the selection rule's tables
# (tests/measure/measure_defaults_tables.cpp).
# Usage: scripts/defaults_sweep.sh [BUILD_DIR]   (default build; needs shadowfilter and sf_measure)
#   SWEEP_SIZES="512 2048"  map sizes (receivers 320x240 at 512, 640x480 above)
#   SWEEP_MESH=bunny00      the scanned mesh (make meshes extracts it into BUILD_DIR/meshes)
#   SWEEP_METHODS="..."     only these methods (default: all)
#   SWEEP_NORMAL_OFFSETS="0 0.5 1"  every candidate at each normal offset (texels; default "0 0.5")
# Writes BUILD_DIR/defaults_sweep.csv (every row) and BUILD_DIR/defaults_sweep.md (the tables,
# also printed). Scenes go to BUILD_DIR/sweep_scenes/SIZE/NAME and are regenerated when missing,
# older than the binary or made with other arguments. The tables alone, from existing rows:
#   SF_SWEEP_CSV="a.csv b.csv" BUILD_DIR/tests/sf_measure --gtest_filter='DefaultsSweep.Tables'
set -eu
B=${1:-build}
SIZES=${SWEEP_SIZES:-512 2048}
MESH=${SWEEP_MESH:-bunny00}
OUT=$B/sweep_scenes
CSV=$B/defaults_sweep.csv
MD=$B/defaults_sweep.md

if [ ! -f "$B/meshes/$MESH.off" ]; then
  make -s meshes BUILD="$B" MESHES="$MESH" >/dev/null
fi

t0=$(date +%s)
dirs=""
for size in $SIZES; do
  # 320x240 camera receivers at 512 (issue 14's table); 640x480 at larger maps, so that a
  # receiver still covers several texels (the 2048 generation takes a few seconds per scene).
  if [ "$size" -le 512 ]; then rx=320x240; else rx=640x480; fi
  for s in spheres fence backyard contact thin terrain "$B/meshes/$MESH.off"; do
    d=$OUT/$size/$(basename "$s" .off)
    args="$s --size $size --receivers $rx --samples 64 --seed 1"
    if [ ! -f "$d/reference_soft.exr" ] || [ "$B/shadowfilter" -nt "$d/reference_soft.exr" ] ||
       [ "$(cat "$d.args" 2>/dev/null)" != "$args" ]; then
      rm -rf "$d"
      mkdir -p "$(dirname "$d")"
      # shellcheck disable=SC2086  # args is a word list
      "$B/shadowfilter" scene $args -o "$d" -q
      echo "$args" > "$d.args"
    fi
    dirs="$dirs $d"
  done
done
t1=$(date +%s)

export SHADOWFILTER_CACHE_DIR=$B/test_cache
export SF_SWEEP_SCENES="$dirs" SF_SWEEP_OUT="$CSV" SF_SWEEP_RADIUS=2 SF_SWEEP_METHODS="${SWEEP_METHODS:-}" \
  SF_SWEEP_NORMAL_OFFSETS="${SWEEP_NORMAL_OFFSETS:-}"
# The candidates that share a prefiltered basis against filter() on the first scene, then the
# rows of every scene; the tables in a second run (gtest's order across files is the link order).
"$B/tests/sf_measure" --gtest_filter='DefaultsSweep.SharedBasisIsExact:DefaultsSweep.Run' >"$MD.log" ||
  { cat "$MD.log"; exit 1; }
t2=$(date +%s)
"$B/tests/sf_measure" --gtest_filter='DefaultsSweep.Tables' >"$MD.log" || { cat "$MD.log"; exit 1; }
# The tables without gtest's lines.
grep -v -e '^\[' -e '^Note: ' -e '^Running main' "$MD.log" >"$MD"
cat "$MD"
echo
echo "defaults sweep: scenes $((t1 - t0)) s, sweep $((t2 - t1)) s; rows in $CSV, tables in $MD"
