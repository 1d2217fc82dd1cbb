#!/usr/bin/env bash
# Installs the dependencies (tools/setup.sh) and builds rtpg in build/ (Release, warnings as
# errors). Usage: bash tools/build.sh [extra cmake -D options]
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DRTPG_WERROR=ON "$@" >/dev/null
cmake --build build -j"$(nproc)"
