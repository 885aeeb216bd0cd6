#!/usr/bin/env bash
# Builds a self-contained x86-64 bundle of the test binaries (sf_tests_*), the `shadowfilter` CLI and sf_bench for a
# machine without our Debian packages (the lent NVIDIA H200 machine; docs/gpu.md):
#   .gpu/bin/{sf_tests_*,shadowfilter,sf_bench}
#   .gpu/lib/  the DT_NEEDED closure of them, glibc and its loader included (no PoCL; unused
#              codecs stubbed, see bundle_libs.py), so that
#              .gpu/lib/ld-linux-x86-64.so.2 --library-path .gpu/lib .gpu/bin/sf_tests_core
#              runs whatever the remote's glibc is
#   .gpu/bundle.tar.xz  bin/ and lib/ packed (what travels: `carry: [".gpu/bundle.tar.xz"]`)
# Usage: scripts/gpu/bundle.sh [BUILD_DIR]   (default build-gpu; configured and built if needed)
# .gpu/ is ignored through .git/info/exclude (added here if missing); never commit it.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=${1:-build-gpu}
cd "$ROOT"
grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || echo '/.gpu/' >> .git/info/exclude

if [ ! -f "$BUILD/CMakeCache.txt" ]; then
  cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DSF_BUILD_BENCH=ON
fi
cmake --build "$BUILD" -j"${JOBS:-2}" --target sf_tests_core sf_tests_core_files sf_tests_reference sf_tests_io sf_tests_cli sf_tests_tools shadowfilter_cli sf_bench

G="$ROOT/.gpu"
rm -rf "$G/bin" "$G/lib" "$G/bundle.tar.xz"
mkdir -p "$G/bin" "$G/lib"
TESTS=(sf_tests_core sf_tests_core_files sf_tests_reference sf_tests_io sf_tests_cli sf_tests_tools)
BINS=("${TESTS[@]/#/$BUILD/tests/}" "$BUILD/shadowfilter" "$BUILD/sf_bench")
for b in "${BINS[@]}"; do
  strip -o "$G/bin/$(basename "$b")" "$b"
done

# The closure of DT_NEEDED (PoCL is not in it: the ICD loader dlopens it), OpenImageIO's codecs
# that shadowfilter never uses replaced by stubs (bundle_libs.py: 420 MB -> ~110 MB).
STUBS=(libopencv_videoio.so.406 libdcmimage.so.17 libdcmimgle.so.17 libdcmdata.so.17 liboflog.so.17
       libofstd.so.17 libavcodec.so.59 libavformat.so.59 libavutil.so.57 libswscale.so.6 libheif.so.1
       libopenvdb.so.10.0 libraw_r.so.20 libopenjp2.so.7 libwebp.so.7 libwebpdemux.so.2 libgif.so.7)
python3 "$ROOT/scripts/gpu/bundle_libs.py" "$G/lib" --stub "${STUBS[@]}" -- "${BINS[@]}"
# glibc pieces a vendor driver (libnvidia-opencl.so.1) may need when ocl-icd dlopens it: they
# must come from the same glibc as the carried libc, never from the remote's.
libc_dir=$(dirname "$(ldd "$BUILD/shadowfilter" | awk '/libc\.so\.6/ {print $3}')")
for extra in libpthread.so.0 libdl.so.2 librt.so.1 libm.so.6 libresolv.so.2 libutil.so.1; do
  if [ -e "$libc_dir/$extra" ] && [ ! -e "$G/lib/$extra" ]; then cp -L "$libc_dir/$extra" "$G/lib/"; fi
done
# Binaries ask for the loader by its absolute path; the explicit invocation replaces that.
chmod +x "$G/lib/ld-linux-x86-64.so.2"
for b in shadowfilter sf_bench; do  # every symbol resolves (stubs included)
  LD_BIND_NOW=1 "$G/lib/ld-linux-x86-64.so.2" --library-path "$G/lib" "$G/bin/$b" --help > /dev/null
done
for b in "${TESTS[@]}"; do
  LD_BIND_NOW=1 "$G/lib/ld-linux-x86-64.so.2" --library-path "$G/lib" "$G/bin/$b" --gtest_list_tests > /dev/null
done

{ echo "commit $(git rev-parse HEAD), built $(date -u +%FT%TZ) from a tree with these local changes:"
  git status --short --untracked-files=no; } > "$G/bin/build_info.txt"
tar -C "$G" -cf - bin lib | xz -T2 -6 > "$G/bundle.tar.xz"
du -sh "$G/bin" "$G/lib" "$G/bundle.tar.xz"
