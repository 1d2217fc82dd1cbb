#!/usr/bin/env python3
"""SVGF's history fallback (docs/denoising.md, "History from the neighbourhood"): PT+SVGF and
PG+SVGF with `--svgf-history-fallback` 1 (the default: where no bilinear tap of last frame shows
the pixel's surface, the same-surface pixels of the 3x3 around it) and 0 (the history restarts
there). Static camera at --res, the camera's sub-pixel jitter on (the default): relMSE of the
denoised frames T-7..T against the suite's reference (mean and standard error), LDR-FLIP of frame
T at the scene's exposure, and the flicker of frames T-8..T: the mean squared change of the
tonemapped (PNG) image from one frame to the next, at the scene's exposure. On radiance
(`flicker_mse` in the stats) the jitter's aliasing at the emitters' edges outweighs everything
else (the same to four digits for every variant on the Cornell box), and along a camera path the
picture's motion does, so the flicker is taken after the tonemap, and the camera paths are not
run.

    python3 bench/svgf_history.py --out build/bench-results   # cornell-box, veach-ajar, sponza

References come from the suite's cache (bench/experiments.py --out): a missing one is rendered
(1024 spp, minutes).
"""
import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from suite import metrics, runner  # noqa: E402

VARIANTS = {"fallback": ["--svgf-history-fallback", 1], "no fallback": ["--svgf-history-fallback", 0]}
METHODS = {"PT": "off", "PG": "pmm"}
LAST = 8


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", nargs="*", default=["cornell-box", "veach-ajar", "sponza"])
    ap.add_argument("--res", default="960x540")
    ap.add_argument("--frames", type=int, default=32)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--out", default=str(runner.ROOT / "build" / "bench-results"))
    args = ap.parse_args()
    out = Path(args.out)
    refs = runner.ReferenceCache(out / "references")
    T = args.frames
    results = {"machine": runner.machine_info(), "res": args.res, "frames": T, "scenes": {}}
    lines = ["| scene | method | variant | relMSE frames T-7..T | LDR-FLIP frame T | flicker frames T-7..T | SVGF ms |",
             "|---|---|---|---|---|---|---|"]
    for scene in args.scenes:
        ref_path = refs.get(scene, args.res, args.ref_spp)
        ref = metrics.load_exr(ref_path)
        exposure = runner.scene_exposure(scene)
        rows = {}
        for method, guiding in METHODS.items():
            for name, flags in VARIANTS.items():
                tag = f"{method}-{name.replace(' ', '-')}"
                folder = out / "svgf-history" / scene
                saved = list(range(T - LAST - 1, T))
                stats, image = runner.render(scene, args.res, T, guiding, folder, tag, reference=ref_path,
                                             extra=["--denoise", "svgf", *flags,
                                                    "--save-frames", ",".join(map(str, saved))])
                rel, rel_sem = runner.mean_sem(f["relmse"] for f in stats["frames"][T - LAST:T])
                shown = [metrics.tonemap_srgb(metrics.load_exr(runner.saved_frame(image, f)), exposure)
                         for f in saved]
                flicker, flicker_sem = runner.mean_sem(float(((a.astype("float64") - b) ** 2).mean())
                                                       for a, b in zip(shown[1:], shown[:-1]))
                row = {"flags": [str(f) for f in flags], "relmse_last8": rel, "relmse_last8_sem": rel_sem,
                       "flicker_last8": flicker, "flicker_last8_sem": flicker_sem,
                       "flip_ldr": metrics.flip_ldr(metrics.load_exr(image), ref, exposure),
                       "svgf_ms": runner.median_frame_ms(stats, "svgf_total")}
                rows[f"{method} {name}"] = row
                lines.append(f"| {scene} | {method}+SVGF | {name} | {rel:.4g} ± {rel_sem:.2g} | {row['flip_ldr']:.4f} "
                             f"| {flicker:.4g} ± {flicker_sem:.2g} | {row['svgf_ms']:.1f} |")
                print(lines[-1], flush=True)
        results["scenes"][scene] = rows
    (out / "svgf-history.json").write_text(json.dumps(results, indent=2))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
