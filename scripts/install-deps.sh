#!/usr/bin/env bash
# Installs the Debian packages shadowfilter needs, only those that are missing.
# Usage: scripts/install-deps.sh [core|bench|all]   (default: core)
#        fuzz: core + clang 14 and its libFuzzer/sanitizer runtimes (`make fuzz`, docs/development.md)
#        meshes: core + libcgal-demo (scanned meshes for `make mesh-scenes`)
#        dev: core + clang-tidy and clang-format (`make tidy`, docs/development.md)
set -euo pipefail
set_name="${1:-core}"
core=(build-essential cmake pkg-config ocl-icd-opencl-dev opencl-clhpp-headers opencl-c-headers
      pocl-opencl-icd clinfo libopenimageio-dev openimageio-tools libcli11-dev libgtest-dev
      libgmock-dev libembree-dev libassimp-dev
      nlohmann-json3-dev  # camera and light files (JSON), the CLI's --json summaries
      zlib1g-dev  # assimp's CMake targets link /usr/lib/x86_64-linux-gnu/libz.so, which libassimp-dev does not pull in
      libstb-dev  # examples/embed writes its PNG with stb_image_write (the package test builds it)
      fonts-dejavu-core  # evaluate's Pareto plots label points with DejaVu Sans (OIIO render_text)
      python3-venv python3-dev)  # make test: the Python package's venv and its extension's headers
bench=(libbenchmark-dev libopencv-dev)
# Scanned meshes (Stanford bunny, Chinese dragon, armadillo, ...) in data.tar.gz of the docs.
meshes=(libcgal-demo)
# Developer tools: clang-tidy 14 for `make tidy` (.clang-tidy), clang-format for the layout.
dev=(clang-tidy clang-format)
# The fuzz harnesses (tests/fuzz): clang 14 with libFuzzer and the ASan/UBSan runtimes.
fuzz=(clang-14 libclang-rt-14-dev)
case "$set_name" in
  core) want=("${core[@]}") ;;
  bench) want=("${core[@]}" "${bench[@]}") ;;
  meshes) want=("${core[@]}" "${meshes[@]}") ;;
  dev) want=("${core[@]}" "${dev[@]}") ;;
  fuzz) want=("${core[@]}" "${fuzz[@]}") ;;
  all) want=("${core[@]}" "${bench[@]}" "${meshes[@]}" "${dev[@]}" "${fuzz[@]}") ;;
  *) echo "install-deps: unknown set '$set_name' (core|bench|meshes|dev|fuzz|all)" >&2; exit 2 ;;
esac
missing=()
for p in "${want[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then exit 0; fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
