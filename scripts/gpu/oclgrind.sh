#!/usr/bin/env bash
# Runs sf_tests_core on Oclgrind, an OpenCL device simulator that reports out-of-bounds accesses (of
# global, local and private arrays), uninitialised reads and data races: the CPU-side check for
# the kernel bugs PoCL hides and a GPU would not (docs/gpu.md). Slow (an interpreter): give it
# small tests, one suite at a time.
# Usage: scripts/gpu/oclgrind.sh 'GTEST_FILTER' [BUILD_DIR]   (BUILD_DIR default build-gpu)
# Env: SF_OCLGRIND_UNINIT=1 adds the uninitialised-value plugin (Oclgrind 21.10's crashes on the
#      SAT kernels and its reports are unconfirmed), SF_OCLGRIND_RACES=1 the race detector,
#      SF_OCLGRIND_SECONDS (600) the time limit.
# Oclgrind is unpacked from Debian's packages into .gpu/oclgrind, not installed: its ICD must not
# join /etc/OpenCL/vendors, where every other test run would take it as the default (GPU) device.
set -uo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
FILTER=${1:?usage: oclgrind.sh GTEST_FILTER [BUILD_DIR]}
BUILD=${2:-build-gpu}
O="$ROOT/.gpu/oclgrind"
cd "$ROOT"
grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || echo '/.gpu/' >> .git/info/exclude
if [ ! -e "$O/root/usr/lib/oclgrind/liboclgrind-rt-icd.so" ]; then
  mkdir -p "$O/debs"
  (cd "$O/debs" && apt-get download oclgrind liboclgrind-21.10) || exit 1
  for d in "$O"/debs/*.deb; do dpkg -x "$d" "$O/root"; done
fi
mkdir -p "$O/icd"
echo "$O/root/usr/lib/oclgrind/liboclgrind-rt-icd.so" > "$O/icd/oclgrind.icd"

export OCL_ICD_VENDORS="$O/icd"
export LD_LIBRARY_PATH="$O/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export SHADOWFILTER_CACHE_DIR="$O/cache"
# Oclgrind 21.10 cannot run LLVM 14's llvm.experimental.noalias.scope.decl, which inlining
# functions with restrict parameters emits: build without restrict (no value changes).
export OCLGRIND_BUILD_OPTIONS="-Drestrict="
export OCLGRIND_UNINITIALIZED=${SF_OCLGRIND_UNINIT:-0} OCLGRIND_DATA_RACES=${SF_OCLGRIND_RACES:-0}
export OCLGRIND_MAX_ERRORS=1000
LOG="$O/errors.txt"
rm -f "$LOG"
export OCLGRIND_LOG="$LOG"
timeout -k 5 "${SF_OCLGRIND_SECONDS:-600}" "$BUILD/tests/sf_tests_core" --gtest_filter="$FILTER" > "$O/tests.log" 2>&1
rc=$?
grep -E '^\[  (PASSED|FAILED) ' "$O/tests.log"
# Oclgrind 21.10 often aborts at exit (heap corruption reported while LLVM's context is torn
# down, after the tests): the tests' own verdict above is what counts.
echo "sf_tests_core exit code $rc; Oclgrind reports (count, message, kernel, source line):"
if [ -s "$LOG" ]; then
  awk '/^[A-Z]/ {msg=$0} /Kernel:/ {k=$2} /^\tAt line/ {getline src; gsub(/^[ \t]+/, "", src);
       print msg " | " k " | " src}' "$LOG" | sed -E 's/(address|Index) \(?0x[0-9a-f]+\)?/\1 N/; s/Index \([0-9]+\)/Index (N)/' |
    sort | uniq -c | sort -rn | head -30
else
  echo "  none"
fi
