#!/usr/bin/env python3
"""Two runs of `bench/experiments.py --only denoised` compared frame by frame along each scene's
camera path: the denoised (and the noisy) sequence's flicker through the motion vectors
(`flicker_reprojected`, docs/design.md, "Metrics") of the second run over the first's, per method.

Both runs render the same noisy frames when only a denoiser setting differs (same seeds, same
renderer), so their frames' common noise cancels in the per-frame ratios; the experiment's own
standard errors, each run's alone, do not resolve such a difference (docs/denoising.md, "The rest
of the suite"):

    python3 bench/experiments.py --only denoised --scenes corridor --out build/svgf-base
    python3 bench/experiments.py --only denoised --scenes corridor --out build/svgf-other \\
        --svgf-args "--svgf-atrous-radius 1"
    python3 bench/paired_flicker.py build/svgf-base build/svgf-other

Each folder is searched for denoised/<scene>/path-<method>.json (the experiment's per-frame
statistics), so one --out folder per scene works too.
"""
import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from suite import metrics  # noqa: E402

METHODS = {"off": "PT+SVGF", "pmm": "PG+SVGF"}


def path_runs(folder):
    """{(scene, method): per-frame statistics file} of an experiment's --out folder."""
    runs = {}
    for f in sorted(Path(folder).rglob("path-*.json")):
        method = f.stem[len("path-"):]
        if f.parent.parent.name == "denoised" and method in METHODS:
            runs[(f.parent.name, method)] = f
    return runs


def per_frame(stats_file, key):
    """The statistic of every frame of a render's --stats-json, None where a frame has none (the
    first frame has no previous one to flicker against)."""
    try:
        frames = json.loads(Path(stats_file).read_text())["frames"]
    except (OSError, ValueError, KeyError) as e:
        raise SystemExit(f"{stats_file}: not a render's statistics ({e})")
    return [f.get(key) for f in frames]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("base", help="--out folder of the first run")
    ap.add_argument("other", help="--out folder of the second run")
    ap.add_argument("--key", default="flicker_reprojected",
                    help="per-frame statistic to compare (also flicker_reprojected_noisy, flicker_mse)")
    args = ap.parse_args()
    base, other = path_runs(args.base), path_runs(args.other)
    common = sorted(set(base) & set(other))
    if not common:
        raise SystemExit(f"no scene has a camera-path run in both {args.base} and {args.other}")
    print(f"| scene | method | {args.key}, first run | second run | ratio of means | "
          "mean per-frame ratio (s.e.) | frames higher |")
    print("|---|---|---|---|---|---|---|")
    for scene, method in common:
        a = per_frame(base[(scene, method)], args.key)
        b = per_frame(other[(scene, method)], args.key)
        if len(a) != len(b):
            raise SystemExit(f"{scene} {method}: {len(a)} frames against {len(b)}; not the same path")
        r = metrics.paired_ratio(a, b)
        print(f"| {scene} | {METHODS[method]} | {r['mean_base']:.4g} | {r['mean_other']:.4g} | "
              f"{r['ratio_of_means']:.3f} | "
              f"{r['mean_ratio']:.3f} ({r['sem']:.3f}) | {r['higher']}/{r['pairs']} |")


if __name__ == "__main__":
    main()
