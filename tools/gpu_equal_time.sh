#!/usr/bin/env bash
# Equal time on a GPU machine inside one short lease: PT against PG (tools/gpu_equal_time.py),
# optionally against a variant of guiding too, then the OpenCL test binaries on the GPU. Run on
# the GPU machine from the repository's root. What it needs travels with the working tree:
#   BUNDLE  (default build/gpu.tar.xz): the renderer's bundle, with its opencl_vendors.sh, as a
#           tar.xz of one folder `gpub`: `bash tools/gpu_bundle.sh build/gpub --renderer &&
#           tar -cJf build/gpu.tar.xz -C build gpub`;
#   REFS    (default build/gpu-et/references): references made on the CPU machine beforehand,
#           `python3 tools/gpu_equal_time.py --out build/gpu-et --references-only --scenes ...`
#           with the same RES (any missing one is rendered there, on the lease's time);
#   ASSETS  (optional): an asset root for the scenes that read ../shared/scenes (RTPG_ASSET_ROOT;
#           a copy of ../shared/scenes/cornell-box for cornell-glossy, say; Sponza's 122 MB do not
#           fit the lease's transfer).
# SCENES (default: the Cornell box, the sunlit room, cornell-indirect), RES (960x540), FRAMES
# (32), REPEATS (4: even, so that each order of a pair of runs comes as often); VARIANT: rtpg arguments for a second guided run against the same path
# tracing (empty: none); TESTS: the test binaries run at the end (the OpenCL ones by default);
# T1, T2 (300, 180 s): the time each table may take, so that the tests and results still come
# back inside the lease's call. FRAME_RUNS (empty: none): after the tests, the bundle's run.sh
# renders the frames of those runs (its RUNS names: off, pinned, packed, sample-overlap-on, ...)
# on FRAME_SCENES (the Cornell box and the sunlit room) at RES, ROUNDS (3) interleaved, within
# T3 (150 s), into frames.md and frames.tgz: the one comparison a table's drift cannot spoil.
# BENCH (empty: none): a bench_guiding_kernels filter, run last within 60 s, into bench.log.
# OUT gets machine.txt, et.md (and variant.md), et.tgz (every run's stats, no images),
# tests.tgz, and frames.md, frames.tgz and bench.log where asked: at most the 8 files a lease's
# call brings back. docs/guiding.md, "Equal time on a GPU", has the first run, "The bus and the
# sampling's overlap on an H200" the first with frames.
set -u
out=${OUT:?OUT must name the folder for the results}
bundle=${BUNDLE:-build/gpu.tar.xz} refs=${REFS:-build/gpu-et/references}
b=/tmp/rtpg-bundle
# A warm machine keeps /tmp between calls: the bundle is extracted again when it is another one
# (a rebuild between two calls), and the last call's runs, frames and tests are cleared, or they
# would be reported as this call's.
sum=$(sha256sum < "$bundle") || exit 2
if [ "$(cat $b/bundle.sha256 2>/dev/null)" != "$sum" ]; then
  rm -rf $b && mkdir -p $b && tar -xJf "$bundle" -C $b && echo "$sum" > $b/bundle.sha256 || exit 2
fi
rm -rf /tmp/et /tmp/etv /tmp/et-frames /tmp/et-tests
g=$b/gpub
. "$g/opencl_vendors.sh"
opencl_vendors /tmp/et-vendors
export RTPG_DEVICE=${RTPG_DEVICE:-gpu} RTPG_CACHE_DIR=/tmp/rtpg-cache
export LD_LIBRARY_PATH=$g/lib PYTHONUNBUFFERED=1 RTPG_BINARY=$g/bin/rtpg
[ -n "${ASSETS:-}" ] && export RTPG_ASSET_ROOT=$PWD/$ASSETS
{ nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv; nproc
  grep -m1 'model name' /proc/cpuinfo; "$g/bin/rtpg" devices; } > "$out/machine.txt" 2>&1
cat "$out/machine.txt"
scenes=${SCENES:-cornell-box sunlit-room cornell-indirect}
common=(--res "${RES:-960x540}" --frames "${FRAMES:-32}" --repeats "${REPEATS:-4}")
mkdir -p /tmp/et/references
[ -d "$refs" ] && cp "$refs"/* /tmp/et/references/
echo "== path tracing against the default guiding"
timeout "${T1:-300}" python3 tools/gpu_equal_time.py --out /tmp/et --scenes $scenes "${common[@]}" | tee "$out/et.md"
if [ -n "${VARIANT:-}" ]; then
  mkdir -p /tmp/etv && ln -sfn /tmp/et/references /tmp/etv/references
  echo "== path tracing against guiding with: $VARIANT"
  timeout "${T2:-180}" python3 tools/gpu_equal_time.py --out /tmp/etv --scenes $scenes "${common[@]}" \
    --pg-args "$VARIANT" | tee "$out/variant.md"
fi
rm -rf /tmp/et/references /tmp/etv/references
tar -czf "$out/et.tgz" --exclude='*.exr' -C /tmp et $([ -d /tmp/etv ] && echo etv)
echo "== tests at $SECONDS s"
# The test binaries read the scenes at the path they were built in.
built_in=$(cat "$g/source_dir")
[ -e "$built_in" ] || { mkdir -p "$(dirname "$built_in")" && ln -s "$PWD" "$built_in"; }
mkdir -p /tmp/et-tests
for t in ${TESTS:-test_guiding_kernels test_image_kernels test_svgf test_work_groups test_cl_runtime test_pmm_stress test_gbuffer_packer}; do
  echo "$t"
done | xargs -P 8 -I{} sh -c 'timeout 100 "$0/bin/{}" --gtest_color=no > /tmp/et-tests/{}.log 2>&1
  echo "== {}: exit $?, $(grep -E "^\[  PASSED  \]|^\[  FAILED  \] [0-9]" /tmp/et-tests/{}.log | tr "\n" " ")"' "$g"
grep -h -E '^\[  FAILED  \] [A-Za-z]' /tmp/et-tests/*.log | sort -u
tar -czf "$out/tests.tgz" -C /tmp et-tests
if [ -n "${FRAME_RUNS:-}" ]; then
  echo "== frames at $SECONDS s"
  RENDER=1 NO_BENCH=1 TESTS=" " RUNS="$FRAME_RUNS" SCENES="${FRAME_SCENES:-cornell-box sunlit-room}" \
    RESOLUTIONS="${RES:-960x540}" ROUNDS="${ROUNDS:-3}" FRAMES=24 OCL_ICD_VENDORS="$OCL_ICD_VENDORS" \
    timeout "${T3:-150}" bash "$g/run.sh" /tmp/et-frames > /dev/null 2>&1
  python3 "$g/gpu_frames_summary.py" /tmp/et-frames/frames | tee "$out/frames.md"
  tar -czf "$out/frames.tgz" --exclude='*.exr' -C /tmp et-frames/frames
fi
if [ -n "${BENCH:-}" ]; then
  echo "== kernels at $SECONDS s"
  timeout 60 "$g/bin/bench_guiding_kernels" --benchmark_repetitions=1 --benchmark_filter="$BENCH" \
    > "$out/bench.log" 2>&1
  grep -E 'manual_time|ERROR' "$out/bench.log"
fi
echo "done at $SECONDS s"
