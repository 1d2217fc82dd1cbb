#!/usr/bin/env bash
# Packs what the GPU check runs into one folder that travels to a machine with a GPU driver but
# none of rtpg's dependencies (the workplace's GPU machines reach no package registry): the test
# binaries of ctest's label cl (every kernel against its host reference, the OpenCL runtime's
# errors; they link only OpenCL and the C++ runtime), bench_guiding_kernels, the shared
# libraries they need beyond libc and libstdc++ (the ocl-icd loader, Google Benchmark, TBB), and
# tools/gpu_bundle_run.sh as DIR/run.sh. There: `bash DIR/run.sh [OUT]` (docs/design.md,
# "Floating point on other devices").
# Usage: bash tools/gpu_bundle.sh [DIR, default .gpu] [--no-build: use the build as it is]
# BUILD_DIR (default build) is the build tree the binaries come from.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=.gpu build=1 tree=${BUILD_DIR:-build}
for arg in "$@"; do
  case "$arg" in
    --no-build) build=0 ;;
    -*) echo "gpu_bundle: unknown option $arg" >&2; exit 2 ;;
    *) dir=$arg ;;
  esac
done
[ "$build" = 1 ] && bash tools/build.sh
binaries=$(cd "$tree" && ctest -L '^cl$' --show-only=json-v1 |
  python3 -c 'import json, sys; print("\n".join(sorted({t["command"][0] for t in json.load(sys.stdin)["tests"]})))')
binaries="$binaries
$(cd "$tree" && pwd)/bench/bench_guiding_kernels"
rm -rf "$dir"
mkdir -p "$dir/bin" "$dir/lib"
for b in $binaries; do
  cp "$b" "$dir/bin/"
  # Every library but the C and C++ runtimes goes along; one the GPU machine cannot be
  # expected to have in a compatible build (Embree, OpenImageIO) means the binary does not fit.
  for lib in $(ldd "$b" | awk '$3 ~ /^\// {print $3}'); do
    case "$(basename "$lib")" in
      libc.so.*|libm.so.*|libstdc++.so.*|libgcc_s.so.*|ld-linux*) ;;
      libOpenCL.so.*|libbenchmark.so.*|libtbb.so.*) cp -L -n "$lib" "$dir/lib/" ;;
      *) echo "gpu_bundle: $(basename "$b") needs $(basename "$lib"), which the bundle does not carry" >&2
         exit 2 ;;
    esac
  done
done
cp tools/gpu_bundle_run.sh "$dir/run.sh"
echo "gpu_bundle: $(ls "$dir/bin" | wc -l) binaries, $(du -sh "$dir" | cut -f1) in $dir"
