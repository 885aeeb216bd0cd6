#!/bin/sh
# Issue 14's "before" table (docs/results.md "Acne and leak with defaults"): every method with
# its defaults (--blur-radius 2 where it follows the prefilter; soft methods with the scene's
# light) on every built-in scene at 512x512 maps and 320x240 receivers, acne / leak against
# reference_hard and RMSE against the ray-traced references, facing-away receivers excluded.
# Usage: scripts/acne_leak.sh [BUILD_DIR]   (default build; needs shadowfilter and sf_measure)
#   SF_SCENES="terrain"  only these built-in scenes (default: all six)
set -eu
B=${1:-build}
OUT=$B/acne_scenes
mkdir -p "$OUT"
dirs=""
for s in ${SF_SCENES:-spheres fence backyard contact thin terrain}; do
  d=$OUT/$s
  # Regenerated when missing or older than the binary (receivers from before ndl lack it).
  if [ ! -f "$d/reference_soft.exr" ] || [ "$B/shadowfilter" -nt "$d/reference_soft.exr" ]; then
    rm -rf "$d"
    "$B/shadowfilter" scene "$s" -o "$d" --size 512 --receivers 320x240 --samples 64 -q
  fi
  dirs="$dirs $d"
done
export SHADOWFILTER_CACHE_DIR=$B/test_cache
SF_ACNE_SCENES="$dirs" "$B/tests/sf_measure" --gtest_filter='AcneLeak.Classes' | grep '^|'
echo
SF_ACNE_SCENES="$dirs" SF_ACNE_RADIUS=2 "$B/tests/sf_measure" --gtest_filter='AcneLeak.Defaults' | grep '^|'
