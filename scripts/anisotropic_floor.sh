#!/bin/sh
# #32's grazing-floor figures (docs/lookups.md "Anisotropic footprints"): every filtered method,
# mips and sat, isotropic (max_anisotropy 1) against 4, 8 and 16 probes, on the grazing scene (a
# lattice's shadows seen from 0.4 over the floor) and on terrain: RMSE against the ray-traced
# soft reference averaged over each pixel (scene --soft-reference pixel) and the reconstruction's device
# time.
# Usage: scripts/anisotropic_floor.sh [BUILD_DIR]   (default build; needs shadowfilter and sf_measure)
#   SF_SCENES="grazing"   only these built-in scenes (default: grazing terrain)
#   SF_ANISO_SIZE=2048   the map size (512: the near floor is magnified, a floor no lookup moves)
#   SF_ANISO_RADIUS=1 SF_ANISO_RUNS=7   the prefilter radius, timed runs per configuration
set -eu
B=${1:-build}
OUT=$B/aniso_scenes/${SF_ANISO_SIZE:-2048}
mkdir -p "$OUT"
dirs=""
for s in ${SF_SCENES:-grazing terrain}; do
  d=$OUT/$s
  # Regenerated when missing or older than the binary (receivers from before the Jacobian lack it).
  if [ ! -f "$d/reference_soft.exr" ] || [ "$B/shadowfilter" -nt "$d/reference_soft.exr" ]; then
    rm -rf "$d"
    "$B/shadowfilter" scene "$s" -o "$d" --size "${SF_ANISO_SIZE:-2048}" --receivers 640x360 --samples 64 \
      --soft-reference pixel -q
  fi
  dirs="$dirs $d"
done
export SHADOWFILTER_CACHE_DIR=$B/test_cache
SF_ANISO_SCENES="$dirs" "$B/tests/sf_measure" --gtest_filter='Anisotropic.*' | grep '^|'
