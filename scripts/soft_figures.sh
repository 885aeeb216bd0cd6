#!/bin/sh
# Figures of docs/soft.md: soft-shadow methods against the ray-traced reference_soft on every
# built-in scene at two light sizes (the scene's default and twice it; plus spheres under a
# perspective light), rectangular lights against squares of their area, ssmm's kernel size n,
# cssm's basis storage, cost against light size, and frame time against the light count; then the cssm parameter table that chose the defaults
# (bundled scenes, data/*).
# Usage: scripts/soft_figures.sh [BUILD_DIR]   (default build-soft; needs shadowfilter and sf_measure)
#        scripts/soft_figures.sh --sweep       (prints the sweep's SF_SOFT_SWEEP list only)
set -eu
sweep() {
  # M,lookup,offset,scale,z_offset,width_scale,contact,A,B,normalise (negative = the default)
  S=""
  for M in 4 16; do
    h=$(echo "0.5/$M" | bc -l)
    S="$S;$M,m,$h,1,$h,1,0,0,0,0"       # previous defaults
    S="$S;$M,m,$h,1,$h,1,1,0,0,0"       # + contact path
    S="$S;$M,m,-1,-1,$h,-1,1,0,-1,0"    # offset 0.1/M, scale 3, width x scale lit
    S="$S;$M,m,-1,-1,-1,-1,1,0,-1,0"    # + z_offset where a lit texel gives 1
    S="$S;$M,m,-1,-1,-1,-1,1,30,-1,0"   # + sharpening 30, 10 M = the defaults
    S="$S;$M,m,-1,-1,-1,-1,0,30,-1,0"   # the defaults without the contact path
    # (offset 0.06/M and scale 2 leave lit receivers below 1: validate() refuses them with sharpening)
    for o in 0.15 0.2; do S="$S;$M,m,$(echo "$o/$M" | bc -l),-1,-1,-1,1,30,-1,0"; done
    S="$S;$M,m,-1,4,-1,-1,1,30,-1,0"    # scale 4
    S="$S;$M,m,-1,-1,-1,1,1,30,-1,0"    # width x 1
    for A in 10 60; do S="$S;$M,m,-1,-1,-1,-1,1,$A,-1,0"; done
    for B in 5 20; do S="$S;$M,m,-1,-1,-1,-1,1,30,$((B * M)),0"; done
    S="$S;$M,m,-1,2,-1,-1,1,30,-1,1"    # normalised (s_f / lit), scale 2
    S="$S;$M,s,-1,-1,-1,-1,1,30,-1,0"   # the defaults with SAT
  done
  echo "${S#;}"
}
if [ "${1:-}" = "--sweep" ]; then sweep; exit 0; fi
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
# Rectangular lights of the square's area: W x H = L x L, 2L x L/2, L/2 x 2L and 4L x L/4.
rects=""
for spec in spheres:0.2 fence:0.1 backyard:0.15 contact:0.15 thin:0.1; do
  s=${spec%%:*}; L=${spec#*:}
  for wh in "1 1" "2 0.5" "0.5 2" "4 0.25"; do
    set -- $wh
    W=$(printf '%g' "$(echo "$L * $1" | bc -l)"); H=$(printf '%g' "$(echo "$L * $2" | bc -l)")
    d=$OUT/$s-R${W}x$H
    [ -f "$d/reference_soft.exr" ] || "$B/shadowfilter" scene "$s" -o "$d" --size 512 --receivers 640x480 --samples 64 --light-size "$W,$H" -q
    rects="$rects $d"
  done
done
export SHADOWFILTER_CACHE_DIR=$B/test_cache
SF_SOFT_SCENES="$rects" "$B/tests/sf_measure" --gtest_filter='SoftFigures.RectangularLights' | grep '^|'
SF_SOFT_SCENES="$dirs" "$B/tests/sf_measure" \
  --gtest_filter='SoftFigures.QualityAndTime' | grep '^|'
SF_SOFT_SCENES="$dirs" "$B/tests/sf_measure" \
  --gtest_filter='SoftFigures.SsmmSweep:SoftFigures.CssmStorage:SoftFigures.CssmStorageMix' | grep '^|'
SF_SOFT_SCENES="$OUT/spheres-L0.2" "$B/tests/sf_measure" \
  --gtest_filter='SoftFigures.CostAgainstLightSize:SoftFigures.LightCount' | grep '^|'
here=$(cd "$(dirname "$0")/.." && pwd)
SF_SOFT_SCENES="$(ls -d "$here"/data/*)" SF_SOFT_SWEEP="$(sweep)" "$B/tests/sf_measure" \
  --gtest_filter='SoftFigures.CssmSweep' | grep '^|'
