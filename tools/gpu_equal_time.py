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
        [--frames 32] [--repeats 4] [--ref-spp 1024] [--pg-args "ARGS"] [--references-only]
--pg-args adds rtpg arguments to the guided runs alone (a variant of guiding against the same path
tracing, say "--guide-vertices world"). --references-only makes the references in OUT/references
and stops: references take minutes of host time, which a CPU machine can spend instead of the GPU
machine's lease (tools/gpu_equal_time.sh copies them there; they are keyed by the renderer's
sources, so they are found only for the same sources).
"""
import argparse
import json
import shlex
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
    parser.add_argument("--repeats", type=int, default=4,
                        help="even: each order of the pair of runs as often (equal_time.method_order)")
    parser.add_argument("--ref-spp", type=int, default=1024)
    parser.add_argument("--pg-args", default="", help="more rtpg arguments for the guided runs only")
    parser.add_argument("--references-only", action="store_true")
    args = parser.parse_args()
    references = runner.ReferenceCache(args.out / "references")
    if args.references_only:
        for scene in args.scenes:
            print(scene, references.get(scene, args.res, args.ref_spp), flush=True)
        return
    pg_extra = shlex.split(args.pg_args)
    results = {"settings": {"res": args.res, "frames": args.frames, "repeats": args.repeats,
                            "ref_spp": args.ref_spp, "pg_args": pg_extra, "machine": runner.machine_info()},
               "scenes": {}}
    print("| scene | PT time | PG time / PT | accumulated relMSE PG / PT at PT's time "
          "| PG's time to PT's final error |\n|---|---|---|---|---|", flush=True)
    for scene in args.scenes:
        reference = references.get(scene, args.res, args.ref_spp)
        curves = equal_time.runs(scene, args.res, args.frames, args.repeats, args.out / scene, reference,
                                 pg_extra=pg_extra)
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
