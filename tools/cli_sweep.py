#!/usr/bin/env python3
"""Random combinations of `rtpg render`'s options at odd image sizes, on the suite's scenes.

Each run draws 1-8 options from the table below (every rendering, guiding and denoising option
of the CLI, at ordinary and extreme values) and an image of 1-65 x 1-31 pixels, and must end in
one of two ways:
- success: exit status 0, the stats JSON with one record per frame and no non-finite sample, the
  output image written, and no NaN or infinite value in the EXRs written (`oiiotool --stats`: the
  denoised and accumulated images come after the renderer's own count);
- a clear refusal: exit status 2 (an input the program refuses), a last line of stderr that starts
  with "rtpg:", and no output file left behind (docs/robustness.md: bad input gets a clear error
  and no half-written output).
Anything else (a signal, exit 1, an internal exception; exit 3, an OpenCL failure, such as a
kernel that does not build for a valid combination of settings; an unnamed message, a missing or
half-written file) is reported with its command line, and the exit status is 1. An option that
acts only beside another (the denoiser's settings beside --denoise svgf, the world guide's beside
--guide-vertices world) brings that one with it, unless the run already chose otherwise. Fixed seeds: the same --seed draws the
same runs. The long sweep is a slow check: README.md, "Robustness checks".

    python3 tools/cli_sweep.py [--runs 250] [--seed 3] [--binary build/rtpg] [--out DIR]
                               [--scenes NAME ...]

The test suite runs a short sweep (ctest cli_sweep_short: 16 runs on the three Cornell boxes).
"""
import argparse
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENES = ["cornell-box", "cornell-glossy", "cornell-indirect", "sunlit-room", "slit-room",
          "corridor", "veach-ajar", "sponza"]
# The large scenes (whose assets take seconds to load) are drawn one time in ten.
SMALL_SCENES = SCENES[:6]

# One entry per option: a function of the random generator giving its arguments. "PATH" stands
# for the scene's camera path.
OPTIONS = [
    lambda r: ["--spp", str(r.choice([1, 2, 3]))],
    lambda r: ["--frames", str(r.choice([1, 2, 3, 5]))],
    lambda r: ["--no-jitter"],
    lambda r: ["--camera-path", "PATH"],
    lambda r: ["--max-bounces", str(r.choice([0, 1, 2, 3, 20]))],
    lambda r: ["--no-nee"],
    lambda r: ["--share-randoms", r.choice(["first-bounce", "primary-vertex", "second-vertex"])],
    lambda r: ["--accumulate"],
    lambda r: ["--guiding", r.choice(["off", "pmm"])],
    lambda r: ["--guide-vertices", r.choice(["first", "all", "world"])],
    lambda r: ["--world-guide-resolution", str(r.choice([1, 2, 7, 300]))],
    lambda r: ["--world-guide-max-depth", str(r.choice([0, 1, 5]))],
    lambda r: ["--world-guide-record-every", str(r.choice([1, 3]))],
    lambda r: ["--guide-direct-light", r.choice(["off", "mis"])],
    lambda r: ["--first-bounce-mis", r.choice(["mixture", "bsdf"])],
    lambda r: ["--denoise", "svgf"],
    lambda r: ["--pg-train-lanes", str(r.choice([1, 2, 4, 8, 16]))],
    lambda r: ["--pg-sample-lanes", str(r.choice([1, 2, 4, 8, 16]))],
    lambda r: ["--pg-apron", str(r.choice([0, 1, 3, 8]))],
    lambda r: ["--pg-em-passes", str(r.choice([1, 8]))],
    lambda r: ["--pg-n-min", "1", "--pg-n-max", str(r.choice([1, 32]))],
    lambda r: ["--pg-pi-learning", "1"],
    lambda r: ["--pg-train-interval", str(r.choice([1, 64]))],
    lambda r: ["--pg-rows-per-model", str(r.choice([0, 1, 2, 4, 8]))],
    lambda r: ["--pg-train-memory", r.choice(["local", "global"])],
    lambda r: ["--pg-local-x", str(r.choice([1, 3, 16])), "--pg-local-y", str(r.choice([1, 5, 16]))],
    lambda r: ["--host-transfer", r.choice(["in-place", "pinned", "packed", "pageable"])],
    lambda r: ["--train-overlap", r.choice(["on", "off"])],
    lambda r: ["--sample-overlap", r.choice(["on", "off"])],
    lambda r: ["--svgf-iterations", str(r.choice([1, 12]))],
    lambda r: ["--svgf-atrous-radius", "1"],
    lambda r: ["--svgf-history-iteration", str(r.choice([0, 3, 11]))],
    lambda r: ["--svgf-phi-normal", str(r.choice([0, 1, 7, 4096]))],
    lambda r: ["--svgf-lanes", str(r.choice([1, 2, 4, 8, 16]))],
    lambda r: ["--svgf-local-x", str(r.choice([1, 7])), "--svgf-local-y", str(r.choice([1, 3]))],
    lambda r: ["--svgf-min-history", "1"],
    lambda r: ["--pg-reproject-view-memory", "2"],
    lambda r: ["--threads", str(r.choice([1, 3]))],
    lambda r: ["--seed", str(r.choice([0, 7, 4294967295]))],
    lambda r: ["--bounce-ray-order", r.choice(["grouped", "listed"])],
    lambda r: ["--world-guide-pi-max", str(r.choice([0.2, 0.95]))],
    lambda r: ["--world-guide-min-pi", str(r.choice([0.0, 0.5, 1.0]))],
    lambda r: ["--pg-pi-min", str(r.choice([0.0, 0.1])), "--pg-pi-max", str(r.choice([0.5, 0.99]))],
    lambda r: ["--pg-k-max", str(r.choice([1, 1000]))],
    lambda r: ["--pg-weight-clamp", str(r.choice([1, 100]))],
    lambda r: ["--pg-max-weight", str(r.choice([1, 1e30]))],
    lambda r: ["--pg-train-all-samples", str(r.choice([0, 1]))],
    lambda r: ["--pg-roughness-skip", str(r.choice([0, 0.5]))],
    lambda r: ["--svgf-alpha-colour", str(r.choice([0, 1])),
               "--svgf-alpha-moments", str(r.choice([0, 0.5]))],
    lambda r: ["--svgf-max-history", str(r.choice([1, 4, 1000]))],
    lambda r: ["--svgf-history-fallback", str(r.choice([0, 1]))],
    lambda r: ["--svgf-depth-slope-from-normal", "1"],
    lambda r: ["--svgf-history-atrous-radius", "1"],
    lambda r: ["--svgf-phi-depth", str(r.choice([1e-6, 1e6])),
               "--svgf-phi-luminance", str(r.choice([1e-6, 1e6]))],
    lambda r: ["--svgf-reproject-position", str(r.choice([0, 10])),
               "--svgf-reproject-normal", str(r.choice([-1, 1]))],
    lambda r: ["--svgf-albedo-floor", str(r.choice([1e-6, 1]))],
]
# An option that acts only beside another: the flag prefix and what it needs.
NEEDS = [("--svgf-", ["--denoise", "svgf"]), ("--world-guide-", ["--guide-vertices", "world"])]


def camera_path(scene):
    paths = json.loads((ROOT / "scenes" / f"{scene}.json").read_text()).get("camera_paths", {})
    return next(iter(paths), None)


def draw(r, k, out, scenes=None):
    """The k-th run's scene (from `scenes` where given) and arguments (after `rtpg render`), and
    its output files."""
    scene = r.choice(scenes) if scenes else r.choice(SMALL_SCENES if r.random() < 0.9 else SCENES)
    w, h = r.choice([1, 2, 3, 7, 16, 17, 33, 65]), r.choice([1, 2, 5, 9, 16, 31])
    files = {"output": out / f"o{k}.exr", "stats": out / f"s{k}.json"}
    args = [str(ROOT / "scenes" / f"{scene}.json"), "--res", f"{w}x{h}", "-q",
            "-o", str(files["output"]), "--stats-json", str(files["stats"])]
    path = camera_path(scene)
    for option in r.sample(OPTIONS, r.randint(1, 8)):
        drawn = option(r)
        if "PATH" in drawn:
            if path is None:
                continue
            drawn = [path if a == "PATH" else a for a in drawn]
        args += drawn
    for prefix, needed in NEEDS:
        if any(a.startswith(prefix) for a in args) and needed[0] not in args:
            args += needed
    if "--denoise" in args and r.random() < 0.3:
        files["noisy"] = out / f"n{k}.exr"
        args += ["--save-frames", "0", "--noisy-output", str(files["noisy"])]
    return args, files


def nonfinite_values(path):
    """NaN and infinite values in an image, by `oiiotool --stats` (OpenImageIO's tools, which
    tools/setup.sh installs)."""
    out = subprocess.run(["oiiotool", "--stats", str(path)], capture_output=True, text=True).stdout
    count = 0
    for line in out.splitlines():
        words = line.split()
        if len(words) > 2 and words[0] == "Stats" and words[1] in ("NanCount:", "InfCount:"):
            count += sum(int(w) for w in words[2:])
    return count


def verdict(result, files, args):
    """None where the run ended as it must, else what went wrong."""
    stderr = result.stderr.strip().splitlines()
    if result.returncode == 0:
        try:
            stats = json.loads(files["stats"].read_text())
        except (OSError, ValueError) as e:
            return f"exit 0 without a readable stats JSON ({e})"
        frames = int(args[args.index("--frames") + 1]) if "--frames" in args else 1
        if len(stats.get("frames", [])) != frames:
            return f"exit 0 with {len(stats.get('frames', []))} frame records for {frames} frames"
        nonfinite = sum(f.get("nonfinite_samples", 0) for f in stats["frames"])
        if nonfinite:
            return f"{nonfinite} non-finite samples"
        if not files["output"].is_file():
            return "exit 0 without the output EXR"
        for name, path in files.items():
            if path.suffix == ".exr" and path.is_file():
                bad = nonfinite_values(path)
                if bad:
                    return f"{bad} NaN or infinite values in the {name} image {path.name}"
        return None
    # Exit 2 is an input the program refused (InputError, GuiderError; host/app/main.cpp); 1 is
    # any other exception and 3 an OpenCL failure, faults that a combination of options reached,
    # never a clean refusal.
    if result.returncode == 2:
        if not stderr or not stderr[-1].startswith("rtpg:"):
            return f"exit {result.returncode} without an 'rtpg:' message: {stderr[-1:]}"
        left = [str(p) for p in files.values() if p.exists()]
        if left:
            return f"refused ({stderr[-1]}) but left {left}"
        return None
    return f"exit status {result.returncode} (a signal if negative): {stderr[-3:]}"


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--runs", type=int, default=250)
    p.add_argument("--seed", type=int, default=3)
    p.add_argument("--binary", default=str(ROOT / "build" / "rtpg"))
    p.add_argument("--out", help="folder for the runs' files (default: a temporary one, removed)")
    p.add_argument("--scenes", nargs="+", choices=SCENES,
                   help="draw the scenes from these (default: the suite's, the large ones rarely)")
    a = p.parse_args()
    out = Path(a.out) if a.out else Path(tempfile.mkdtemp(prefix="rtpg-cli-sweep-"))
    out.mkdir(parents=True, exist_ok=True)
    r = random.Random(a.seed)
    failures, refusals = 0, 0
    for k in range(a.runs):
        args, files = draw(r, k, out, a.scenes)
        result = subprocess.run([a.binary, "render", *args], capture_output=True, text=True,
                                env=os.environ, timeout=600)
        problem = verdict(result, files, args)
        if result.returncode != 0 and problem is None:
            refusals += 1
        if problem:
            failures += 1
            print(f"run {k}: {problem}\n  {a.binary} render {' '.join(args)}", flush=True)
    print(f"{a.runs} runs (seed {a.seed}): {a.runs - failures - refusals} rendered, {refusals} "
          f"refused with a clear message, {failures} failed")
    if not a.out:
        shutil.rmtree(out, ignore_errors=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
