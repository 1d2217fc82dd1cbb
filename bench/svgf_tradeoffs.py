#!/usr/bin/env python3
"""SVGF's time against its error: PT+SVGF (and with --methods off pmm, PG+SVGF) at 1 spp after T
frames (static camera) for variants of the denoiser's settings, LDR-FLIP and relMSE of the last
frame against the suite's reference, the mean relMSE of the last 8 frames with its standard error,
and the denoiser's median time per frame (docs/denoising.md, "Cost", "The filter's strength").

    python3 bench/svgf_tradeoffs.py                                  # cornell-box and sponza, 960x540
    python3 bench/svgf_tradeoffs.py --scenes cornell-box --frames 16
    python3 bench/svgf_tradeoffs.py --variants "defaults (5 iterations)" "3x3 kernel (5 iterations)"
    python3 bench/svgf_tradeoffs.py --methods off pmm --variants "defaults (5 iterations)" "phi_l 2"

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
    # The filter's strength: the luminance edge-stop's scale (SVGF's sigma_l, 4) and the temporal
    # blend weights (0.2).
    "phi_l 1": ["--svgf-phi-luminance", 1],
    "phi_l 2": ["--svgf-phi-luminance", 2],
    "phi_l 8": ["--svgf-phi-luminance", 8],
    "alpha 0.1": ["--svgf-alpha-colour", 0.1, "--svgf-alpha-moments", 0.1],
    "alpha 0.05": ["--svgf-alpha-colour", 0.05, "--svgf-alpha-moments", 0.05],
    "phi_l 2, alpha 0.1": ["--svgf-phi-luminance", 2, "--svgf-alpha-colour", 0.1,
                           "--svgf-alpha-moments", 0.1],
    # The depth weight's slope from the pixel's plane instead of its jittered neighbours' depths
    # (docs/denoising.md, "Where we deviate").
    "plane slope": ["--svgf-depth-slope-from-normal", 1],
}
LAST = 8  # frames whose relMSE is averaged (bench/experiments.py's final_frame_metrics)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", nargs="*", default=["cornell-box", "sponza"])
    ap.add_argument("--res", default="960x540")
    ap.add_argument("--frames", type=int, default=32)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--out", default=str(runner.ROOT / "build" / "bench-results"))
    ap.add_argument("--variants", nargs="*", default=list(VARIANTS), choices=list(VARIANTS),
                    help="which variants to run (default all)")
    ap.add_argument("--methods", nargs="*", default=["off"], choices=list(runner.METHODS),
                    help="off: PT+SVGF (default); pmm: PG+SVGF; both: the ratio PG/PT too")
    args = ap.parse_args()
    out = Path(args.out)
    refs = runner.ReferenceCache(out / "references")
    results = {"machine": runner.machine_info(), "res": args.res, "frames": args.frames, "scenes": {}}
    lines = ["| scene | variant | method | SVGF ms | a-trous ms | frame ms without SVGF | SVGF / frame "
             "| LDR-FLIP | relMSE | relMSE, last 8 (± s.e.) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for scene in args.scenes:
        ref_path = refs.get(scene, args.res, args.ref_spp)
        ref = metrics.load_exr(ref_path)
        exposure = runner.scene_exposure(scene)
        rows = {}
        for k, (name, flags) in enumerate(VARIANTS.items()):
            if name not in args.variants:
                continue
            rows[name] = {"flags": [str(f) for f in flags]}
            for method in args.methods:
                stats, image = runner.render(scene, args.res, args.frames, method,
                                             out / "svgf-tradeoffs" / scene, f"v{k}-{method}",
                                             reference=ref_path,
                                             extra=["--denoise", "svgf", *flags])
                img = metrics.load_exr(image)
                svgf = runner.median_frame_ms(stats, "svgf_total")
                frame = runner.median_frame_ms(stats) - svgf
                mean, sem = runner.mean_sem(f["relmse"] for f in stats["frames"][-LAST:])
                r = rows[name][method] = {
                    "svgf_ms": svgf, "atrous_ms": runner.median_frame_ms(stats, "svgf_atrous"),
                    "frame_ms": frame, "flip_ldr": metrics.flip_ldr(img, ref, exposure),
                    "relmse": metrics.relmse(img, ref), "relmse_last8": mean, "relmse_last8_sem": sem}
                lines.append(f"| {scene} | {name} | {method} | {r['svgf_ms']:.1f} | {r['atrous_ms']:.1f} "
                             f"| {frame:.0f} | {svgf / frame:.2f} | {r['flip_ldr']:.4f} | {r['relmse']:.4g} "
                             f"| {mean:.4g} ± {sem:.2g} |")
                print(lines[-1], flush=True)
            if "off" in rows[name] and "pmm" in rows[name]:
                pt, pg = rows[name]["off"], rows[name]["pmm"]
                rows[name]["pg_over_pt"] = {"flip_ldr": pg["flip_ldr"] / pt["flip_ldr"],
                                            "relmse_last8": pg["relmse_last8"] / pt["relmse_last8"]}
                q = rows[name]["pg_over_pt"]
                lines.append(f"| {scene} | {name} | PG/PT | | | | | {q['flip_ldr']:.3f} | "
                             f"| {q['relmse_last8']:.3f} |")
                print(lines[-1], flush=True)
        results["scenes"][scene] = rows
    (out / "svgf-tradeoffs.json").write_text(json.dumps(results, indent=2))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
