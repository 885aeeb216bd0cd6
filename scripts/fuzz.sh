#!/usr/bin/env bash
# Runs every libFuzzer harness built in BUILD (make fuzz, docs/development.md "Fuzzing"): each one
# from a scratch copy of its committed corpus and regressions (tests/fuzz/corpus/<harness>,
# tests/fuzz/regressions/<harness>; the committed files are never changed), for SECONDS, PARALLEL
# harnesses at a time. Prints per harness its executions per second and in all, and fails when
# any harness crashed, leaked, timed out or ran out of memory, naming the input that did it (left
# in BUILD/fuzz-work/<harness>/).
# Usage: scripts/fuzz.sh BUILD SECONDS PARALLEL
set -uo pipefail
cd "$(dirname "$0")/.."
build=$1 seconds=$2 parallel=$3
work="$build/fuzz-work"
harnesses=(image cascade csm frame_list light_list mesh view_file)
rm -rf "$work" && mkdir -p "$work"

run_one() {
  local h=$1 d="$work/$1"
  mkdir -p "$d/corpus"
  cp tests/fuzz/corpus/"$h"/* "$d/corpus/"
  if [ -d "tests/fuzz/regressions/$h" ]; then cp tests/fuzz/regressions/"$h"/* "$d/corpus/"; fi
  # OpenImageIO 2.4's PNG reader leaks a string on its error path (scripts/sanitize/lsan.supp); its
  # suppression needs whole allocation stacks, which cost the image harnesses about 20% of their
  # speed, so only they unwind slowly.
  local asan=""
  case $h in image | cascade) asan="fast_unwind_on_malloc=0" ;; esac
  # -timeout: one input may take 20 s (a hang is a bug); -rss_limit_mb: libFuzzer's default, named.
  ASAN_OPTIONS="$asan" LSAN_OPTIONS="suppressions=$PWD/scripts/sanitize/lsan.supp:print_suppressions=0" \
    "$build/tests/fuzz/sf_fuzz_$h" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$d/" "$d/corpus" > "$d/log" 2>&1
  echo $? > "$d/rc"
}
export -f run_one
export work build seconds
printf '%s\n' "${harnesses[@]}" | xargs -P "$parallel" -I{} bash -c 'run_one {}'

failed=0
printf 'fuzz: %-11s %9s %12s %8s %s\n' harness exec/s executions corpus result
for h in "${harnesses[@]}"; do
  d="$work/$h"
  rc=$(cat "$d/rc" 2>/dev/null || echo 1)
  stat() { sed -n "s/^stat::$1: *//p" "$d/log" | tail -1; }
  corpus=$(ls "$d/corpus" | wc -l)
  found=$(ls "$d" | grep -E '^(crash|leak|timeout|oom|slow-unit)-' || true)
  result=ok
  if [ "$rc" != 0 ] || [ -n "$found" ]; then
    result="FAILED (exit $rc)"
    failed=1
  fi
  printf 'fuzz: %-11s %9s %12s %8s %s\n' "$h" "$(stat average_exec_per_sec)" "$(stat number_of_executed_units)" \
    "$corpus" "$result"
  for f in $found; do echo "fuzz: $h: input that failed: $d/$f"; done
  if [ "$result" != ok ]; then grep -m1 -A12 -E 'ERROR: |==[0-9]+==|runtime error|terminate called' "$d/log" | sed 's/^/fuzz:   /'; fi
done
[ $failed = 0 ] && echo "fuzz: every harness ran ${seconds} s without a failure" || echo "fuzz: failures above (logs in $work/<harness>/log)"
exit $failed
