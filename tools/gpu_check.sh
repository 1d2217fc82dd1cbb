#!/usr/bin/env bash
# The OpenCL tests (ctest label cl: runtime, kernel sources, work-groups, image, guiding and SVGF
# kernels against their host references) on a GPU instead of PoCL, then the guiding kernels'
# roofline benchmark there. For a machine with a GPU and its vendor's OpenCL driver; CI has none.
# docs/design.md, "Floating point on other devices", has the last result (NVIDIA H100).
# Usage: bash tools/gpu_check.sh [device, default gpu: as --device / RTPG_DEVICE take it]
set -euo pipefail
cd "$(dirname "$0")/.."
export RTPG_DEVICE="${1:-gpu}"
bash tools/build.sh
if ! ./build/rtpg devices | grep -q .; then
  echo "gpu_check: no OpenCL device listed" >&2
  exit 2
fi
./build/rtpg devices
cd build
# Each test selects RTPG_DEVICE itself (tests/CMakeLists.txt); a wrong name fails every test
# with the list of devices there are.
ctest --output-on-failure -L '^cl$' --timeout 600
./bench/bench_guiding_kernels --benchmark_repetitions=1 \
  --benchmark_filter='^(CopyFloat4|FmaPeak|(Reproject|Sample|Train)/1280x720/local:auto(/memory:global)?/min)'
