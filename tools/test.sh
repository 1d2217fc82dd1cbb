#!/usr/bin/env bash
# Quick start, command 2: install, build, run the whole test suite (ctest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
# Kernel caches stay inside the build tree (also set per test by tests/CMakeLists.txt).
export POCL_CACHE_DIR="$PWD/build/cache/pocl" RTPG_CACHE_DIR="$PWD/build/cache/rtpg"
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 600
