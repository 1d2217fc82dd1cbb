#!/usr/bin/env bash
# Quick start, command 1: install, build, then the main job on the built-in scenes: plain path
# tracing and PMM path guiding side by side at 1 sample per pixel (images, time per frame, error
# against a many-sample reference). Output in build/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
export POCL_CACHE_DIR="$PWD/build/cache/pocl" RTPG_CACHE_DIR="$PWD/build/cache/rtpg"
out=build/demo
mkdir -p "$out"
res=${RTPG_DEMO_RES:-192x192}
frames=${RTPG_DEMO_FRAMES:-32}
ref_spp=${RTPG_DEMO_REF_SPP:-1024}

echo "== rtpg render (default scene: scenes/cornell-box.json), guiding on"
./build/rtpg render --res "$res" --frames 4 -o "$out/default.png"

printf '\n== %s frames at 1 spp, %s, against a %s-spp reference\n' "$frames" "$res" "$ref_spp"
printf '%-18s %-8s %12s %14s %10s %s\n' scene method "ms/frame" "relMSE(last8)" "s.e." image
for scene in cornell-box cornell-indirect; do
  # Named by what it is made of (the program and the scene file): a rebuilt renderer or an edited
  # scene renders its reference again.
  key=$(cat build/rtpg "scenes/$scene.json" | sha256sum | cut -c1-12)
  ref="$out/$scene-ref-$res-$ref_spp-$key.exr"
  [ -f "$ref" ] || ./build/rtpg reference "scenes/$scene.json" --res "$res" --spp "$ref_spp" -o "$ref" -q
  for method in off pmm; do
    ./build/rtpg render "scenes/$scene.json" --res "$res" --frames "$frames" --guiding "$method" \
      --reference "$ref" --stats-json "$out/$scene-$method.json" -o "$out/$scene-$method.png" -q
    python3 - "$out/$scene-$method.json" "$scene" "$method" "$out/$scene-$method.png" <<'PY'
import json, statistics, sys
d = json.load(open(sys.argv[1]))
f = d["frames"]
ms = statistics.median(x["time_ms"]["total"] for x in f)
last = [x["relmse"] for x in f[-8:]]
rel = statistics.mean(last)
se = statistics.stdev(last) / len(last) ** 0.5 if len(last) > 1 else float("nan")
print(f"{sys.argv[2]:<18} {sys.argv[3]:<8} {ms:12.1f} {rel:14.4f} {se:10.4f} {sys.argv[4]}")
PY
  done
done
echo
echo "relMSE = mean of (I - R)^2 / (R^2 + 0.01) over pixels and channels, averaged over the last"
echo "8 frames, with the standard error of that average (a frame's relMSE is heavy-tailed: one"
echo "firefly moves it, so differences within two standard errors are noise; bench/experiments.py"
echo "measures the methods over many frames and seeds); 'off' = BSDF sampling of the first bounce,"
echo "'pmm' = the guided mixture."
