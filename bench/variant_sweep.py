#!/usr/bin/env python3
"""Error of guiding variants against path tracing at equal frames, on many scenes and seeds: the
protocol of the variant tables in docs/guiding.md.

    python3 bench/variant_sweep.py --variants '{"default": [], "interval 2": ["--pg-train-interval", "2"]}'
    python3 bench/variant_sweep.py --variants '{"pi 0.1": ["--pg-pi-min", "0.1", "--pg-pi-max", "0.1"]}' --scenes cornell-box sponza

Per scene and seed: `rtpg render` of --frames 1-spp frames with --guiding off and with each variant's
extra arguments, against a cached reference (`rtpg reference`, --ref-spp, --ref-seed); the figure is
the mean relMSE of the last --window frames, PG/PT per seed, then the mean over seeds with the
standard error of that mean. Renders are cached in --out by scene, variant name and seed, keyed by
the variant's arguments, the size and frame count, and the binary (runner.binary_fingerprint: the
executable's bytes and any RTPG_KERNEL_DIR), so a rebuilt renderer or changed arguments render
again; references in --out/references by the renderer's source hash.
Prints a line per scene and variant and a Markdown table; writes --out/sweep.json.

With --camera-path every run follows the scene's first camera path (reprojection, history
rejection and the model's age under motion are exercised) and the figure is the mean relMSE of
the frames listed in --checkpoints against a reference of each of those frames (cached like the
static ones):

    python3 bench/variant_sweep.py --camera-path --checkpoints 23 31 --variants '{"default": []}'

--window equal to --frames gives the ratio of the errors summed over every frame, what the
equal-time experiment's accumulated image sees (docs/guiding.md, "How fast the guide learns"); --curve N
prints the ratio of each N-frame window, the guide's learning curve:

    python3 bench/variant_sweep.py --frames 128 --curve 8 --variants '{"default": []}' --scenes cornell-box
"""
import argparse
import hashlib
import json
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from suite import metrics, runner  # noqa: E402



def window_relmse(stats, window):
    """Mean relMSE of the last `window` frames of a run's statistics."""
    frames = stats["frames"][-window:]
    return statistics.fmean(f["relmse"] for f in frames)


def window_curve(pg_runs, pt_runs, n):
    """PG/PT of each consecutive n-frame window, the mean over seeds of each seed's ratio of the
    windows' summed relMSE."""
    frames = min(len(r["frames"]) for r in pg_runs + pt_runs)
    curve = []
    for start in range(0, frames - n + 1, n):
        ratios = [sum(f["relmse"] for f in pg["frames"][start:start + n]) /
                  sum(f["relmse"] for f in pt["frames"][start:start + n]) for pg, pt in zip(pg_runs, pt_runs)]
        curve.append((start + 1, start + n, statistics.fmean(ratios)))
    return curve


def markdown_table(scenes, table):
    """table[variant][scene] = (mean, se): a row per variant, the mean over scenes last."""
    lines = ["| variant | " + " | ".join(scenes) + " | mean |", "|---" * (len(scenes) + 2) + "|"]
    for name, row in table.items():
        cells = [f"{row[s][0]:.3f} ± {row[s][1]:.3f}" for s in scenes]
        mean = statistics.fmean(row[s][0] for s in scenes)
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {mean:.3f} |")
    return "\n".join(lines)


def cache_key(binary, scene, extra, res, frames, ref_spp, ref_seed):
    """The cache key of a run: what else decides it besides scene name, variant name and seed (the binary, the
    scene file's bytes, the arguments, the size, the frames, and the reference too: the cached figures are
    errors against it). 10 hex digits."""
    key = json.dumps([binary, runner.scene_file_hash(scene), [str(a) for a in extra], res, frames, ref_spp,
                      ref_seed])
    return hashlib.sha256(key.encode()).hexdigest()[:10]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--variants", required=True, help='JSON object: variant name -> list of extra rtpg arguments')
    parser.add_argument("--scenes", nargs="+", default=runner.SUITE_SCENES)
    parser.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    parser.add_argument("--res", default="240x135")
    parser.add_argument("--frames", type=int, default=32)
    parser.add_argument("--window", type=int, default=8,
                        help="last frames whose relMSE is averaged (--window equal to --frames: the "
                             "ratio of the summed per-frame errors, the accumulated image's error "
                             "ratio where frames are independent)")
    parser.add_argument("--curve", type=int, metavar="N",
                        help="also print PG/PT per consecutive N-frame window (mean over seeds): "
                             "how fast the guide learns")
    parser.add_argument("--ref-spp", type=int, default=1024)
    parser.add_argument("--ref-seed", type=int, default=777,
                        help="the references' seed (1000: those of the equal-time experiment)")
    parser.add_argument("--out", default=str(runner.ROOT / "build" / "variant-sweep"))
    parser.add_argument("--camera-path", action="store_true",
                        help="follow each scene's first camera path; the figure comes from --checkpoints")
    parser.add_argument("--checkpoints", nargs="+", type=int,
                        help="with --camera-path: 0-based frames compared with their own references "
                             "(default: the last --window frames)")
    args = parser.parse_args()
    variants = runner.parse_variants(parser, args.variants, '{"default": []}')
    if not 1 <= args.window <= args.frames:
        parser.error(f"--window {args.window} must be between 1 and --frames {args.frames}")
    if args.curve is not None and (args.camera_path or not 1 <= args.curve <= args.frames):
        parser.error("--curve N needs a static run (no --camera-path) and 1 <= N <= --frames")
    if args.checkpoints and not args.camera_path:
        parser.error("--checkpoints needs --camera-path")
    checkpoints = sorted(set(args.checkpoints or range(args.frames - args.window, args.frames)))
    if args.camera_path and not all(0 <= f < args.frames for f in checkpoints):
        parser.error(f"--checkpoints must be frames in [0, --frames {args.frames})")

    out = Path(args.out)
    refs = runner.ReferenceCache(out / "references")
    binary = runner.binary_fingerprint()

    def run_key(scene, extra, frames):
        return cache_key(binary, scene, extra, args.res, frames, args.ref_spp, args.ref_seed)

    def path_relmse(scene, tag, seed, guiding, extra):
        """Mean relMSE of the checkpoint frames along the scene's first camera path."""
        name = runner.first_camera_path(scene)
        if not name:
            raise SystemExit(f"variant_sweep.py: {runner.scene_path(scene)} has no camera path (--camera-path)")
        run_dir = out / scene
        run_tag = f"path-{tag}-{seed}-{run_key(scene, extra, max(checkpoints) + 1)}"
        cached = run_dir / f"{run_tag}.relmse.json"
        if cached.exists():
            figures = json.loads(cached.read_text())
            if figures["checkpoints"] == checkpoints and figures["camera_path"] == name:
                return figures["relmse"]
        _, image = runner.render(scene, args.res, max(checkpoints) + 1, guiding, run_dir, run_tag,
                                 extra=["--seed", seed, "--camera-path", name, "--save-frames",
                                        ",".join(map(str, checkpoints)), *extra])
        errors = [metrics.relmse(metrics.load_exr(runner.saved_frame(image, f)),
                                 metrics.load_exr(refs.get(scene, args.res, args.ref_spp, seed=args.ref_seed, camera_path=name,
                                                           frame=f)))
                  for f in checkpoints]
        value = statistics.fmean(errors)
        cached.write_text(json.dumps({"camera_path": name, "checkpoints": checkpoints, "relmse_per_checkpoint": errors,
                                      "relmse": value}) + "\n")
        return value

    def static_stats(scene, tag, seed, guiding, extra):
        reference = refs.get(scene, args.res, args.ref_spp, seed=args.ref_seed)
        run_dir = out / scene
        run_tag = f"{tag}-{seed}-{run_key(scene, extra, args.frames)}"
        cached = run_dir / f"{run_tag}.json"
        if cached.exists():
            return json.loads(cached.read_text())
        stats, _ = runner.render(scene, args.res, args.frames, guiding, run_dir, run_tag, reference=reference,
                                 extra=["--seed", seed, *extra])
        return stats

    def relmse(scene, tag, seed, guiding, extra):
        if args.camera_path:
            return path_relmse(scene, tag, seed, guiding, extra)
        return window_relmse(static_stats(scene, tag, seed, guiding, extra), args.window)

    table = {name: {} for name in variants}
    for scene in args.scenes:
        pt = [relmse(scene, "pt", s, "off", []) for s in args.seeds]
        for name, extra in variants.items():
            tag = "pg-" + "".join(c if c.isalnum() else "_" for c in name)
            pg = [relmse(scene, tag, s, "pmm", extra) for s in args.seeds]
            table[name][scene] = runner.mean_sem([a / b for a, b in zip(pg, pt)])
            m, se = table[name][scene]
            print(f"{scene:18s} {name:24s} PT {statistics.fmean(pt):.4g}  PG/PT {m:.3f} ± {se:.3f}", flush=True)
            if args.curve:
                curve = window_curve([static_stats(scene, tag, s, "pmm", extra) for s in args.seeds],
                                     [static_stats(scene, "pt", s, "off", []) for s in args.seeds], args.curve)
                print(f"{'':18s} {'':24s} " + " ".join(f"{a}-{b}: {r:.3f}" for a, b, r in curve), flush=True)
    print(markdown_table(args.scenes, table))
    (out / "sweep.json").write_text(json.dumps({"settings": vars(args), "table": table}, indent=1) + "\n")


if __name__ == "__main__":
    main()
