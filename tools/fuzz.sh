#!/usr/bin/env bash
# Fuzzes the scene loaders with libFuzzer (clang, ASan + UBSan) in build-fuzz/: each target of
# tests/fuzz runs for SECONDS (default 60) from the seed corpus in tests/fuzz/corpus.
# Findings land in build-fuzz/tests/fuzz/<target>-crash-* (and -timeout-, -oom-); a fixed one
# is copied into tests/fuzz/corpus/<target>/ so every ctest replays it. tests/fuzz/README.md.
# Usage: bash tools/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH="${1:-60}"
RTPG_EXTRA_PACKAGES="clang libclang-rt-14-dev" bash tools/setup.sh
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRTPG_FUZZ=ON \
  -DRTPG_BUILD_BENCH=OFF -DRTPG_FUZZ_SECONDS="$SECONDS_EACH" >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz_scene_json fuzz_obj fuzz_mtl fuzz_ply
export LSAN_OPTIONS="suppressions=$PWD/tools/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd build-fuzz
ctest --output-on-failure -j"$(nproc)" -L fuzz --timeout $((SECONDS_EACH * 2 + 120))
