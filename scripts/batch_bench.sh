#!/bin/sh
# Batch throughput (docs/batch.md): `filter --frames` against a shell loop of single runs over
# the same frames, in the same run, interleaved round by round (the machine's load changes
# between rounds, not within one), with the main job's options (esm, Gaussian R = 3).
#  1. 100 frames of 512x512 maps with 640x480 receivers, copies of the five bundled scenes (every
#     frame its own files): once with each frame's own receiver file, once with one receiver
#     file for all (one camera, the batch decodes it once).
#  2. N2 frames of a 2048x2048 map with 1920x1080 receivers (spheres, one camera): the batch's
#     wall time per frame against the larger of its device time and its EXR decode time per frame.
# Usage: scripts/batch_bench.sh [BUILD_DIR] [ROUNDS] [N2]   (default build, 2, 20)
set -eu
B=${1:-build}
ROUNDS=${2:-2}
N2=${3:-20}
SF=$(cd "$B" && pwd)/shadowfilter
export SHADOWFILTER_CACHE_DIR=$B/test_cache
OPTS="--method esm --blur-radius 3"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
mkdir -p "$W/in" "$W/out"

i=0
while [ $i -lt 100 ]; do
  case $((i % 5)) in 0) s=spheres ;; 1) s=backyard ;; 2) s=contact ;; 3) s=fence ;; *) s=thin ;; esac
  n=$(printf %03d $i)
  cp "data/$s/shadowmap.exr" "$W/in/map_$n.exr"
  cp "data/$s/receivers.exr" "$W/in/rx_$n.exr"
  echo "in/map_$n.exr in/rx_$n.exr out/f_$n.exr" >>"$W/own.txt"
  echo "in/map_$n.exr in/rx_000.exr out/f_$n.exr" >>"$W/shared.txt"
  i=$((i + 1))
done

now() { date +%s.%N; }
# loop LIST: one process per line; prints its wall seconds
loop() {
  t0=$(now)
  while read -r m r o; do
    # shellcheck disable=SC2086  # OPTS is a word list
    (cd "$W" && "$SF" filter --shadow-map "$m" --receivers "$r" -o "$o" -q $OPTS)
  done <"$1"
  awk -v a="$(now)" -v b="$t0" 'BEGIN { printf "%.3f\n", a - b }'
}
# batch LIST: one process; prints its wall seconds and keeps its summary line
batch() {
  t0=$(now)
  # shellcheck disable=SC2086
  "$SF" filter --frames "$1" $OPTS >"$1.summary"
  awk -v a="$(now)" -v b="$t0" 'BEGIN { printf "%.3f\n", a - b }'
}

echo "round,receivers,loop_s,batch_s" >"$W/rounds.csv"
r=0
while [ $r -lt "$ROUNDS" ]; do
  a=$(loop "$W/own.txt")
  b=$(batch "$W/own.txt")
  c=$(batch "$W/shared.txt")
  d=$(loop "$W/shared.txt")
  echo "$r,own,$a,$b" >>"$W/rounds.csv"
  echo "$r,shared,$d,$c" >>"$W/rounds.csv"
  r=$((r + 1))
done
# The 100 batch outputs equal the loop's, byte for byte (the loop ran last).
mkdir -p "$W/check" && cp "$W"/out/*.exr "$W/check/"
batch "$W/shared.txt" >/dev/null
for f in "$W"/out/*.exr; do cmp -s "$f" "$W/check/$(basename "$f")" || { echo "differs: $f"; exit 1; }; done

python3 - "$W/rounds.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("| round | receivers | shell loop, s (frames/s) | batch, s (frames/s) | batch / loop throughput |")
print("|---|---|---|---|---|")
for r in rows:
    lo, ba = float(r["loop_s"]), float(r["batch_s"])
    print(f"| {r['round']} | {'each frame its own' if r['receivers'] == 'own' else 'one for all frames'} | {lo:.1f} ({100/lo:.1f}) | {ba:.2f} ({100/ba:.1f}) | {lo/ba:.1f}x |")
PY

# 2. 2048x2048 maps, 1920x1080 receivers.
S=$B/cost_scene/spheres
if [ ! -f "$S/receivers.exr" ] || [ "$B/shadowfilter" -nt "$S/receivers.exr" ]; then
  rm -rf "$S"
  "$SF" scene spheres -o "$S" --size 2048 --receivers 1920x1080 --samples 4 --seed 1 -q
fi
cp "$S/receivers.exr" "$W/in/rx_big.exr"
i=0
: >"$W/big.txt"
while [ $i -lt "$N2" ]; do
  n=$(printf %03d $i)
  cp "$S/shadowmap.exr" "$W/in/big_$n.exr"
  echo "in/big_$n.exr in/rx_big.exr out/big_$n.exr" >>"$W/big.txt"
  i=$((i + 1))
done
head -n 3 "$W/big.txt" >"$W/big3.txt"
echo
# The map's decode alone (sf_measure Decode.*: the median of 5 on one thread, nothing else running).
dec=$(SF_DECODE_MAP="$W/in/big_000.exr" "$B/tests/sf_measure" --gtest_filter='Decode.*' | sed -n 's/^decode_ms //p')
echo "| 2048x2048 map, 1920x1080 receivers | wall ms per frame | device ms per frame | decode ms per frame, alone | wall / max(device, decode) | decode, encode ms per frame in the batch (threads) |"
echo "|---|---|---|---|---|---|"
r=0
while [ $r -lt "$ROUNDS" ]; do
  l=$(loop "$W/big3.txt")
  t=$(batch "$W/big.txt")
  python3 - "$W/big.txt.summary" "$t" "$N2" "$l" "$dec" <<'PY'
import re, sys
line = open(sys.argv[1]).read()
wall, n, loop, alone = float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
dev = re.search(r"device ms per frame: ([^|]*)\|", line).group(1)
device = sum(float(v) for v in re.findall(r"[a-z]+ ([0-9.]+)", dev))
stage = dict(re.findall(r"(decode|run|encode) ([0-9.]+)", line.split("stage s in all:")[1]))
decode, encode = float(stage["decode"]) * 1e3 / n, float(stage["encode"]) * 1e3 / n
w = wall * 1e3 / n
print(f"| batch of {n} (shell loop: {loop * 1e3 / 3:.0f} ms per frame) | {w:.0f} | {device:.0f} | {alone:.0f} | {w / max(device, alone):.2f} | {decode:.0f}, {encode:.0f} |")
PY
  r=$((r + 1))
done
