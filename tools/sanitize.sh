#!/usr/bin/env bash
# The whole test suite built with AddressSanitizer + UndefinedBehaviorSanitizer (host code; the
# kernels run inside PoCL, which is not instrumented) in build-asan/, then run. Any report
# aborts its test, so a clean run is a passing run. docs/robustness.md, "Sanitizers".
# Usage: bash tools/sanitize.sh [extra ctest arguments, e.g. -R Scene]
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRTPG_WERROR=ON -DRTPG_SANITIZE=ON \
  -DRTPG_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j"$(nproc)"
export POCL_CACHE_DIR="$PWD/build-asan/cache/pocl" RTPG_CACHE_DIR="$PWD/build-asan/cache/rtpg"
# Leaks of the libraries we do not own (PoCL's LLVM, the OpenCL ICD loader) are theirs.
export LSAN_OPTIONS="suppressions=$PWD/tools/lsan.supp:print_suppressions=0"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd build-asan
# Oclgrind runs the kernels in its own interpreter (nothing of ours to instrument), the
# benchmark pipeline tests time the renderer, and the GPU bundle carries no sanitizer runtime:
# all three are left to the plain build.
ctest --output-on-failure -j"$(nproc)" --timeout 900 -LE "oclgrind|bench|gpu_bundle" "$@"
