#!/usr/bin/env python3
"""rtpg benchmark suite: run time against error for plain path tracing (PT) and PMM path
guiding (PG), with official FLIP, plots and a Markdown report.

    python3 bench/experiments.py --quick            # CI-sized check of the pipeline (< 5 min)
    python3 bench/experiments.py                    # full run (960x540, 1024-spp references): 75 min on 2 cores, 30 min with cached references
    python3 bench/experiments.py --only equal_frame convergence --scenes cornell-indirect
    python3 bench/experiments.py --scenes all       # also the scenes outside the default set

Every experiment writes JSON (machine, commit, settings, every figure) and PNG plots into
--out (default: build/bench-results); the report goes to --report (default docs/results/ for a
full run, <out>/report for --quick). References are cached in <out>/references, so a rerun of
the same command renders only the experiments (bench/compare.py compares two runs).
"""
import argparse
import json
import shlex
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from suite import equal_time as equal_time_figures, metrics, runner  # noqa: E402

import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ALL_SCENES = runner.SUITE_SCENES  # --scenes all
METHODS = runner.METHODS
LABEL = {"off": "PT", "pmm": "PG"}

# res: equal frame, equal time, static convergence and flicker, against references of ref_spp.
# T: training frames of the equal-frame comparison; sweep: other T (all from one static run of
# max(sweep) frames per method, saved with --save-frames). path_*: convergence along the scene's
# camera path, per-frame references of path_ref_spp. trade_res: trade-offs, against the main
# reference box-filtered down (metrics.downsample_box). repeats: even, so that each method takes
# each place in the equal-time pairs as often (suite/equal_time.py, method_order; 3 before 2026-12-08).
MODES = {
    "quick": dict(res="48x32", ref_spp=64, T=8, sweep=[2, 8], time_frames=6, repeats=2, flicker_frames=4,
                  path_res="24x16", path_frames=[1, 4], path_ref_spp=64, trade_res="24x16", trade_frames=8,
                  svgf_large_res="96x64",
                  scenes=["cornell-box", "cornell-indirect"], tradeoff_scenes=["cornell-indirect"]),
    "full": dict(res="960x540", ref_spp=1024, T=32, sweep=[1, 4, 8, 16, 32, 64], time_frames=32, repeats=4,
                 flicker_frames=24, path_res="480x270", path_frames=[7, 15, 31, 59], path_ref_spp=256,
                 trade_res="480x270", trade_frames=32, svgf_large_res="1920x1080",
                 scenes=["cornell-box", "cornell-indirect", "cornell-glossy", "veach-ajar", "sponza"],
                 tradeoff_scenes=["cornell-indirect", "sponza"]),
}
# The equal-time runs' order, recorded in the results' settings so that the report says it:
# "alternating-balanced" (since 2026-12-07: PT and PG run by run, each pair in the reverse order of
# the one before, suite/equal_time.py's method_order); "alternating" (2026-11-27, evening, to
# 2026-12-07: PT and PG run by run, PT first in every pair); absent before (all PT runs first).
EQUAL_TIME_ORDER = "alternating-balanced"
LAST = 8  # equal-frame and trade-off errors: mean over the last 8 frames of a run


def available(scene):
    """A scene whose assets are missing is skipped with a message, not failed."""
    if not Path(runner.scene_path(scene)).exists():
        return False, "no scene file"
    try:
        runner.run(["info", runner.scene_path(scene)])
        return True, ""
    except RuntimeError as e:
        return False, str(e).splitlines()[-1]


def final_frame_metrics(stats, img, ref, T, exposure):
    """What equal-frame and denoised report of one method's run: the relMSE and LDR-FLIP (at the
    scene's exposure) of frame T, the mean relMSE of frames T-7..T with its standard error, and
    median times per stage."""
    frames = [f["relmse"] for f in stats["frames"][T - LAST:T]]
    mean, sem = runner.mean_sem(frames)
    # The frames themselves too: the report's verdict pairs them with the other method's (same seed).
    return {"relmse": metrics.relmse(img, ref), "relmse_last8": mean, "relmse_last8_sem": sem,
            "relmse_frames": frames,
            "flip_ldr": metrics.flip_ldr(img, ref, exposure),
            "time_ms": {k: runner.median_frame_ms(stats, k) for k in stats["frames"][-1]["time_ms"]}}


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


def comparison_figure(ref, images, titles, suptitle, path, exposure):
    """Reference, PT and PG (images["off"], images["pmm"]) side by side at the scene's exposure,
    each with a zoomed crop where PT's error is largest; titles: the reference's, PT's and PG's."""
    err = np.mean((images["off"] - ref) ** 2 / (ref ** 2 + 0.01), axis=2)
    y0, x0, s = crop_box(err, max(16, min(ref.shape[:2]) // 3))
    fig, axes = plt.subplots(2, 3, figsize=(12, 8) if ref.shape[1] > 400 else (9, 6))
    for col, (title, img) in enumerate(zip(titles, (ref, images["off"], images["pmm"]))):
        tm = metrics.tonemap_srgb(img, exposure)
        axes[0, col].imshow(tm)
        axes[0, col].add_patch(plt.Rectangle((x0, y0), s, s, fill=False, color="cyan"))
        axes[0, col].set_title(title, fontsize=9)
        axes[1, col].imshow(tm[y0:y0 + s, x0:x0 + s], interpolation="nearest")
        for a in axes[:, col]:
            a.axis("off")
    fig.suptitle(suptitle)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return str(path)


def static_run(ctx, scene, method):
    """The static-camera run shared by equal_frame and convergence: max(sweep, T) frames at 1 spp
    with relMSE per frame, and the frames of the sweep saved as EXR. Rendered once per scene."""
    key = (scene, method)
    if key not in ctx.static_runs:
        m = ctx.mode
        counts = sorted(set(m["sweep"]) | {m["T"]})  # frames rendered before each saved image
        out = ctx.out / "static" / scene
        stats, image = runner.render(scene, m["res"], counts[-1], method, out, method,
                                     reference=ctx.reference(scene, m["res"]),
                                     extra=["--save-frames", ",".join(str(t - 1) for t in counts)])
        ctx.static_runs[key] = (stats, {t: runner.saved_frame(image, t - 1) for t in counts})
    return ctx.static_runs[key]


def equal_frame(ctx, scene):
    """PT vs PG at 1 spp after T training frames, FLIP and relMSE, images with zoomed crops; the
    sweep over T comes from the same runs."""
    m = ctx.mode
    T = m["T"]
    ref = ctx.reference_image(scene, m["res"])
    out = ctx.out / "equal_frame" / scene
    out.mkdir(parents=True, exist_ok=True)
    result = {"scene": scene, "reference": str(ctx.reference(scene, m["res"])), "T": T, "methods": {}, "sweep": {}}
    exposure = result["exposure"] = runner.scene_exposure(scene)
    images = {}
    for method in METHODS:
        stats, frames = static_run(ctx, scene, method)
        img = metrics.load_exr(frames[T])
        images[method] = img
        result["methods"][method] = {
            **final_frame_metrics(stats, img, ref, T, exposure), "flip_hdr": metrics.flip_hdr(img, ref),
            "frame_ms": runner.median_frame_ms(stats), "nonfinite": sum(f["nonfinite_samples"] for f in stats["frames"]),
        }
        for key in ("guided_fraction", "trained_fraction", "mean_pi"):
            if key in stats["frames"][T - 1]:
                result["methods"][method][key] = stats["frames"][T - 1][key]
    for t in m["sweep"]:
        row = {}
        for method in METHODS:
            img = metrics.load_exr(static_run(ctx, scene, method)[1][t])
            row[method] = {"relmse": metrics.relmse(img, ref), "flip_ldr": metrics.flip_ldr(img, ref, exposure)}
        result["sweep"][str(t)] = row
    flips = {k: result["methods"][k]["flip_ldr"] for k in METHODS}
    result["figure"] = comparison_figure(
        ref, images, ("Reference", f"PT 1 spp  FLIP {flips['off']:.3f}", f"PG 1 spp  FLIP {flips['pmm']:.3f}"),
        f"{scene}: 1 spp after {T} frames ({m['res']})", out / "comparison.png", exposure)
    return result


def equal_time(ctx, scene):
    """Error of the accumulated image against cumulative wall time, both methods, repeats with
    different seeds. Every figure is read off each run's own curve, then the median over the runs
    (suite/equal_time.py); the plot shows every run."""
    m = ctx.mode
    out = ctx.out / "equal_time" / scene
    curves = equal_time_figures.runs(scene, m["res"], m["time_frames"], m["repeats"], out,
                                     ctx.reference(scene, m["res"]))
    fig, ax = plt.subplots(figsize=(5, 4))
    for i, (method, c) in enumerate(curves.items()):
        for j, run in enumerate(c["runs"]):
            ax.loglog(run["time_ms"], run["relmse"], color=f"C{i}", alpha=0.7,
                      label=LABEL[method] if j == 0 else None)
    ax.set_xlabel("wall time (ms, cumulative)")
    ax.set_ylabel("relMSE of the accumulated image")
    ax.set_title(f"{scene}: equal time ({m['res']}, {m['repeats']} runs each)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "equal_time.png", dpi=100)
    plt.close(fig)
    # The error each method reaches within PT's time for all its frames, and the time PG needs to
    # reach the error PT ends with (ratio PG/PT: below 1, guiding pays for itself).
    result = equal_time_figures.figures_of(curves)
    return {"scene": scene, "curves": curves, **result, "figure": str(out / "equal_time.png")}


def flicker(ctx, scene):
    """Temporal flicker (docs/design.md, "Metrics"): mean MSE between consecutive frames of a
    static camera with jitter off, over the last 8 frame pairs of a run (PG has trained by then)."""
    m = ctx.mode
    out = ctx.out / "flicker" / scene
    result = {"scene": scene, "frames": m["flicker_frames"], "methods": {}}
    for method in METHODS:
        stats, _ = runner.render(scene, m["res"], m["flicker_frames"], method, out, method, extra=["--no-jitter"])
        values = [f["flicker_mse"] for f in stats["frames"] if "flicker_mse" in f][-LAST:]
        mean, sem = runner.mean_sem(values)
        result["methods"][method] = {"flicker_mse": mean, "sem": sem}
    return result


def convergence(ctx, scene):
    """relMSE of the 1-spp frame against frame index: static camera (every frame), and at
    checkpoints along the scene's first camera path (per-frame references)."""
    m = ctx.mode
    out = ctx.out / "convergence" / scene
    result = {"scene": scene, "static": {}, "path": {}, "res": m["res"], "path_res": m["path_res"]}
    exposure = result["exposure"] = runner.scene_exposure(scene)
    for method in METHODS:
        result["static"][method] = [f["relmse"] for f in static_run(ctx, scene, method)[0]["frames"]]
    name = runner.first_camera_path(scene)
    if name:
        result["path_name"] = name
        refs = {f: metrics.load_exr(ctx.refs.get(scene, m["path_res"], m["path_ref_spp"], camera_path=name, frame=f))
                for f in m["path_frames"]}
        for method in METHODS:
            _, image = runner.render(scene, m["path_res"], max(m["path_frames"]) + 1, method, out, f"path-{method}",
                                     extra=["--camera-path", name, "--save-frames", ",".join(map(str, m["path_frames"]))])
            imgs = {f: metrics.load_exr(runner.saved_frame(image, f)) for f in m["path_frames"]}
            result["path"][method] = {"frames": m["path_frames"],
                                      "relmse": [metrics.relmse(imgs[f], refs[f]) for f in m["path_frames"]],
                                      "flip_ldr": [metrics.flip_ldr(imgs[f], refs[f], exposure)
                                                   for f in m["path_frames"]]}
    fig, axes = plt.subplots(1, 2 if name else 1, figsize=(10 if name else 5, 4), squeeze=False)
    for method, e in result["static"].items():
        axes[0, 0].semilogy(e, label=LABEL[method])
    axes[0, 0].set_title(f"{scene}: static camera ({m['res']})", fontsize=9)
    for method, p in result["path"].items():
        axes[0, 1].semilogy(p["frames"], p["relmse"], "o--", label=LABEL[method])
    if name:
        axes[0, 1].set_title(f"camera path '{result['path_name']}' ({m['path_res']})", fontsize=9)
    for ax in axes[0]:
        ax.set_xlabel("frame")
        ax.set_ylabel("relMSE of the 1-spp frame")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "convergence.png", dpi=100)
    plt.close(fig)
    result["figure"] = str(out / "convergence.png")
    return result


def denoised(ctx, scene):
    """PT+SVGF against PG+SVGF (paper, table 2; docs/denoising.md): FLIP and relMSE of the denoised
    frame after T frames against the reference (static camera), the same at checkpoints of the
    camera path, the flicker of the denoised sequence along the path, and SVGF's time as a
    fraction of the PT frame at the main resolution and at svgf_large_res."""
    m = ctx.mode
    T = m["T"]
    ref = ctx.reference_image(scene, m["res"])
    out = ctx.out / "denoised" / scene
    out.mkdir(parents=True, exist_ok=True)
    result = {"scene": scene, "T": T, "static": {}, "path": {}, "cost": {}}
    exposure = result["exposure"] = runner.scene_exposure(scene)
    images = {}
    for method in METHODS:
        noisy_path = out / f"{method}-noisy.exr"
        stats, image = runner.render(scene, m["res"], T, method, out, method, reference=ctx.reference(scene, m["res"]),
                                     extra=["--denoise", "svgf", "--noisy-output", noisy_path, *ctx.svgf_args])
        img, noisy = metrics.load_exr(image), metrics.load_exr(noisy_path)
        images[method] = img
        result["static"][method] = {
            **final_frame_metrics(stats, img, ref, T, exposure), "relmse_noisy": metrics.relmse(noisy, ref),
            "flip_ldr_noisy": metrics.flip_ldr(noisy, ref, exposure),
        }
    # SVGF's cost against the path-traced frame it filters (the renderer's part of "total").
    for res, method_stats in ((m["res"], result["static"]["off"]["time_ms"]), (m["svgf_large_res"], None)):
        if method_stats is None:
            stats, _ = runner.render(scene, res, 4, "off", out, "cost-large",
                                    extra=["--denoise", "svgf", *ctx.svgf_args])
            method_stats = {k: runner.median_frame_ms(stats, k) for k in stats["frames"][-1]["time_ms"]}
        svgf = method_stats["svgf_total"]
        result["cost"][res] = {"svgf_ms": svgf, "pt_frame_ms": method_stats["total"] - svgf,
                               "kernels_ms": {k: v for k, v in method_stats.items() if k.startswith("svgf_")}}
    name = runner.first_camera_path(scene)
    if name:
        result["path_name"] = name
        frames = m["path_frames"]
        refs = {f: metrics.load_exr(ctx.refs.get(scene, m["path_res"], m["path_ref_spp"], camera_path=name, frame=f))
                for f in frames}
        for method in METHODS:
            stats, image = runner.render(scene, m["path_res"], max(frames) + 1, method, out, f"path-{method}",
                                         extra=["--camera-path", name, "--denoise", "svgf",
                                                "--save-frames", ",".join(map(str, frames)), *ctx.svgf_args])
            imgs = {f: metrics.load_exr(runner.saved_frame(image, f)) for f in frames}
            flicker = [f["flicker_mse"] for f in stats["frames"] if "flicker_mse" in f]
            flicker_noisy = [f["flicker_mse_noisy"] for f in stats["frames"] if "flicker_mse_noisy" in f]
            fm, fs = runner.mean_sem(flicker)
            # Through the motion vectors, on the displayed values (docs/design.md, "Metrics"): the
            # plain consecutive-frame MSE above is mostly the picture moving.
            tracked = [f for f in stats["frames"] if "flicker_reprojected" in f]
            rm, rs = runner.mean_sem(f["flicker_reprojected"] for f in tracked)
            result["path"][method] = {"frames": frames,
                                      "relmse": [metrics.relmse(imgs[f], refs[f]) for f in frames],
                                      "flip_ldr": [metrics.flip_ldr(imgs[f], refs[f], exposure) for f in frames],
                                      "flicker_mse": fm, "flicker_sem": fs,
                                      "flicker_mse_noisy": runner.mean_sem(flicker_noisy)[0],
                                      "flicker_reprojected": rm, "flicker_reprojected_sem": rs,
                                      "flicker_reprojected_noisy":
                                          runner.mean_sem(f["flicker_reprojected_noisy"] for f in tracked)[0],
                                      "flicker_tracked_fraction":
                                          runner.mean_sem(f["flicker_tracked_fraction"] for f in tracked)[0]}
    flips = {k: result["static"][k]["flip_ldr"] for k in METHODS}
    result["figure"] = comparison_figure(
        ref, images, ("Reference", f"PT+SVGF  FLIP {flips['off']:.3f}", f"PG+SVGF  FLIP {flips['pmm']:.3f}"),
        f"{scene}: 1 spp + SVGF after {T} frames ({m['res']})", out / "denoised.png", exposure)
    return result


TRADEOFFS = {
    "N schedule (paper)": [],
    "fixed N=5": ["--pg-n-min", 5, "--pg-n-max", 5],
    "fixed N=10": ["--pg-n-min", 10, "--pg-n-max", 10],
    "fixed N=20": ["--pg-n-min", 20, "--pg-n-max", 20],
    "kMax=8": ["--pg-k-max", 8],
    "kMax=128": ["--pg-k-max", 128],
    "tile 8, apron 1": ["--pg-local-x", 8, "--pg-local-y", 8, "--pg-apron", 1],
    "tile 16, apron 3": ["--pg-apron", 3],
}


def tradeoffs(ctx, scene):
    """Time against error for the N schedule, kMax and the tile/apron size."""
    m = ctx.mode
    ref = ctx.reference_image(scene, m["trade_res"])
    out = ctx.out / "tradeoffs" / scene
    last = ",".join(str(f) for f in range(m["trade_frames"] - LAST, m["trade_frames"]))
    rows = {}
    for name, method, flags in [("PT (no guiding)", "off", [])] + [(n, "pmm", f) for n, f in TRADEOFFS.items()]:
        tag = f"v{len(rows)}"
        stats, image = runner.render(scene, m["trade_res"], m["trade_frames"], method, out, tag,
                                     extra=flags + ["--save-frames", last])
        errors = [metrics.relmse(metrics.load_exr(runner.saved_frame(image, f)), ref)
                  for f in range(m["trade_frames"] - LAST, m["trade_frames"])]
        mean, sem = runner.mean_sem(errors)
        rows[name] = {"train_ms": runner.median_frame_ms(stats, "train"), "frame_ms": runner.median_frame_ms(stats),
                      "relmse_last8": mean, "relmse_last8_sem": sem, "flags": [str(f) for f in flags]}
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, r in rows.items():
        ax.errorbar(r["train_ms"], r["relmse_last8"], yerr=r["relmse_last8_sem"], fmt="o")
        ax.annotate(name, (r["train_ms"], r["relmse_last8"]), fontsize=7)
    ax.set_xlabel("train kernel time (ms, median)")
    ax.set_ylabel("relMSE, mean of the last 8 frames")
    ax.set_title(f"{scene}: trade-offs ({m['trade_res']})")
    fig.tight_layout()
    fig.savefig(out / "tradeoffs.png", dpi=100)
    plt.close(fig)
    return {"scene": scene, "res": m["trade_res"], "rows": rows, "figure": str(out / "tradeoffs.png")}


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


EXPERIMENTS = {"equal_frame": equal_frame, "equal_time": equal_time, "flicker": flicker, "convergence": convergence,
               "denoised": denoised, "tradeoffs": tradeoffs, "kernels": kernels}


def parse_res(res):
    w, h = res.split("x")
    return int(w), int(h)


class Context:
    def __init__(self, args):
        self.quick = args.quick
        self.mode = dict(MODES["quick" if args.quick else "full"])
        # Extra flags of every denoised render (--svgf-args, e.g. "--svgf-atrous-radius 1").
        self.svgf_args = shlex.split(args.svgf_args or "")
        self.out = Path(args.out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.refs = runner.ReferenceCache(self.out / "references")
        self.static_runs = {}
        self._images = {}

    def reference(self, scene, res):
        """The cached reference of the mode's main resolution (rendered on first use)."""
        assert res == self.mode["res"], res
        return self.refs.get(scene, res, self.mode["ref_spp"])

    def reference_image(self, scene, res):
        """The reference at `res`: the main one, or the main one box-filtered down by an integer
        factor (an unbiased reference for the smaller image, metrics.downsample_box)."""
        key = (scene, res)
        if key not in self._images:
            (w, h), (mw, mh) = parse_res(res), parse_res(self.mode["res"])
            main = metrics.load_exr(self.reference(scene, self.mode["res"]))
            if (w, h) == (mw, mh):
                self._images[key] = main
            elif mw % w == 0 and mw // w == mh // h and mh % h == 0:
                self._images[key] = metrics.downsample_box(main, mw // w)
            else:
                raise ValueError(f"{res} is not the main resolution {self.mode['res']} divided by an integer")
        return self._images[key]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="tiny CI-sized run")
    ap.add_argument("--out", default=str(runner.ROOT / "build" / "bench-results"))
    ap.add_argument("--report", default=None, help="folder of the Markdown report")
    ap.add_argument("--only", nargs="*", choices=list(EXPERIMENTS), default=list(EXPERIMENTS))
    ap.add_argument("--scenes", nargs="*", default=None, help="scene names, or 'all' (%s)" % ", ".join(ALL_SCENES))
    ap.add_argument("--report-from", help="only rewrite the report from this results.json")
    ap.add_argument("--svgf-args", default="", help="extra rtpg flags of every denoised render, e.g. "
                    "'--svgf-atrous-radius 1' (recorded in the results' settings)")
    args = ap.parse_args()
    from suite import report
    if args.report_from:
        results = json.loads(Path(args.report_from).read_text())
        report_dir = Path(args.report or Path(args.report_from).parent)
        report.write(results, report_dir)
        print(f"report: {report_dir / 'README.md'}")
        return
    ctx = Context(args)
    scenes = ALL_SCENES if args.scenes == ["all"] else (args.scenes or ctx.mode["scenes"])
    command = "python3 bench/experiments.py" + (" --quick" if args.quick else "") + \
        (f" --only {' '.join(args.only)}" if args.only != list(EXPERIMENTS) else "") + \
        (f" --scenes {' '.join(args.scenes)}" if args.scenes else "") + \
        (f" --svgf-args {shlex.quote(args.svgf_args)}" if args.svgf_args else "")
    results = {"machine": runner.machine_info(), "mode": "quick" if args.quick else "full", "settings": {**ctx.mode, "equal_time_order": EQUAL_TIME_ORDER,
                                                                                             "svgf_args": ctx.svgf_args},
               "command": command, "started": time.strftime("%Y-%m-%d %H:%M:%S"), "skipped_scenes": {},
               "experiments": {}, "seconds": {}}
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
            scene_list = usable if name != "tradeoffs" else [s for s in usable if s in ctx.mode["tradeoff_scenes"]]
            results["experiments"][name] = {}
            for s in scene_list:
                results["experiments"][name][s] = fn(ctx, s)
                print(f"{name} {s}: {time.time() - t0:.0f} s", file=sys.stderr, flush=True)
        results["seconds"][name] = round(time.time() - t0, 1)
        # Each experiment also on its own: machine, commit, settings and its figures.
        own = {k: v for k, v in results.items() if k not in ("experiments", "seconds")}
        own.update(experiment=name, seconds=results["seconds"][name], figures=results["experiments"][name])
        (ctx.out / f"{name}.json").write_text(json.dumps(own, indent=2))
        (ctx.out / "results.json").write_text(json.dumps(results, indent=2))
    results["references"] = sorted(ctx.refs.timings.values(), key=lambda r: (r["scene"], r["res"], r["spp"]))
    results["finished"] = time.strftime("%Y-%m-%d %H:%M:%S")
    (ctx.out / "results.json").write_text(json.dumps(results, indent=2))
    # Beside the results, never over docs/results/README.md, which is the project's log of runs
    # (a run's report is copied into it by hand, with what it measured and why).
    report_dir = Path(args.report) if args.report else ctx.out / "report"
    report.write(results, report_dir)
    print(f"report: {report_dir / 'README.md'}")


if __name__ == "__main__":
    main()
