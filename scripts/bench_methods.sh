#!/bin/sh
# Transform throughput vs copy bandwidth (2048x2048), memory per texel and reconstruction time
# (1920x1080 receivers) per method and storage: see docs/methods.md. Needs `make build` first.
set -e
cd "$(dirname "$0")/.."
cmake --build build --target shadowfilter >/dev/null
mkdir -p out
g++ -O2 -std=c++17 -DCL_HPP_TARGET_OPENCL_VERSION=120 -DCL_HPP_MINIMUM_OPENCL_VERSION=120 \
  -DCL_HPP_ENABLE_EXCEPTIONS -Ihost/include scripts/bench_methods.cpp build/libshadowfilter.a \
  -lOpenCL -o out/bench_methods
exec out/bench_methods "${1:-7}"
