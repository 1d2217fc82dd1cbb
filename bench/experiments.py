#!/usr/bin/env python3
"""rtpg benchmark suite: run time against error for plain path tracing (PT) and PMM path
guiding (PG), with official FLIP, plots and a Markdown report.

    python3 bench/experiments.py --quick            # CI-sized check of the pipeline (< 5 min)
    python3 bench/experiments.py                    # full run (540p, 1024-spp references): hours
    python3 bench/experiments.py --only equal_frame convergence --scenes cornell-indirect

Every experiment writes JSON (machine, commit, settings, every figure) and PNG plots into
--out (default: build/bench-results); the report goes to --report (default docs/results/ for a
full run, <out>/report for --quick).
"""
import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from suite import metrics, runner  # noqa: E402

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ALL_SCENES = ["cornell-box", "cornell-indirect", "cornell-glossy", "veach-ajar", "sponza", "sponza-glossy",
              "sponza-sky"]

MODES = {
    "quick": dict(res="48x32", ref_spp=64, frames=8, sweep=[2, 8], time_frames=6, repeats=2, conv_frames=8,
                  path_frames=[0, 4], path_ref_spp=32, trade_res="48x32", trade_frames=8,
                  scenes=["cornell-box", "cornell-indirect"]),
    "full": dict(res="960x540", ref_spp=1024, frames=32, sweep=[1, 4, 8, 16, 32, 64], time_frames=48, repeats=3,
                 conv_frames=64, path_frames=[0, 15, 30, 45, 59], path_ref_spp=256, trade_res="480x270",
                 trade_frames=32, scenes=ALL_SCENES),
}


def available(scene):
    """A scene whose assets are missing is skipped with a message, not failed."""
    if not Path(runner.scene_path(scene)).exists():
        return False, "no scene file"
    try:
        runner.run(["info", runner.scene_path(scene)])
        return True, ""
    except RuntimeError as e:
        return False, str(e).splitlines()[-1]


def last_frames_error(stats, key="relmse", count=8):
    values = [f[key] for f in stats["frames"] if key in f]
    return statistics.mean(values[-count:]) if values else float("nan")


def median_time(stats, key="total"):
    return statistics.median(f["time_ms"].get(key, 0.0) for f in stats["frames"][1:] or stats["frames"])


def crop_box(err_map, size):
    """A square crop centred on the region where PT's error is largest (smoothed)."""
    h, w = err_map.shape
    s = min(size, h, w)
    k = max(1, s // 2)
    cs = np.cumsum(np.cumsum(np.pad(err_map, ((1, 0), (1, 0))), 0), 1)
    best, at = -1.0, (0, 0)
    for y in range(0, h - k + 1, max(1, k // 4)):
        for x in range(0, w - k + 1, max(1, k // 4)):
            v = cs[y + k, x + k] - cs[y, x + k] - cs[y + k, x] + cs[y, x]
            if v > best:
                best, at = v, (y, x)
    y0 = int(np.clip(at[0] + k // 2 - s // 2, 0, h - s))
    x0 = int(np.clip(at[1] + k // 2 - s // 2, 0, w - s))
    return y0, x0, s


def equal_frame(ctx, scene):
    """PT vs PG at 1 spp after T training frames, FLIP and relMSE, images with zoomed crops."""
    m = ctx.mode
    ref_path = ctx.refs.get(scene, m["res"], m["ref_spp"])
    ref = metrics.load_exr(ref_path)
    out = ctx.out / "equal_frame" / scene
    result = {"scene": scene, "reference": str(ref_path), "T": m["frames"], "methods": {}, "sweep": {}}
    images = {}
    for method in ("off", "pmm"):
        stats, img_path = runner.render(scene, m["res"], m["frames"], method, out, f"{method}-T{m['frames']}",
                                        reference=ref_path)
        img = metrics.load_exr(img_path)
        images[method] = img
        result["methods"][method] = {
            "relmse": metrics.relmse(img, ref), "relmse_last8": last_frames_error(stats),
            "flip_ldr": metrics.flip_ldr(img, ref), "flip_hdr": metrics.flip_hdr(img, ref),
            "frame_ms": median_time(stats), "nonfinite": sum(f["nonfinite_samples"] for f in stats["frames"]),
            "time_ms": {k: statistics.median(f["time_ms"].get(k, 0.0) for f in stats["frames"][1:])
                        for k in stats["frames"][-1]["time_ms"]},
        }
    for t in m["sweep"]:
        row = {}
        for method in ("off", "pmm"):
            stats, img_path = runner.render(scene, m["res"], t, method, out, f"{method}-T{t}", reference=ref_path)
            img = metrics.load_exr(img_path)
            row[method] = {"relmse": metrics.relmse(img, ref), "flip_ldr": metrics.flip_ldr(img, ref)}
        result["sweep"][str(t)] = row
    # Figure: reference, PT, PG, each with a zoomed crop where PT's error is largest.
    err = np.mean((images["off"] - ref) ** 2 / (ref ** 2 + 0.01), axis=2)
    y0, x0, s = crop_box(err, max(16, min(ref.shape[:2]) // 3))
    fig, axes = plt.subplots(2, 3, figsize=(9, 6))
    for col, (name, img) in enumerate((("Reference", ref), ("PT 1 spp", images["off"]), ("PG 1 spp", images["pmm"]))):
        tm = metrics.tonemap_srgb(img)
        axes[0, col].imshow(tm)
        axes[0, col].add_patch(plt.Rectangle((x0, y0), s, s, fill=False, color="cyan"))
        label = name if col == 0 else f"{name}  FLIP {result['methods']['off' if col == 1 else 'pmm']['flip_ldr']:.3f}"
        axes[0, col].set_title(label, fontsize=9)
        axes[1, col].imshow(tm[y0:y0 + s, x0:x0 + s], interpolation="nearest")
        for a in axes[:, col]:
            a.axis("off")
    fig.suptitle(f"{scene}: 1 spp after {m['frames']} frames")
    fig.tight_layout()
    fig.savefig(out / "comparison.png", dpi=100)
    plt.close(fig)
    result["figure"] = str(out / "comparison.png")
    return result


def equal_time(ctx, scene):
    """Error of the accumulated image against cumulative wall time, both methods, same run."""
    m = ctx.mode
    ref_path = ctx.refs.get(scene, m["res"], m["ref_spp"])
    out = ctx.out / "equal_time" / scene
    curves = {}
    for method in ("off", "pmm"):
        runs = []
        for r in range(m["repeats"]):
            stats, _ = runner.render(scene, m["res"], m["time_frames"], method, out, f"{method}-r{r}",
                                     reference=ref_path, extra=["--accumulate", "--seed", 100 + r])
            t = np.cumsum([f["time_ms"]["total"] for f in stats["frames"]])
            e = [f["relmse_accumulated"] for f in stats["frames"]]
            runs.append((t, e))
        t_med = np.median([r[0] for r in runs], axis=0)
        e_med = np.median([r[1] for r in runs], axis=0)
        curves[method] = {"time_ms": t_med.tolist(), "relmse": e_med.tolist()}
    fig, ax = plt.subplots(figsize=(5, 4))
    for method, c in curves.items():
        ax.loglog(c["time_ms"], c["relmse"], label="PT" if method == "off" else "PG")
    ax.set_xlabel("wall time (ms, cumulative)")
    ax.set_ylabel("relMSE of the accumulated image")
    ax.set_title(f"{scene}: equal time")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "equal_time.png", dpi=100)
    plt.close(fig)
    # Error each method reaches at the time budget PT needs for all its frames.
    budget = curves["off"]["time_ms"][-1]
    at_budget = {k: float(np.interp(budget, c["time_ms"], c["relmse"])) for k, c in curves.items()}
    return {"scene": scene, "curves": curves, "relmse_at_pt_budget": at_budget, "figure": str(out / "equal_time.png")}


def convergence(ctx, scene):
    """relMSE of the 1-spp frame against frame index: static camera, and along the camera path."""
    m = ctx.mode
    ref_path = ctx.refs.get(scene, m["res"], m["ref_spp"])
    out = ctx.out / "convergence" / scene
    result = {"scene": scene, "static": {}, "path": {}}
    for method in ("off", "pmm"):
        stats, _ = runner.render(scene, m["res"], m["conv_frames"], method, out, f"static-{method}", reference=ref_path)
        result["static"][method] = [f["relmse"] for f in stats["frames"]]
    paths = json.loads(Path(runner.scene_path(scene)).read_text()).get("camera_paths", {})
    if paths:
        name = sorted(paths)[0]
        result["path_name"] = name
        for method in ("off", "pmm"):
            errors = []
            for frame in m["path_frames"]:
                ref = ctx.refs.get(scene, m["res"], m["path_ref_spp"], camera_path=name, frame=frame)
                stats, _ = runner.render(scene, m["res"], frame + 1, method, out, f"path-{method}-{frame}",
                                         reference=ref, extra=["--camera-path", name])
                errors.append(stats["frames"][-1]["relmse"])
            result["path"][method] = {"frames": m["path_frames"], "relmse": errors}
    fig, ax = plt.subplots(figsize=(5, 4))
    for method, e in result["static"].items():
        ax.semilogy(e, label=("PT" if method == "off" else "PG") + " static")
    for method, p in result["path"].items():
        ax.semilogy(p["frames"], p["relmse"], "o--", label=("PT" if method == "off" else "PG") + " camera path")
    ax.set_xlabel("frame")
    ax.set_ylabel("relMSE of the 1-spp frame")
    ax.set_title(f"{scene}: convergence")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "convergence.png", dpi=100)
    plt.close(fig)
    result["figure"] = str(out / "convergence.png")
    return result


TRADEOFFS = {
    "N schedule (paper)": [],
    "fixed N=5": ["--pg-n-min", 5, "--pg-n-max", 5],
    "fixed N=10": ["--pg-n-min", 10, "--pg-n-max", 10],
    "fixed N=20": ["--pg-n-min", 20, "--pg-n-max", 20],
    "kMax=8": ["--pg-kmax", 8],
    "kMax=128": ["--pg-kmax", 128],
    "tile 8, apron 1": ["--pg-local", 8, "--pg-apron", 1],
    "tile 16, apron 3": ["--pg-apron", 3],
}


def tradeoffs(ctx, scene):
    """Time against error for the N schedule, kMax and the tile/apron size."""
    m = ctx.mode
    ref_path = ctx.refs.get(scene, m["trade_res"], m["ref_spp"])
    out = ctx.out / "tradeoffs" / scene
    rows = {}
    stats, _ = runner.render(scene, m["trade_res"], m["trade_frames"], "off", out, "pt", reference=ref_path)
    rows["PT (no guiding)"] = {"train_ms": 0.0, "frame_ms": median_time(stats), "relmse_last8": last_frames_error(stats)}
    for i, (name, flags) in enumerate(TRADEOFFS.items()):
        stats, _ = runner.render(scene, m["trade_res"], m["trade_frames"], "pmm", out, f"v{i}", reference=ref_path,
                                 extra=flags)
        rows[name] = {"train_ms": median_time(stats, "train"), "frame_ms": median_time(stats),
                      "relmse_last8": last_frames_error(stats)}
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, r in rows.items():
        ax.scatter(r["train_ms"], r["relmse_last8"])
        ax.annotate(name, (r["train_ms"], r["relmse_last8"]), fontsize=7)
    ax.set_xlabel("train kernel time (ms, median)")
    ax.set_ylabel("relMSE, mean of the last 8 frames")
    ax.set_title(f"{scene}: trade-offs")
    fig.tight_layout()
    fig.savefig(out / "tradeoffs.png", dpi=100)
    plt.close(fig)
    return {"scene": scene, "rows": rows, "figure": str(out / "tradeoffs.png")}


def kernels(ctx, _scene=None):
    """Summarises the Google Benchmark kernel microbenchmarks (bench/bench_guiding_kernels)."""
    exe = runner.ROOT / "build" / "bench" / "bench_guiding_kernels"
    if not exe.exists():
        return {"skipped": f"{exe} not built"}
    out = ctx.out / "kernels.json"
    # --quick: two cheap benchmarks only, to check that the summary pipeline works.
    flt = "CopyFloat4|Reproject/1280x720/local:16x16" if ctx.quick else "."
    args = [str(exe), f"--benchmark_out={out}", "--benchmark_out_format=json", f"--benchmark_filter={flt}"]
    if ctx.quick:
        args.append("--benchmark_repetitions=1")
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0 or not out.exists():
        return {"skipped": f"benchmark failed: {r.stderr.strip()[-300:]}"}
    data = json.loads(out.read_text())
    rows = []
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        rows.append({k: b[k] for k in b if k in ("name", "real_time", "time_unit") or isinstance(b[k], float)})
    return {"benchmarks": rows}


EXPERIMENTS = {"equal_frame": equal_frame, "equal_time": equal_time, "convergence": convergence,
               "tradeoffs": tradeoffs, "kernels": kernels}


class Context:
    def __init__(self, args):
        self.quick = args.quick
        self.mode = dict(MODES["quick" if args.quick else "full"])
        self.out = Path(args.out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.refs = runner.ReferenceCache(self.out / "references")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="tiny CI-sized run")
    ap.add_argument("--out", default=str(runner.ROOT / "build" / "bench-results"))
    ap.add_argument("--report", default=None, help="folder of the Markdown report")
    ap.add_argument("--only", nargs="*", choices=list(EXPERIMENTS), default=list(EXPERIMENTS))
    ap.add_argument("--scenes", nargs="*", default=None)
    ap.add_argument("--res", help="override the mode's resolution (WxH); the report states it")
    ap.add_argument("--ref-spp", type=int, help="override the references' samples per pixel")
    args = ap.parse_args()
    ctx = Context(args)
    overrides = {}
    if args.res:
        ctx.mode["res"] = ctx.mode["trade_res"] = overrides["res"] = args.res
    if args.ref_spp:
        ctx.mode["ref_spp"] = overrides["ref_spp"] = args.ref_spp
    scenes = args.scenes or ctx.mode["scenes"]
    results = {"machine": runner.machine_info(), "mode": "quick" if args.quick else "full", "settings": ctx.mode,
               "overrides": overrides, "started": time.strftime("%Y-%m-%d %H:%M:%S"), "skipped_scenes": {},
               "experiments": {}}
    usable = []
    for s in scenes:
        ok, why = available(s)
        if ok:
            usable.append(s)
        else:
            results["skipped_scenes"][s] = why
            print(f"skipping {s}: {why}", file=sys.stderr)
    for name in args.only:
        fn = EXPERIMENTS[name]
        t0 = time.time()
        if name == "kernels":
            results["experiments"][name] = fn(ctx)
        else:
            scene_list = usable if name != "tradeoffs" else [s for s in usable if s in ("cornell-indirect", "sponza")] or usable[:1]
            results["experiments"][name] = {s: fn(ctx, s) for s in scene_list}
        print(f"{name}: {time.time() - t0:.1f} s", file=sys.stderr)
        (ctx.out / "results.json").write_text(json.dumps(results, indent=2))
    results["finished"] = time.strftime("%Y-%m-%d %H:%M:%S")
    (ctx.out / "results.json").write_text(json.dumps(results, indent=2))
    from suite import report
    report_dir = Path(args.report) if args.report else (ctx.out / "report" if args.quick else runner.ROOT / "docs" / "results")
    report.write(results, report_dir)
    print(f"report: {report_dir / 'README.md'}")


if __name__ == "__main__":
    main()
