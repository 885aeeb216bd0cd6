#!/bin/sh
# A one-shot run's device time against the same frame in the bench (docs/batch.md, "What a frame
# costs alone"): the backyard scene at a 2048x2048 map with 1920x1080 camera receivers, esm with
# its defaults and R = 3, which is sf_bench's esm_classify/frame/size:2048/scene:2/lookup:0. Each
# round runs `shadowfilter filter` once (a new process) and the bench's frame once, interleaved
# (the machine's load changes between rounds); printed: the medians of each stage's device ms
# from the CLI's --json (resident, the fills that fault in the new buffers, apart), of the sum of
# the stages, of the bench's frame, and the ratio of the two sums.
# Usage: scripts/one_shot.sh [BUILD_DIR] [ROUNDS] [JSON]   (default build, 5; sf_bench from make bench)
# JSON: also write the medians as an sf_bench-shaped entry `one_shot/filter/size:2048` (real_time
# the one-shot stages, counters bench_frame_ms, over_bench, wall_run_ms, resident_ms; the context
# of the bench's last run), which scripts/performance_tables.py reads beside sf_bench's own JSON
# (make performance).
set -eu
B=${1:-build}
ROUNDS=${2:-5}
S=$B/cost_scene/backyard
if [ ! -x "$B/sf_bench" ]; then
  echo "one_shot: $B/sf_bench is missing (make bench builds it)" >&2
  exit 2
fi
if [ ! -f "$S/receivers.exr" ] || [ "$B/shadowfilter" -nt "$S/receivers.exr" ]; then
  rm -rf "$S"
  "$B/shadowfilter" scene backyard -o "$S" --size 2048 --receivers 1920x1080 --samples 1 --seed 1 -q
fi
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
r=0
while [ $r -lt "$ROUNDS" ]; do
  "$B/shadowfilter" filter --method esm --blur-radius 3 --shadow-map "$S/shadowmap.exr" \
    --receivers "$S/receivers.exr" -o "$OUT/v.exr" --json >>"$OUT/cli.jsonl"
  SF_BENCH_REPETITIONS=1 "$B/sf_bench" --benchmark_filter='^esm_classify/frame/size:2048/scene:2/lookup:0/' \
    --benchmark_out="$OUT/bench_$r.json" --benchmark_out_format=json >/dev/null 2>&1
  r=$((r + 1))
done
python3 - "$OUT" "$ROUNDS" "${3:-}" <<'PY'
import glob, json, os, statistics, sys
out, rounds, json_out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
lines = [json.loads(line) for line in open(f"{out}/cli.jsonl")]
runs = [j["device_ms"] for j in lines]
stages = [k for k in runs[0] if k not in ("upload", "download", "resident")]
med = lambda xs: statistics.median(xs)
for k in stages + ["resident"]:
    print(f"one-shot {k:12s} {med([r.get(k, 0.0) for r in runs]):8.2f} ms")
one = med([sum(r[k] for k in stages) for r in runs])
bench_files = sorted(glob.glob(f"{out}/bench_*.json"), key=lambda f: int(f.rsplit("_", 1)[1].split(".")[0]))
bench = med([b["real_time"] for f in bench_files for b in json.load(open(f))["benchmarks"]
             if b.get("run_type") == "iteration"])
wall = med([j["wall_ms"]["run"] for j in lines])
print(f"one-shot stages      {one:8.2f} ms (median of {rounds} runs)")
print(f"one-shot wall run    {wall:8.2f} ms (allocation, builds, enqueue, frame, readback)")
print(f"bench frame          {bench:8.2f} ms (esm_classify/frame, the classified frame's device time)")
print(f"one-shot / bench     {one / bench:8.2f}x")
if json_out:
    entry = {"name": "one_shot/filter/size:2048", "run_name": "one_shot/filter/size:2048", "run_type": "iteration",
             "real_time": one, "time_unit": "ms", "bench_frame_ms": bench, "over_bench": one / bench,
             "wall_run_ms": wall, "resident_ms": med([r.get("resident", 0.0) for r in runs]), "rounds": rounds}
    context = json.load(open(bench_files[-1])).get("context", {})
    with open(json_out + ".part", "w") as f:
        json.dump({"context": context, "benchmarks": [entry]}, f, indent=1)
    os.replace(json_out + ".part", json_out)
PY
