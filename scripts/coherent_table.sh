#!/usr/bin/env bash
# Ritschel 2007's Table 1 on Debian's scanned meshes (make meshes): `coherent build` at M = 128 for
# each mesh, view grid and ordering; prints a Markdown table with the seed's figures beside ours.
# Usage: scripts/coherent_table.sh [BUILD] [VIEWS...]   (default: build 32x32 128x128)
# MESHES (default "bunny00 ChineseDragon-10kv armadillo"), ORDERINGS (default "scanline hilbert").
set -euo pipefail
build="${1:-build}"
shift || true
views=("$@")
[ ${#views[@]} -gt 0 ] || views=(32x32 128x128)
meshes=(${MESHES:-bunny00 ChineseDragon-10kv armadillo})
orderings=(${ORDERINGS:-scanline hilbert})
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The seed's Table 1 (distant lat-long, M = 128): compressed MB and ratio, bunny and dragon.
seed() {
  case "$1/$2" in
    bunny00/32x32) echo "3.9 MB, 8.2:1" ;;
    bunny00/128x128) echo "19.9 MB, 25.4:1" ;;
    ChineseDragon-10kv/32x32) echo "8.3 MB, 3.9:1 (Dragon); 5.4 MB, 5.0:1 (XYZ Dragon)" ;;
    ChineseDragon-10kv/128x128) echo "50.0 MB, 10.2:1 (Dragon); 44.2 MB, 11.5:1 (XYZ Dragon)" ;;
    *) echo "-" ;;
  esac
}
echo "| mesh | triangles | views | ordering | uncompressed | compressed | ratio | segments/texel | render s | compress s | seed (same views) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for m in "${meshes[@]}"; do
  mesh="$build/meshes/$m.off"
  [ -f "$mesh" ] || { echo "coherent_table: $mesh missing (make meshes)" >&2; exit 2; }
  tris=$(sed -n 2p "$mesh" | awk '{print $2}')
  for v in "${views[@]}"; do
    for o in "${orderings[@]}"; do
      line=$("$build/shadowfilter" coherent build "$mesh" -o "$work/$m.csm" --views "$v" --ordering "$o" 2>/dev/null | tail -n 1)
      unc=$(sed -E 's/.*uncompressed ([0-9.]+ MiB).*/\1/' <<<"$line")
      comp=$(sed -E 's/.*, compressed ([0-9.]+ MiB).*/\1/' <<<"$line")
      ratio=$(sed -E 's/.*ratio ([0-9.]+:1).*/\1/' <<<"$line")
      per=$(sed -E 's/.*\(([0-9.]+) per texel\).*/\1/' <<<"$line")
      rs=$(sed -E 's/.*render ([0-9.]+) s.*/\1/' <<<"$line")
      cs=$(sed -E 's/.*compress ([0-9.]+) s.*/\1/' <<<"$line")
      echo "| $m | $tris | $v | $o | $unc | $comp | $ratio | $per | $rs | $cs | $(seed "$m" "$v") |"
      rm -f "$work/$m.csm"
    done
  done
done
