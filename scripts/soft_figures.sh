#!/bin/sh
# Figures of docs/soft.md: soft-shadow methods against the ray-traced reference_soft on every
# built-in scene at two light sizes (the scene's default and twice it; plus spheres under a
# perspective light), cost against light size, and frame time against the light count.
# Usage: scripts/soft_figures.sh [BUILD_DIR]   (default build-soft; needs shadowfilter and sf_tests)
set -eu
B=${1:-build-soft}
OUT=$B/soft_scenes
mkdir -p "$OUT"
dirs=""
for spec in spheres:0.2 fence:0.1 backyard:0.15 contact:0.15 thin:0.1 terrain:0.1; do
  s=${spec%%:*}; L=${spec#*:}
  L2=$(echo "$L * 2" | bc -l)
  for l in $L $L2; do
    d=$OUT/$s-L$l
    [ -f "$d/reference_soft.exr" ] || "$B/shadowfilter" scene "$s" -o "$d" --size 512 --receivers 640x480 --samples 64 --light-size "$l" -q
    dirs="$dirs $d"
  done
done
d=$OUT/spheres-persp-L0.2
[ -f "$d/reference_soft.exr" ] || "$B/shadowfilter" scene spheres -o "$d" --size 512 --receivers 640x480 --samples 64 --light perspective -q
dirs="$dirs $d"
export SHADOWFILTER_CACHE_DIR=$B/test_cache
SF_SOFT_SCENES="$dirs" "$B/tests/sf_tests" --gtest_also_run_disabled_tests \
  --gtest_filter='SoftFigures.DISABLED_QualityAndTime' | grep '^|'
SF_SOFT_SCENES="$OUT/spheres-L0.2" "$B/tests/sf_tests" --gtest_also_run_disabled_tests \
  --gtest_filter='SoftFigures.DISABLED_CostAgainstLightSize:SoftFigures.DISABLED_LightCount' | grep '^|'
