#!/usr/bin/env python3
"""SVGF's time against its error: PT+SVGF at 1 spp after T frames (static camera) for variants of
the denoiser's settings, LDR-FLIP and relMSE of the last frame against the suite's reference, and
the denoiser's median time per frame (docs/denoising.md, "Cost").

    python3 bench/svgf_tradeoffs.py                                  # cornell-box and sponza, 960x540
    python3 bench/svgf_tradeoffs.py --scenes cornell-box --frames 16
    python3 bench/svgf_tradeoffs.py --variants "defaults (5 iterations)" "3x3 kernel (5 iterations)"

References come from the suite's cache (bench/experiments.py --out, default build/bench-results):
a full run of the suite leaves them there; a missing one is rendered (1024 spp, minutes).
"""
import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from suite import metrics, runner  # noqa: E402

VARIANTS = {
    "defaults (5 iterations)": [],
    "4 iterations": ["--svgf-iterations", 4],
    "3 iterations": ["--svgf-iterations", 3],
    "2 iterations": ["--svgf-iterations", 2],
    "one pixel per work-item": ["--svgf-lanes", 1],
    "3x3 kernel (5 iterations)": ["--svgf-atrous-radius", 1, "--svgf-history-atrous-radius", 1],
    "3x3 kernel, 6 iterations": ["--svgf-atrous-radius", 1, "--svgf-history-atrous-radius", 1,
                                 "--svgf-iterations", 6],
    "5x5 up to the history, 3x3 after": ["--svgf-atrous-radius", 1],
}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", nargs="*", default=["cornell-box", "sponza"])
    ap.add_argument("--res", default="960x540")
    ap.add_argument("--frames", type=int, default=32)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--out", default=str(runner.ROOT / "build" / "bench-results"))
    ap.add_argument("--variants", nargs="*", default=list(VARIANTS), choices=list(VARIANTS),
                    help="which variants to run (default all)")
    args = ap.parse_args()
    out = Path(args.out)
    refs = runner.ReferenceCache(out / "references")
    results = {"machine": runner.machine_info(), "res": args.res, "frames": args.frames, "scenes": {}}
    lines = ["| scene | variant | SVGF ms | a-trous ms | PT frame ms | SVGF / PT | LDR-FLIP | relMSE |",
             "|---|---|---|---|---|---|---|---|"]
    for scene in args.scenes:
        ref = metrics.load_exr(refs.get(scene, args.res, args.ref_spp))
        exposure = runner.scene_exposure(scene)
        rows = {}
        for k, (name, flags) in enumerate(VARIANTS.items()):
            if name not in args.variants:
                continue
            stats, image = runner.render(scene, args.res, args.frames, "off", out / "svgf-tradeoffs" / scene,
                                         f"v{k}", extra=["--denoise", "svgf", *flags])
            img = metrics.load_exr(image)
            svgf = runner.median_frame_ms(stats, "svgf_total")
            pt = runner.median_frame_ms(stats) - svgf
            rows[name] = {"flags": [str(f) for f in flags], "svgf_ms": svgf,
                          "atrous_ms": runner.median_frame_ms(stats, "svgf_atrous"),
                          "pt_frame_ms": pt, "flip_ldr": metrics.flip_ldr(img, ref, exposure), "relmse": metrics.relmse(img, ref)}
            r = rows[name]
            lines.append(f"| {scene} | {name} | {r['svgf_ms']:.1f} | {r['atrous_ms']:.1f} | {pt:.0f} "
                         f"| {svgf / pt:.2f} | {r['flip_ldr']:.4f} | {r['relmse']:.4g} |")
            print(lines[-1], flush=True)
        results["scenes"][scene] = rows
    (out / "svgf-tradeoffs.json").write_text(json.dumps(results, indent=2))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
