#!/usr/bin/env python3
"""Where a 1-spp pixel's error comes from, for path tracing and for guiding: the split of the
relMSE into what the frame fixes (the camera ray's jitter), the first bounce's direction, the
next-event estimate at the primary hit, and the rest of the path (docs/guiding.md, "Where the
variance is").

    python3 bench/variance_split.py --out build/variance-split
    python3 bench/variance_split.py --scenes cornell-box --variants '{"PG": [], "pi 0.95": ["--pg-pi-max", "0.95"]}'

Per scene, seed and method (PT: --guiding off; each variant: --guiding pmm with its extra
arguments, by default one variant, PG, with none), five renders of --frames frames against the
cached reference (`rtpg reference`, --ref-spp, seed 777; the protocol of bench/variant_sweep.py),
each figure the mean relMSE of the last --window frames:

    t  1 spp                                                  = P + D + N + Y + R
    a  M spp, every sample its own                            = P + (D + N + Y + R) / M
    b  M spp, the first bounce shared (--share-randoms first-bounce)    = P + D + (N + Y + R) / M
    c  M spp, the primary vertex shared (primary-vertex)      = P + D + N + (Y + R) / M
    d  M spp, the first bounce's hit y shared (second-vertex) = P + D + N + Y + R / M

P is what a frame's samples share anyway (the camera ray is jittered once a frame; the
reference's own error adds here too), D the first-bounce direction's part (what first-bounce
guiding changes), N the next-event estimate at the primary hit, Y the light sample and bounce at
y (the radiance estimate at the VPL's vertex, one bounce deep), R the rest of the path. relMSE is
a mean of per-pixel squared errors, so the parts add: with k = 1 - 1/M, D = (b - a) / k,
N = (c - b) / k, Y = (d - c) / k, R = (t - d) / k, P = t - D - N - Y - R. Sample 0 draws as the
renderer does in every mode (tests/render/test_shared_randoms.cpp), so the five renders of a
seed share it, PG's model is the same in all five (training reads sample 0's VPLs), and their
differences carry little noise of their own.

Prints a line per scene and method and a Markdown table of the parts as shares of PT's 1-spp
relMSE (a row per scene and method), with the standard error over seeds; writes
--out/split.json.
"""
import argparse
import hashlib
import json
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from suite import runner  # noqa: E402

RUNS = {  # name -> (spp multiplier: 1 or M, --share-randoms)
    "t": (False, "none"),
    "a": (True, "none"),
    "b": (True, "first-bounce"),
    "c": (True, "primary-vertex"),
    "d": (True, "second-vertex"),
}
PARTS = ["P", "D", "N", "Y", "R"]


def split(f, m):
    """The five parts from the five figures f[run] (module docstring)."""
    k = 1.0 - 1.0 / m
    d, n, y, r = (f["b"] - f["a"]) / k, (f["c"] - f["b"]) / k, (f["d"] - f["c"]) / k, (f["t"] - f["d"]) / k
    return {"P": f["t"] - d - n - y - r, "D": d, "N": n, "Y": y, "R": r}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenes", nargs="+", default=runner.SUITE_SCENES)
    parser.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    parser.add_argument("--res", default="240x135")
    parser.add_argument("--frames", type=int, default=32)
    parser.add_argument("--window", type=int, default=8, help="last frames whose relMSE is averaged")
    parser.add_argument("--spp", type=int, default=8, help="M, the samples of the three M-spp renders")
    parser.add_argument("--ref-spp", type=int, default=1024)
    parser.add_argument("--out", default=str(runner.ROOT / "build" / "variance-split"))
    parser.add_argument("--variants", default='{"PG": []}',
                        help="JSON object: guided variant name -> list of extra rtpg arguments")
    args = parser.parse_args()
    variants = runner.parse_variants(parser, args.variants, '{"PG": []}')
    # Method name -> (--guiding, extra arguments, cache tag); "PG" keeps the tag "pg".
    methods = {"PT": ("off", [], "pt")}
    for name, extra in variants.items():
        if name == "PT":
            parser.error('--variants: "PT" names path tracing')
        tag = "pg" if name == "PG" and not extra else "pg-" + "".join(c if c.isalnum() else "_" for c in name)
        methods[name] = ("pmm", [str(e) for e in extra], tag)
    if args.spp < 2:
        parser.error("--spp must be at least 2")
    if not 1 <= args.window <= args.frames:
        parser.error(f"--window {args.window} must be between 1 and --frames {args.frames}")

    out = Path(args.out)
    refs = runner.ReferenceCache(out / "references")
    binary = runner.binary_fingerprint()

    def figure(scene, method, run, seed):
        guiding, extra, tag_prefix = methods[method]
        many, shared = RUNS[run]
        spp = args.spp if many else 1
        # The cached run's key holds what else decides its figures: the binary, the scene file's
        # bytes, the variant's arguments, the size, the frames and the reference they are errors
        # against.
        key = json.dumps([binary, runner.scene_file_hash(scene), guiding, extra, args.res, args.frames,
                          args.ref_spp])
        tag = f"{tag_prefix}-{run}-{spp}spp-{seed}-{hashlib.sha256(key.encode()).hexdigest()[:10]}"
        cached = out / scene / f"{tag}.json"
        if cached.exists():
            stats = json.loads(cached.read_text())
        else:
            reference = refs.get(scene, args.res, args.ref_spp, seed=777)
            stats, _ = runner.render(scene, args.res, args.frames, guiding, out / scene, tag, reference=reference,
                                     extra=["--seed", seed, "--spp", spp, "--share-randoms", shared, *extra])
        return statistics.fmean(f["relmse"] for f in stats["frames"][-args.window:])

    results = {}
    for scene in args.scenes:
        per_seed = {m: [] for m in methods}
        for seed in args.seeds:
            for method in methods:
                f = {run: figure(scene, method, run, seed) for run in RUNS}
                per_seed[method].append({"figures": f, "parts": split(f, args.spp)})
        # Shares of PT's 1-spp relMSE, per seed, then mean and standard error over seeds.
        shares = {}
        for method, seeds in per_seed.items():
            shares[method] = {
                part: runner.mean_sem([(s["parts"][part] if part != "t" else s["figures"]["t"]) / p["figures"]["t"]
                                       for s, p in zip(seeds, per_seed["PT"])])
                for part in PARTS + ["t"]}
        results[scene] = {"per_seed": per_seed, "shares": shares}
        pt_t = statistics.fmean(s["figures"]["t"] for s in per_seed["PT"])
        for method in methods:
            print(f"{scene:18s} {method:12s} (PT relMSE {pt_t:.4g}) " +
                  " ".join(f"{p} {shares[method][p][0]:.3f}" for p in PARTS + ["t"]), flush=True)

    header = ["scene", "method", "P (jitter)", "D (first bounce)", "N (light at x0)", "Y (vertex y)", "R (rest)",
              "total"]
    lines = ["| " + " | ".join(header) + " |", "|---" * len(header) + "|"]
    for scene, r in results.items():
        for method, parts in r["shares"].items():
            cells = [f"{parts[p][0]:.3f} ± {parts[p][1]:.3f}" for p in PARTS + ["t"]]
            lines.append(f"| {scene} | {method} | " + " | ".join(cells) + " |")
    print("\n".join(lines))
    (out / "split.json").write_text(json.dumps({"settings": vars(args), "results": results}, indent=1) + "\n")


if __name__ == "__main__":
    main()
