#!/usr/bin/env python3
"""Equal time, path tracing against path guiding, where no Python package can be installed: the
machines with a GPU have the renderer's bundle (tools/gpu_bundle.sh --renderer) and a bare Python.
The same experiment as `bench/experiments.py --only equal_time` (bench/suite/equal_time.py: PT and
PG alternating run by run, accumulated frames against a reference, every figure read off each
run's curve, medians over the runs), without its plots: per scene, a reference (`rtpg reference`,
cached by the renderer's sources as the suite caches them), then the runs, then a Markdown table
on stdout and everything in OUT/results.json.

Run from the repository's root (the scenes and bench/suite are read from there), with RTPG_BINARY
the bundle's rtpg and the bundle's environment (LD_LIBRARY_PATH, OCL_ICD_VENDORS, RTPG_DEVICE):
    RTPG_BINARY=DIR/bin/rtpg python3 tools/gpu_equal_time.py --out OUT [--scenes ...] [--res WxH]
        [--frames 32] [--repeats 3] [--ref-spp 1024]
"""
import argparse
import json
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "bench"))
from suite import equal_time, runner  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, type=Path)
    parser.add_argument("--scenes", nargs="+", default=["cornell-box", "sunlit-room", "cornell-glossy"])
    parser.add_argument("--res", default="960x540")
    parser.add_argument("--frames", type=int, default=32)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--ref-spp", type=int, default=1024)
    args = parser.parse_args()
    references = runner.ReferenceCache(args.out / "references")
    results = {"settings": {"res": args.res, "frames": args.frames, "repeats": args.repeats,
                            "ref_spp": args.ref_spp, "machine": runner.machine_info()}, "scenes": {}}
    print("| scene | PT time | PG time / PT | accumulated relMSE PG / PT at PT's time "
          "| PG's time to PT's final error |\n|---|---|---|---|---|", flush=True)
    for scene in args.scenes:
        reference = references.get(scene, args.res, args.ref_spp)
        curves = equal_time.runs(scene, args.res, args.frames, args.repeats, args.out / scene, reference)
        figures = equal_time.figures_of(curves)
        pg_time = statistics.median(r["time_ms"][-1] for r in curves["pmm"]["runs"])
        at_budget = figures["relmse_at_pt_budget"]
        error_ratio = (at_budget["pmm"] / at_budget["off"] if isinstance(at_budget["pmm"], float)
                       else at_budget["pmm"])
        ratio = figures["time_ratio_pg_pt"]
        print(f"| {scene} | {figures['pt_time_ms'] / 1000:.2f} s | {pg_time / figures['pt_time_ms']:.3f} | "
              f"{error_ratio if isinstance(error_ratio, str) else format(error_ratio, '.3f')} | "
              f"{ratio if isinstance(ratio, str) else format(ratio, '.3f') + 'x'} |", flush=True)
        results["scenes"][scene] = {"curves": curves, **figures}
    results["references"] = list(references.timings.values())
    (args.out / "results.json").write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
