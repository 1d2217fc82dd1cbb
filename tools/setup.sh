#!/usr/bin/env bash
# Installs everything rtpg needs on Debian 12 (run as root, or with sudo available).
# Idempotent: packages already present are skipped quickly by apt.
set -euo pipefail

SUDO=""
if [ "$(id -u)" != "0" ]; then SUDO="sudo"; fi

DEBIAN_PACKAGES=(
  build-essential cmake pkg-config git ca-certificates
  pocl-opencl-icd ocl-icd-opencl-dev opencl-clhpp-headers opencl-c-headers clinfo
  libembree-dev libopenimageio-dev openimageio-tools libglm-dev libassimp-dev libtbb-dev
  libcli11-dev nlohmann-json3-dev libfmt-dev libspdlog-dev
  libgtest-dev libgmock-dev libbenchmark-dev oclgrind clang-format
  embree-tools
  python3 python3-pip python3-venv
)

# More for one job (tools/fuzz.sh: clang and libFuzzer), space-separated.
read -r -a EXTRA <<< "${RTPG_EXTRA_PACKAGES:-}"
DEBIAN_PACKAGES+=("${EXTRA[@]}")

missing=()
for p in "${DEBIAN_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Python tooling for the benchmark suite (numpy, matplotlib, NVIDIA's official FLIP).
PY=python3
if ! $PY -c "import numpy, matplotlib, flip_evaluator" 2>/dev/null; then
  $PY -m pip install --quiet --disable-pip-version-check -r "$(dirname "$0")/../bench/requirements.txt" \
    || $PY -m pip install --quiet --disable-pip-version-check --break-system-packages \
         -r "$(dirname "$0")/../bench/requirements.txt"
fi
