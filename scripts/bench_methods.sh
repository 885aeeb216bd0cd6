#!/bin/sh
# Transform throughput vs copy bandwidth (2048x2048), memory per texel and reconstruction time
# (1920x1080 receivers) per method and storage: see docs/methods.md. Needs a configured build
# directory: BUILD (default build). Args: repetitions (default 7). Env of the harness: see
# scripts/bench_methods.cpp (ONLY, NOREC, WG, XVEC).
set -e
cd "$(dirname "$0")/.."
BUILD="${BUILD:-build}"
cmake --build "$BUILD" --target shadowfilter >/dev/null
mkdir -p out
g++ -O2 -std=c++17 -DCL_HPP_TARGET_OPENCL_VERSION=120 -DCL_HPP_MINIMUM_OPENCL_VERSION=120 \
  -DCL_HPP_ENABLE_EXCEPTIONS -Ihost/include scripts/bench_methods.cpp "$BUILD/libshadowfilter.a" \
  -lOpenCL -o "out/bench_methods_$(basename "$BUILD")"
exec "out/bench_methods_$(basename "$BUILD")" "${1:-7}"
