#!/usr/bin/env bash
# The GPU check where rtpg builds: the bundle of tools/gpu_bundle.sh (the OpenCL tests, ctest's
# label cl, and the guiding kernels' roofline benchmark) made in build/gpu-bundle and run here on
# a GPU instead of PoCL. CI has no GPU. docs/design.md, "Floating point on other devices", has the
# last result (NVIDIA H100).
# Usage: bash tools/gpu_check.sh [device, default gpu: as --device / RTPG_DEVICE take it]
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/gpu_bundle.sh build/gpu-bundle
RTPG_DEVICE="${1:-gpu}" bash build/gpu-bundle/run.sh
