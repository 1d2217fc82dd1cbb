#!/usr/bin/env bash
# Packs what the GPU check runs into one folder that travels to a machine with a GPU driver but
# none of rtpg's dependencies (the workplace's GPU machines reach no package registry): the test
# binaries of ctest's label cl (every kernel against its host reference, the OpenCL runtime's
# errors; they link only OpenCL and the C++ runtime), bench_guiding_kernels, the shared
# libraries they need beyond libc and libstdc++ (the ocl-icd loader, Google Benchmark, TBB), and
# tools/gpu_bundle_run.sh as DIR/run.sh. There: `bash DIR/run.sh [OUT]` (docs/design.md,
# "Floating point on other devices").
# With --renderer the bundle also holds rtpg, every test binary and bench_frame / bench_svgf /
# bench_gbuffer_packer (the host's share of the G-buffer's trip on a GPU machine: docs/guiding.md,
# "Equal time on a GPU"),
# with Embree, assimp and OpenImageIO; the ~200 libraries OpenImageIO links for formats rtpg
# never reads (video, OpenVDB, DICOM, ...) are replaced by load-time stand-ins
# (tools/gpu_stub_libs.py) so that the bundle stays small enough to travel. Then run.sh also
# runs the whole test suite and guided frames (RENDER=1).
# Usage: bash tools/gpu_bundle.sh [DIR, default .gpu] [--no-build: use the build as it is]
#        [--renderer]
# BUILD_DIR (default build) is the build tree the binaries come from.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=.gpu build=1 renderer=0 tree=${BUILD_DIR:-build}
for arg in "$@"; do
  case "$arg" in
    --no-build) build=0 ;;
    --renderer) renderer=1 ;;
    -*) echo "gpu_bundle: unknown option $arg" >&2; exit 2 ;;
    *) dir=$arg ;;
  esac
done
[ "$build" = 1 ] && bash tools/build.sh
label='^cl$'
[ "$renderer" = 1 ] && label='.'
binaries=$(cd "$tree" && ctest -L "$label" --show-only=json-v1 |
  python3 -c 'import json, sys; print("\n".join(sorted({t["command"][0] for t in json.load(sys.stdin)["tests"] if "command" in t and "/tests/" in t["command"][0] and "/fuzz/" not in t["command"][0]})))')
binaries="$binaries
$(cd "$tree" && pwd)/bench/bench_guiding_kernels"
[ "$renderer" = 1 ] && binaries="$binaries
$(cd "$tree" && pwd)/rtpg
$(cd "$tree" && pwd)/bench/bench_frame
$(cd "$tree" && pwd)/bench/bench_svgf
$(cd "$tree" && pwd)/bench/bench_gbuffer_packer"
# Libraries that travel: the C and C++ runtimes are the machine's; these are carried; with
# --renderer any other is a stand-in, else it means the binary does not fit.
system='^(libc|libm|libstdc\+\+|libgcc_s|ld-linux.*|libpthread|libdl|librt)\.so'
carried='^lib(OpenCL|benchmark|tbb|tbbmalloc)\.so'
[ "$renderer" = 1 ] &&
  carried='^lib(OpenCL|benchmark|tbb|tbbmalloc|embree3|assimp|draco|minizip|z|fmt|OpenImageIO|OpenImageIO_Util|OpenEXR-3_1|OpenEXRCore-3_1|Imath-3_1|Iex-3_1|IlmThread-3_1|png16|jpeg|boost_thread|tiff|Lerc|zstd|lzma|jbig|deflate|webp|sharpyuv)\.so'
rm -rf "$dir"
mkdir -p "$dir/bin" "$dir/lib"
declare -A path_of
for b in $binaries; do
  cp "$b" "$dir/bin/"
  while read -r name lib; do
    path_of[$name]=$lib
    if [[ $name =~ $system ]]; then continue; fi
    if [[ $name =~ $carried ]]; then cp -L -n "$lib" "$dir/lib/"; continue; fi
    if [ "$renderer" = 0 ]; then
      echo "gpu_bundle: $(basename "$b") needs $name, which the bundle does not carry" >&2
      exit 2
    fi
  done < <(ldd "$b" | awk '$3 ~ /^\// {print $1, $3}')
done
if [ "$renderer" = 1 ]; then
  # Stand-ins for what the carried files link directly and the bundle leaves behind.
  stubs=()
  for name in $(for f in "$dir"/bin/* "$dir"/lib/*; do
                  readelf -d "$f" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'; done | sort -u); do
    [[ $name =~ $system ]] && continue
    [ -e "$dir/lib/$name" ] && continue
    stubs+=("${path_of[$name]:?gpu_bundle: no path for $name}")
  done
  python3 tools/gpu_stub_libs.py "$dir/lib" --carried "$dir"/bin/* "$dir"/lib/* --stub "${stubs[@]}"
fi
cp tools/gpu_bundle_run.sh "$dir/run.sh"
cp tools/gpu_opencl_vendors.sh "$dir/opencl_vendors.sh"
cp tools/gpu_frames_summary.py "$dir/"
pwd > "$dir/source_dir"
echo "gpu_bundle: $(ls "$dir/bin" | wc -l) binaries, $(du -sh "$dir" | cut -f1) in $dir"
