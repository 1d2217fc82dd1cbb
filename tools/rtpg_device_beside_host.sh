#!/usr/bin/env bash
# rtpg with the host on one thread and PoCL's CPU device on the other: a model, on a CPU machine,
# of a device with cores of its own (docs/guiding.md, "Sampling overlapped with the primary hit's
# light samples"). `render` runs with --threads 1 and POCL_MAX_PTHREAD_COUNT=1; every other
# subcommand (reference, info, devices) as it is. RTPG (default build/rtpg beside this folder)
# is the binary; use this script as RTPG_BINARY for the benchmark tools, e.g.
#   RTPG_BINARY=tools/rtpg_device_beside_host.sh python3 tools/gpu_equal_time.py --out OUT \
#       --pg-args "--train-overlap on --sample-overlap on"
set -euo pipefail
rtpg=${RTPG:-$(cd "$(dirname "$0")/.." && pwd)/build/rtpg}
if [ "${1:-}" = render ]; then
  POCL_MAX_PTHREAD_COUNT=1 exec "$rtpg" "$@" --threads 1
fi
exec "$rtpg" "$@"
