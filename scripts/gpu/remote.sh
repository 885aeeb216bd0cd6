#!/usr/bin/env bash
# Runs on the lent GPU machine (as root, in the root of the working-tree copy): the bundled
# The test binaries (sf_tests_*), `shadowfilter devices` and sf_bench on NVIDIA's OpenCL driver (docs/gpu.md).
# Needs .gpu/bundle.tar.xz from scripts/gpu/bundle.sh, carried. Writes to $OUT (8 files at most):
#   env.txt devices.txt tests.log tests.xml bench.log bench.json summary.txt
# Knobs: SF_TEST_FILTER (*) SF_TEST_SECONDS (240) SF_BENCH_SECONDS (150) SF_SHARDS (6) SF_BENCH_FILTER SF_SKIP_BENCH=1
#        SHADOWFILTER_DEVICE (default gpu). Locally, OCL_ICD_VENDORS=/etc/OpenCL/vendors
#        SHADOWFILTER_DEVICE=cpu scripts/gpu/remote.sh runs the same bundle on PoCL.
set -u
OUT=${OUT:-/tmp/sf_gpu_out}
mkdir -p "$OUT"
ROOT=$PWD
G=$ROOT/.gpu
T0=$(date +%s)
log() { echo "[$(( $(date +%s) - T0 ))s] $*" | tee -a "$OUT/env.txt"; }

if [ ! -x "$G/bin/sf_tests_core" ]; then
  tar -C "$G" -xJf "$G/bundle.tar.xz" ||
    python3 -c "import sys, tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])" "$G/bundle.tar.xz" "$G" ||
    { log "cannot unpack $G/bundle.tar.xz"; exit 1; }
fi
log "bundle unpacked"
{
  cat "$G/bin/build_info.txt"; uname -a; head -2 /etc/os-release; ldd --version 2>&1 | head -1
  nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.sm,clocks.max.sm,clocks.mem --format=csv 2>&1
  echo "ls /etc/OpenCL/vendors:"; ls -l /etc/OpenCL/vendors 2>&1; cat /etc/OpenCL/vendors/* 2>/dev/null
  nproc; free -g | head -2
} >> "$OUT/env.txt" 2>&1

# The tests read SF_DATA_DIR=/work/main/data and run SF_CLI_PATH=/work/main/build-gpu/shadowfilter.
if [ "$(readlink -f /work/main)" != "$(readlink -f "$ROOT")" ]; then
  mkdir -p /work
  if [ -e /work/main ] && [ ! -L /work/main ]; then mv /work/main "/work/main.orig.$$"; fi
  ln -sfn "$ROOT" /work/main
fi

# NVIDIA's OpenCL driver, registered for the carried ocl-icd loader.
if [ -z "${OCL_ICD_VENDORS:-}" ]; then
  NV=$(ldconfig -p 2>/dev/null | awk '/libnvidia-opencl\.so\.1/ {print $NF; exit}')
  if [ -z "$NV" ]; then
    for d in /usr/lib/x86_64-linux-gnu /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib64 /usr/lib; do
      if [ -e "$d/libnvidia-opencl.so.1" ]; then NV="$d/libnvidia-opencl.so.1"; break; fi
    done
  fi
  if [ -z "$NV" ]; then
    NV=$(timeout 40 find / \( -path /proc -o -path /sys -o -path /dev \) -prune -o \
         -name 'libnvidia-opencl.so*' -print 2>/dev/null | head -1)
  fi
  log "NVIDIA OpenCL driver: ${NV:-none found}"
  mkdir -p /tmp/sf_icd
  echo "$NV" > /tmp/sf_icd/nvidia.icd
  export OCL_ICD_VENDORS=/tmp/sf_icd
  EXTRA="$(dirname "${NV:-/usr/lib/x86_64-linux-gnu/x}")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
else
  EXTRA=""
fi
LP="$G/lib${EXTRA:+:$EXTRA}"
export SHADOWFILTER_DEVICE=${SHADOWFILTER_DEVICE:-gpu}
export SHADOWFILTER_CACHE_DIR=/tmp/sf_cache
# OpenImageIO tries every reader on a file its extension's reader refuses; the bundle's codecs are
# stubs (bundle_libs.py) that must never be called.
export OPENIMAGEIO_OPTIONS=try_all_readers=0

# Mode A: the carried loader and glibc. Mode B (fallback): the remote's glibc, our other libraries.
RUN="$G/lib/ld-linux-x86-64.so.2 --library-path $LP"
timeout -k 5 60 $RUN "$G/bin/shadowfilter" devices > "$OUT/devices.txt" 2>&1
log "devices (carried glibc): rc $?"
if ! grep -qi "${SF_EXPECT_DEVICE:-nvidia}" "$OUT/devices.txt"; then
  mkdir -p /tmp/sf_libn
  for f in "$G"/lib/*; do
    case "$(basename "$f")" in
      ld-linux*|libc.so*|libm.so*|libpthread*|libdl.so*|librt.so*|libresolv*|libutil*) ;;
      *) ln -sfn "$f" /tmp/sf_libn/ ;;
    esac
  done
  RUN="env LD_LIBRARY_PATH=/tmp/sf_libn${EXTRA:+:$EXTRA}"
  echo "---- fallback: remote glibc" >> "$OUT/devices.txt"
  timeout -k 5 60 $RUN "$G/bin/shadowfilter" devices >> "$OUT/devices.txt" 2>&1
  log "devices (remote glibc): rc $?"
fi
cat "$OUT/devices.txt"

# The CLI the tests run: a wrapper through the same loader (a real binary there is kept).
W="$ROOT/build-gpu/shadowfilter"
if [ ! -e "$W" ] || grep -q sf-gpu-wrapper "$W"; then
  mkdir -p "$ROOT/build-gpu"
  printf '#!/bin/sh\n# sf-gpu-wrapper\nexec %s %s "$@"\n' "$RUN" "$G/bin/shadowfilter" > "$W"
  chmod +x "$W"
fi

# Tests, in SF_SHARDS concurrent gtest shards (one process each, as ctest -j runs them).
N=${SF_SHARDS:-6}
R=/tmp/sf_res
rm -rf "$R"; mkdir -p "$R"
# Each shard runs its part of every test binary (tests/CMakeLists.txt: one per layer), in turn.
TESTS="sf_tests_core sf_tests_core_files sf_tests_reference sf_tests_io sf_tests_cli sf_tests_tools"
for i in $(seq 0 $((N - 1))); do
  for b in $TESTS; do
    GTEST_TOTAL_SHARDS=$N GTEST_SHARD_INDEX=$i timeout -k 5 "${SF_TEST_SECONDS:-240}" \
      $RUN "$G/bin/$b" --gtest_filter="${SF_TEST_FILTER:-*}" --gtest_output="xml:$R/tests_${i}_$b.xml" >> "$R/tests_$i.log" 2>&1
  done &
done
wait
log "tests done"
for i in $(seq 0 $((N - 1))); do
  echo "==== shard $i"; cat "$R/tests_$i.log"
  for b in $TESTS; do
    [ -f "$R/tests_${i}_$b.xml" ] || echo "==== shard $i of $b wrote no XML (timed out or crashed)"
  done
done > "$OUT/tests.log"
python3 - "$R" "$OUT/tests.xml" <<'PY'
import glob, sys, xml.etree.ElementTree as ET
root = ET.Element("testsuites")
for n in ("tests", "failures", "disabled", "errors"):
    root.set(n, "0")
for f in sorted(glob.glob(sys.argv[1] + "/tests_*.xml")):
    r = ET.parse(f).getroot()
    for n in ("tests", "failures", "disabled", "errors"):
        root.set(n, str(int(root.get(n)) + int(r.get(n, "0"))))
    for s in r:
        s.set("shard", f.rsplit("_", 1)[1].split(".")[0])
        root.append(s)
ET.ElementTree(root).write(sys.argv[2])
PY
FAILRE='^\[  FAILED  \] .*\([0-9]+ ms\)$'
{
  echo "tests: $(grep -c '^\[       OK \]' "$OUT/tests.log") passed, $(grep -cE "$FAILRE" "$OUT/tests.log") failed"
  grep -E "$FAILRE" "$OUT/tests.log"
  grep -h 'wrote no XML' "$OUT/tests.log"
} > "$OUT/summary.txt"
cat "$OUT/summary.txt"

if [ -z "${SF_SKIP_BENCH:-}" ]; then
  # Device kernels only (no double references, no OpenCV): copy, transforms at 2048^2 (width 1
  # and 16), blurs at 2048^2, pyramids, SATs, the ESM pipeline; the seeds' tables and the
  # classified frame (docs/performance.md's benchmarks, scripts/performance_tables.py --gpu).
  F=${SF_BENCH_FILTER:-'^copy/|^transform/.*/size:2048/vec:(1|16)/|^blur/ours[a-z0-9_]*/size:2048/|^mips/(chain|zmax_chain|zmin_chain)/|^sat/table/|^esm_pipeline/|^esm_transform/size:2048/|^table|^coherent/query_|^esm_classify/frame/size:2048/'}
  SF_BENCH_MIN_TIME=${SF_BENCH_MIN_TIME:-0.05} SF_BENCH_REPETITIONS=${SF_BENCH_REPETITIONS:-3} \
  timeout -k 5 "${SF_BENCH_SECONDS:-150}" $RUN "$G/bin/sf_bench" --benchmark_filter="$F" \
    --benchmark_min_time=0.05 --benchmark_repetitions=3 --benchmark_out="$OUT/bench.json" \
    --benchmark_out_format=json > "$OUT/bench.log" 2>&1
  log "bench: rc $?"
fi
nvidia-smi --query-gpu=clocks.sm,clocks.mem,temperature.gpu,power.draw --format=csv >> "$OUT/env.txt" 2>&1
log "end"
