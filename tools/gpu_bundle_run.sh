#!/usr/bin/env bash
# run.sh of a bundle made by tools/gpu_bundle.sh: the OpenCL tests, then the guiding kernels'
# roofline benchmark, on RTPG_DEVICE (default gpu); the binaries embed the kernels and read no
# other file. Logs go to OUT (default DIR/out): tests.log, bench.log, bench.json, devices.log.
# TESTS (binary names) narrows the tests; NO_BENCH=1 skips the benchmark; BENCH_FILTER replaces
# its default filter (the yardsticks, the three kernels at 1280x720 and one frame's bus traffic).
# A bundle made with --renderer (tools/gpu_bundle.sh) holds every test binary and rtpg: with
# RENDER=1 the tests run JOBS at a time (default 6; the test binaries find the repository's
# scenes at the path they were built in, linked to SOURCE, default the working directory), then
# rtpg renders FRAMES frames (default 24) of SCENES at RESOLUTIONS path-traced and guided with each
# host transfer, and with SVGF, into OUT/frames/*.json (--stats-json; RUNS names them: off,
# off-svgf, each --host-transfer alone or with -svgf, overlap-on / overlap-off: the default
# transfer with --train-overlap on / off, and sample-overlap-on / sample-overlap-off: with
# --sample-overlap on / off) with their table in OUT/frames.md
# (gpu_frames_summary.py; ROUNDS repeats them, interleaved, into ...-RUN-rN.json), and
# bench_svgf and bench_frame run on the Cornell box (not with NO_BENCH). TESTS narrows the tests
# there too.
# Exit status: the number of test binaries that failed, 0 if none.
set -uo pipefail
dir=$(cd "$(dirname "$0")" && pwd)
out=${1:-$dir/out}
mkdir -p "$out"
export RTPG_DEVICE="${RTPG_DEVICE:-gpu}" RTPG_CACHE_DIR="${RTPG_CACHE_DIR:-$out/cache}"
export LD_LIBRARY_PATH="$dir/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
# The carried ICD loader reads the system's vendor files; a driver whose OpenCL library is
# installed without one (NVIDIA's in a container) gets one in a folder of its own.
if [ -z "${OCL_ICD_VENDORS:-}" ]; then
  . "$dir/opencl_vendors.sh"
  opencl_vendors "$out/vendors"
fi
{ ls "$OCL_ICD_VENDORS"; cat "$OCL_ICD_VENDORS"/*.icd; } > "$out/devices.log" 2>&1
failed=0
: > "$out/tests.log"
if [ -n "${RENDER:-}" ]; then
  # The test binaries read scenes at the path they were built in (RTPG_SOURCE_DIR).
  built_in=$(cat "$dir/source_dir")
  [ -e "$built_in" ] || { mkdir -p "$(dirname "$built_in")" && ln -s "${SOURCE:-$PWD}" "$built_in"; }
  # The CLI tests run the build's rtpg.
  [ -e "$built_in/build/rtpg" ] || { mkdir -p "$built_in/build" && ln -s "$dir/bin/rtpg" "$built_in/build/rtpg"; }
  mkdir -p "$out/tests"
  for t in ${TESTS:-$(ls "$dir/bin" | grep '^test_')}; do echo "$t"; done | xargs -P "${JOBS:-6}" -I{} sh -c \
    'start=$(date +%s); timeout "${TEST_TIMEOUT:-300}" "$0/bin/{}" --gtest_color=no > "$1/tests/{}.log" 2>&1;
     echo "== {}: exit $?, $(( $(date +%s) - start )) s"' "$dir" "$out" | tee -a "$out/tests.log"
  failed=$(grep -c -v ': exit 0,' "$out/tests.log")
  cat "$out"/tests/*.log > "$out/tests-full.log"
  grep -h -E '^\[  FAILED  \] [A-Za-z]' "$out"/tests/*.log | sort -u
else
  for t in ${TESTS:-$(ls "$dir/bin" | grep '^test_')}; do
    start=$(date +%s)
    "$dir/bin/$t" --gtest_color=no >> "$out/tests.log" 2>&1
    rc=$?
    [ "$rc" = 0 ] || failed=$((failed + 1))
    echo "== $t: exit $rc, $(( $(date +%s) - start )) s" | tee -a "$out/tests.log"
  done
  grep -E '^\[  FAILED  \] [A-Za-z]' "$out/tests.log" | sort -u
fi
if [ -z "${NO_BENCH:-}" ]; then
  # One repetition: on a GPU each configuration is already the mean of thousands of launches.
  "$dir/bin/bench_guiding_kernels" --benchmark_repetitions=1 \
    --benchmark_filter="${BENCH_FILTER:-^(CopyFloat4|FmaPeak|(Reproject|Sample|Train)/1280x720/local:auto(/memory:global)?/min|FrameTraffic/960x540|Transfer/.*/960x540)}" \
    --benchmark_out="$out/bench.json" --benchmark_out_format=json > "$out/bench.log" 2>&1
  grep -E 'manual_time|ERROR' "$out/bench.log"
fi
if [ -n "${RENDER:-}" ]; then
  mkdir -p "$out/frames"
  for round in $(seq 1 "${ROUNDS:-1}"); do
  # ROUNDS > 1 repeats every run, interleaved, into files named ...-RUN-rN.json (the summary
  # pools a run's rounds).
  suffix=""
  [ "${ROUNDS:-1}" -gt 1 ] && suffix="-r$round"
  for scene in ${SCENES:-cornell-box cornell-indirect veach-ajar sunlit-room}; do
    for res in ${RESOLUTIONS:-960x540 1920x1080}; do
      for name in ${RUNS:-off pinned packed pageable in-place off-svgf pinned-svgf}; do
        case $name in
          off) set -- --guiding off ;;
          off-svgf) set -- --guiding off --denoise svgf ;;
          overlap-on|overlap-off) set -- --train-overlap "${name#overlap-}" ;;
          sample-overlap-on|sample-overlap-off) set -- --sample-overlap "${name#sample-overlap-}" ;;
          *-svgf) set -- --host-transfer "${name%-svgf}" --denoise svgf ;;
          *) set -- --host-transfer "$name" ;;
        esac
        file="$out/frames/$scene-$res-$name$suffix"
        "$dir/bin/rtpg" render "scenes/$scene.json" --res "$res" --frames "${FRAMES:-24}" "$@" \
          --stats-json "$file.json" > "$file.log" 2>&1
        echo "== $scene $res $name$suffix: exit $?, $(grep 'time per frame' "$file.log")"
      done
    done
  done
  done
  python3 "$dir/gpu_frames_summary.py" "$out/frames" | tee "$out/frames.md"
fi
if [ -n "${RENDER:-}" ] && [ -z "${NO_BENCH:-}" ]; then
  "$dir/bin/bench_svgf" --benchmark_repetitions=1 \
    --benchmark_filter="${SVGF_FILTER:-^cornell/(960x540|1920x1080)/lanes:auto/history:(full|none)}" \
    --benchmark_out="$out/bench_svgf.json" --benchmark_out_format=json > "$out/bench_svgf.log" 2>&1
  grep -E 'manual_time|ERROR' "$out/bench_svgf.log"
  "$dir/bin/bench_frame" --benchmark_filter="${FRAME_FILTER:-^Frame/cornell}" \
    --benchmark_out="$out/bench_frame.json" --benchmark_out_format=json > "$out/bench_frame.log" 2>&1
  grep -E 'manual_time|ERROR' "$out/bench_frame.log"
fi
exit "$failed"
