"""Writes the Markdown report (docs/results/README.md for a full run) from results.json."""
import json
import shutil
from pathlib import Path


def _copy_figure(src, report_dir, name):
    if not src or not Path(src).exists():
        return None
    dst = report_dir / "figures" / name
    dst.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(src, dst)
    return f"figures/{name}"


def _figures(ex, report_dir, suffix):
    """The experiment's plot of every scene, copied beside the report, as Markdown images."""
    lines = []
    for scene, r in ex.items():
        fig = _copy_figure(r.get("figure"), report_dir, f"{scene}-{suffix}.png")
        if fig:
            lines += [f"![{scene} {suffix}]({fig})", ""]
    return lines


def _ms(value):
    if value >= 1e4:
        return f"{value / 1e3:.1f} s"
    return f"{value:.0f} ms" if value >= 100 else f"{value:.3g} ms"


# Two-sided 1% quantiles of Student's t by degrees of freedom (1-30; the normal's beyond).
_T_995 = [63.657, 9.925, 5.841, 4.604, 4.032, 3.707, 3.499, 3.355, 3.250, 3.169, 3.106, 3.055, 3.012, 2.977,
          2.947, 2.921, 2.898, 2.878, 2.861, 2.845, 2.831, 2.819, 2.807, 2.797, 2.787, 2.779, 2.771, 2.763,
          2.756, 2.750]


def paired_verdict(pt_frames, pg_frames):
    """Better / worse from the frames' paired differences pg - pt: both methods render with one seed,
    so their frames share the camera jitter and most random streams and their errors move together
    (correlation 0.99 on the Cornell box); the two means' own standard errors, combined as if the runs
    were independent, hid real differences. Significant where |mean| exceeds the two-sided 1% t bound
    of the differences' standard error. Returns (verdict, mean difference, its standard error)."""
    d = [g - p for p, g in zip(pt_frames, pg_frames)]
    n = len(d)
    if n < 2:
        return "no significant difference", float("nan"), float("nan")
    mean = sum(d) / n
    sem = (sum((x - mean) ** 2 for x in d) / (n - 1) / n) ** 0.5
    bound = (_T_995[n - 2] if n - 1 <= len(_T_995) else 2.576) * sem
    if mean < -bound:
        return "PG better", mean, sem
    if mean > bound:
        return "PT better", mean, sem
    return "no significant difference", mean, sem


def verdict(pt_mean, pt_sem, pg_mean, pg_sem):
    """Better / worse when the difference of the means exceeds 3 combined standard errors: for results
    without the per-frame errors (before 2026-12-08), and for the denoised frames, which are neither
    independent of each other (SVGF carries its history from frame to frame) nor of the other method's."""
    gap = 3.0 * (pt_sem ** 2 + pg_sem ** 2) ** 0.5
    if pg_mean < pt_mean - gap:
        return "PG better"
    if pg_mean > pt_mean + gap:
        return "PT better"
    return "no significant difference"


def _relmse_cells(pt, pg, pt_frames=None, pg_frames=None):
    """The table cells 'relMSE PT (± s.e.) | relMSE PG (± s.e.) | verdict' of two methods' figures: the
    paired verdict where both runs' per-frame errors are given, with PG/PT and its paired standard
    error, else the unpaired one."""
    cells = (f"| {pt['relmse_last8']:.4g} ± {pt['relmse_last8_sem']:.2g} "
             f"| {pg['relmse_last8']:.4g} ± {pg['relmse_last8_sem']:.2g} ")
    if pt_frames and pg_frames:
        said, mean, sem = paired_verdict(pt_frames, pg_frames)
        base = max(pt["relmse_last8"], 1e-30)
        return cells + f"| {said} (PG/PT {1.0 + mean / base:.3f} ± {sem / base:.3f}, paired) "
    return cells + f"| {verdict(pt['relmse_last8'], pt['relmse_last8_sem'], pg['relmse_last8'], pg['relmse_last8_sem'])} "


def _frames_of(method_figures, convergence, scene, method, T, last=8):
    """A method's per-frame relMSE of frames T-7..T: recorded with the figures since 2026-12-08, else read
    from the convergence experiment's static curve, which comes from the same run."""
    if method_figures.get("relmse_frames"):
        return method_figures["relmse_frames"]
    curve = (convergence or {}).get(scene, {}).get("static", {}).get(method)
    if curve and len(curve) >= T:
        return curve[T - last:T]
    return None


def _exposures(ex):
    """'cornell-box 2, sponza 32': the scene files' exposures the LDR-FLIP figures used (results
    recorded before scenes had one used 1)."""
    return ", ".join(f"{scene} {r.get('exposure', 1.0):g}" for scene, r in ex.items())


def _equal_frame(ex, report_dir, convergence=None):
    lines = ["## Equal frame: 1 spp after T frames (paper, figure 3)", "",
             "| scene | PT FLIP | PG FLIP | ratio | relMSE ratio | frame time PT | frame time PG | guiding overhead |",
             "|---|---|---|---|---|---|---|---|"]
    for scene, r in ex.items():
        pt, pg = r["methods"]["off"], r["methods"]["pmm"]
        lines.append(
            f"| {scene} | {pt['flip_ldr']:.3f} | {pg['flip_ldr']:.3f} | {pt['flip_ldr'] / max(pg['flip_ldr'], 1e-9):.2f}x "
            f"| {pg['relmse_last8'] / max(pt['relmse_last8'], 1e-12):.2f} | {_ms(pt['frame_ms'])} | {_ms(pg['frame_ms'])} "
            f"| {100.0 * (pg['frame_ms'] - pt['frame_ms']) / max(pt['frame_ms'], 1e-9):+.0f}% |")
    lines += ["", f"FLIP: mean LDR-FLIP of frame T (tonemapped as rtpg's PNG output, at the scene's exposure: "
              f"{_exposures(ex)}); ratio = PT/PG (above 1: "
              "guiding is better). relMSE ratio = PG/PT of the mean relMSE of frames T-7..T (below 1: guiding is "
              "better). Frame times: medians over the frames of the run (frame 0 left out); overhead = (PG - PT) / PT.",
              "", "| scene | HDR-FLIP PT | HDR-FLIP PG | relMSE PT (± s.e.) | relMSE PG (± s.e.) | verdict | guided pixels | mean pi |",
              "|---|---|---|---|---|---|---|---|"]
    for scene, r in ex.items():
        pt, pg = r["methods"]["off"], r["methods"]["pmm"]
        frames = [_frames_of(f, convergence, scene, m, r["T"]) for f, m in ((pt, "off"), (pg, "pmm"))]
        lines.append(f"| {scene} | {pt['flip_hdr']:.3f} | {pg['flip_hdr']:.3f} "
                     f"{_relmse_cells(pt, pg, *frames)}"
                     f"| {pg.get('guided_fraction', float('nan')):.2f} | {pg.get('mean_pi', float('nan')):.2f} |")
    lines += ["", "Verdict: the two runs share their seed, so their frames' errors move together; the verdict is "
              "that of the 8 paired differences PG - PT of frames T-7..T against the two-sided 1% t bound, with "
              "PG/PT and its standard error from them (results without the per-frame errors: the difference of the "
              "means against three combined standard errors, as if independent). Guided pixels: share of surface "
              "pixels that sampled a trained mixture at frame T; mean pi: their mean Gaussian weight.", ""]
    lines += _figures(ex, report_dir, "comparison")
    lines += ["Training sweep (relMSE and LDR-FLIP of the frame after T frames; one run per method, frames saved "
              "with `--save-frames`):", "", "| scene | T | relMSE PT | relMSE PG | FLIP PT | FLIP PG |",
              "|---|---|---|---|---|---|"]
    for scene, r in ex.items():
        for t, row in r["sweep"].items():
            lines.append(f"| {scene} | {t} | {row['off']['relmse']:.4g} | {row['pmm']['relmse']:.4g} "
                         f"| {row['off']['flip_ldr']:.3f} | {row['pmm']['flip_ldr']:.3f} |")
    return lines + [""]


def _figure(value, fmt):
    """A number formatted, or what stands in its place ("not reached", suite/equal_time.py)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return format(value, fmt)
    return "not reached" if value is None else str(value)  # None: results.json from before equal_time.py


def _equal_time(ex, report_dir, settings):
    if all("runs" in c for r in ex.values() for c in r["curves"].values()):
        method = ("Each figure is read off each run's own (time, error) curve, log-log between frames, then the "
                  "median over the runs is taken (bench/suite/equal_time.py): PT's time is the median of its runs' "
                  "times, PT's error the median of their final errors.")
    else:  # results.json from before bench/suite/equal_time.py: its figures came from per-frame medians
        method = ("The figures are read off per-frame medians of the runs' times and errors (the method before "
                  "bench/suite/equal_time.py).")
    # Runs before 2026-11-27 (evening) rendered all of PT's repeats, then all of PG's; until
    # 2026-12-07 PT came first in every pair (bench/experiments.py, EQUAL_TIME_ORDER).
    order = {"alternating-balanced": "PT and PG alternating run by run, each pair in the reverse order of the one "
                                     "before",
             "alternating": "PT and PG alternating run by run, PT first in each pair"}.get(
        settings.get("equal_time_order"), "all PT runs first, then all PG runs")
    lines = ["## Equal time: error of the accumulated image against wall time", "",
             f"{settings['time_frames']} accumulated frames per method, {settings['repeats']} runs each (seeds 100, "
             f"101, ...) in the same process tree, {order}; frame 0's one-time program build is replaced by the "
             f"median frame time. {method}", "",
             "| scene | PT time | relMSE PT at PT's time | relMSE PG at the same time | PG time to PT's final error |",
             "|---|---|---|---|---|"]
    for scene, r in ex.items():
        b = r["relmse_at_pt_budget"]
        ratio = r.get("time_ratio_pg_pt")
        ratio = f"{ratio:.2f}x PT time" if isinstance(ratio, (int, float)) else _figure(ratio, "")
        lines.append(f"| {scene} | {_ms(r.get('pt_time_ms', float('nan')))} | {_figure(b['off'], '.4g')} "
                     f"| {_figure(b['pmm'], '.4g')} | {ratio} |")
    lines += ["", "Last column below 1x: guiding reaches PT's error sooner (it pays for its cost); above 1x or "
              "'not reached' (the median PG run does not get there within the frames rendered): PT is the better "
              "use of the time on this machine. 'not reached' for PG's error: the median PG run ended before PT's "
              "time.", ""]
    return lines + _figures(ex, report_dir, "equal-time")


def _flicker(ex, settings):
    lines = ["## Temporal flicker (static camera, jitter off)", "",
             f"Mean MSE between consecutive 1-spp frames, over the last {min(8, settings['flicker_frames'] - 1)} "
             f"frame pairs of {settings['flicker_frames']} frames "
             "(docs/design.md, \"Metrics\"; the paper's flicker claim is for SVGF output, which comes later).", "",
             "| scene | flicker PT | flicker PG | PG/PT |", "|---|---|---|---|"]
    for scene, r in ex.items():
        pt, pg = r["methods"]["off"], r["methods"]["pmm"]
        lines.append(f"| {scene} | {pt['flicker_mse']:.4g} ± {pt['sem']:.2g} | {pg['flicker_mse']:.4g} ± {pg['sem']:.2g} "
                     f"| {pg['flicker_mse'] / max(pt['flicker_mse'], 1e-30):.2f} |")
    return lines + [""]


def _convergence(ex, report_dir, settings):
    lines = ["## Convergence: relMSE of the 1-spp frame against frame index", "",
             f"Static camera at {settings['res']} (every frame, against the main reference) and along the scene's "
             f"camera path at {settings['path_res']} (frames {settings['path_frames']}, against per-frame references "
             f"of {settings['path_ref_spp']} spp: their own variance adds about 1/{settings['path_ref_spp']} of a "
             "1-spp frame's).", "",
             "| scene | static PT frame 0 -> last | static PG frame 0 -> last | path | path relMSE PG/PT per checkpoint |",
             "|---|---|---|---|---|"]
    for scene, r in ex.items():
        s, p = r["static"], r.get("path", {})
        ratios = ""
        if p:
            ratios = ", ".join(f"f{f}: {g / max(o, 1e-12):.2f}"
                               for f, o, g in zip(p["off"]["frames"], p["off"]["relmse"], p["pmm"]["relmse"]))
        lines.append(f"| {scene} | {s['off'][0]:.4g} -> {s['off'][-1]:.4g} | {s['pmm'][0]:.4g} -> {s['pmm'][-1]:.4g} "
                     f"| {r.get('path_name', '-')} | {ratios} |")
    return lines + [""] + _figures(ex, report_dir, "convergence")


def _denoised(ex, report_dir, settings):
    lines = ["## Denoised: PT+SVGF against PG+SVGF (paper, table 2)", "",
             f"SVGF (`--denoise svgf`, docs/denoising.md) on every 1-spp frame; figures of the denoised frame after "
             f"T = {settings['T']} frames at {settings['res']}, static camera; LDR-FLIP at the scene's exposure "
             f"({_exposures(ex)}). The paper reports LDR-FLIP 0.13 (PT+SVGF) "
             "against 0.05 (PG+SVGF) and 0.10 against 0.03 on its two scenes (ratios 0.38 and 0.30).", "",
             "| scene | FLIP PT+SVGF | FLIP PG+SVGF | PG/PT | relMSE PT+SVGF (± s.e.) | relMSE PG+SVGF (± s.e.) "
             "| verdict | FLIP PT / PG without SVGF |",
             "|---|---|---|---|---|---|---|---|"]
    for scene, r in ex.items():
        pt, pg = r["static"]["off"], r["static"]["pmm"]
        lines.append(f"| {scene} | {pt['flip_ldr']:.3f} | {pg['flip_ldr']:.3f} | {pg['flip_ldr'] / max(pt['flip_ldr'], 1e-9):.2f} "
                     f"{_relmse_cells(pt, pg)}"
                     f"| {pt['flip_ldr_noisy']:.3f} / {pg['flip_ldr_noisy']:.3f} |")
    lines += ["", f"Along the camera path ({settings['path_res']}, frames {settings['path_frames']}, per-frame references "
              f"of {settings['path_ref_spp']} spp): LDR-FLIP PG/PT per checkpoint, and the flicker of the denoised "
              "sequence: the mean squared change of each pixel's displayed value (the PNG transform at the scene's "
              "exposure) from last frame's pixel that shows the same surface, through the motion vectors "
              "(`flicker_reprojected`; docs/design.md, \"Metrics\"; results without it show the plain MSE between "
              "consecutive frames, which is mostly the camera's motion).", "",
              "| scene | path | FLIP PG/PT per checkpoint | flicker PT+SVGF | flicker PG+SVGF | PG/PT | PG/PT without SVGF |",
              "|---|---|---|---|---|---|---|"]
    for scene, r in ex.items():
        p = r.get("path", {})
        if not p:
            lines.append(f"| {scene} | - | | | | | |")
            continue
        ratios = ", ".join(f"f{f}: {g / max(o, 1e-12):.2f}"
                           for f, o, g in zip(p["off"]["frames"], p["off"]["flip_ldr"], p["pmm"]["flip_ldr"]))
        o, g = p["off"], p["pmm"]
        key = "flicker_reprojected" if "flicker_reprojected" in o else "flicker_mse"
        sem = "flicker_reprojected_sem" if key == "flicker_reprojected" else "flicker_sem"
        noisy = key + "_noisy" if key == "flicker_reprojected" else "flicker_mse_noisy"
        lines.append(f"| {scene} | {r['path_name']} | {ratios} | {o[key]:.4g} ± {o[sem]:.2g} "
                     f"| {g[key]:.4g} ± {g[sem]:.2g} | {g[key] / max(o[key], 1e-30):.2f} "
                     f"| {g[noisy] / max(o[noisy], 1e-30):.2f} |")
    lines += ["", "SVGF's time per frame (medians; upload, kernels and download) against the path-traced frame it filters:", "",
              "| scene | resolution | SVGF | PT frame | fraction | a-trous (5 iterations) |", "|---|---|---|---|---|---|"]
    for scene, r in ex.items():
        for res, c in r["cost"].items():
            lines.append(f"| {scene} | {res} | {_ms(c['svgf_ms'])} | {_ms(c['pt_frame_ms'])} "
                         f"| {100.0 * c['svgf_ms'] / max(c['pt_frame_ms'], 1e-9):.0f}% "
                         f"| {_ms(c['kernels_ms'].get('svgf_atrous', 0.0))} |")
    return lines + [""] + _figures(ex, report_dir, "denoised")


def _tradeoffs(ex, report_dir):
    lines = ["## Trade-offs: train time against error", ""]
    for scene, r in ex.items():
        lines += [f"{scene} ({r.get('res', '?')}, reference: the main one box-filtered down):", "",
                  "| variant | train ms | frame ms | relMSE (last 8, ± s.e.) |", "|---|---|---|---|"]
        for name, row in r["rows"].items():
            lines.append(f"| {name} | {row['train_ms']:.2f} | {row['frame_ms']:.1f} "
                         f"| {row['relmse_last8']:.4g} ± {row.get('relmse_last8_sem', float('nan')):.2g} |")
        fig = _copy_figure(r.get("figure"), report_dir, f"{scene}-tradeoffs.png")
        lines += ["", f"![{scene} trade-offs]({fig})" if fig else "", ""]
    return lines


def _kernels(k):
    lines = ["## Kernel microbenchmarks (bench/bench_guiding_kernels)", ""]
    if "skipped" in k:
        return lines + [f"Skipped: {k['skipped']}", ""]
    lines += ["| benchmark | time | counters |", "|---|---|---|"]
    for b in k["benchmarks"]:
        counters = ", ".join(f"{n}={v:.3g}" for n, v in b.items()
                             if n not in ("name", "real_time", "time_unit", "cpu_time", "iterations"))
        lines.append(f"| {b['name']} | {b.get('real_time', 0):.3g} {b.get('time_unit', '')} | {counters} |")
    return lines + [""]


def write(results, report_dir):
    report_dir = Path(report_dir)
    report_dir.mkdir(parents=True, exist_ok=True)
    m = results["machine"]
    st = results["settings"]
    ex = results["experiments"]
    lines = [
        "# rtpg benchmark report",
        "",
        f"Mode: **{results['mode']}** ({st['res']}, references of {st['ref_spp']} spp, T = {st['T']} training "
        f"frames). Generated by `{results.get('command', 'python3 bench/experiments.py')}` from "
        f"{results.get('started', '?')} to {results.get('finished', '?')}"
        + (" (seconds per experiment: " + ", ".join(f"{k} {v:.0f}" for k, v in results["seconds"].items()) + ")"
           if results.get("seconds") else "") + ".",
        "",
        f"Machine: {m.get('cpu', '?')}, {m.get('cores', '?')} cores; OpenCL: {'; '.join(m.get('devices', []))}. "
        f"Commit `{m.get('git_commit', '?')}`{' (with uncommitted renderer changes)' if m.get('git_dirty') else ''}.",
        "",
        "PT = plain path tracing (BSDF sampling at the first bounce), PG = PMM path guiding (`--guiding pmm`), both "
        "with next-event estimation and MIS, 1 sample per pixel per frame. relMSE = mean of (I - R)^2 / (R^2 + 0.01) "
        "on linear radiance; FLIP = NVIDIA's flip-evaluator.",
        "",
    ]
    if (report_dir / "reproducibility.md").exists():
        lines += ["A rerun of the same command against this report: [reproducibility.md](reproducibility.md) "
                  "(`bench/compare.py`).", ""]
    if results.get("references"):
        lines += ["References (`rtpg reference`, plain path tracing; cached ones rendered by an earlier run show no "
                  "figures): " + "; ".join(
                      f"{r['scene']}{' (' + r['camera'] + ')' if r.get('camera') else ''} {r['res']} {r['spp']} spp "
                      + (f"{r['seconds']:.1f} s, {r['samples_per_second'] / 1e6:.2f} M samples/s"
                         if "samples_per_second" in r else "cached")
                      for r in results["references"]), ""]
    if results.get("skipped_scenes"):
        lines += ["Skipped scenes: " + ", ".join(f"{k} ({v})" for k, v in results["skipped_scenes"].items()), ""]
    if "equal_frame" in ex:
        lines += _equal_frame(ex["equal_frame"], report_dir, ex.get("convergence"))
    if "equal_time" in ex:
        lines += _equal_time(ex["equal_time"], report_dir, st)
    if "flicker" in ex:
        lines += _flicker(ex["flicker"], st)
    if "convergence" in ex:
        lines += _convergence(ex["convergence"], report_dir, st)
    if "denoised" in ex:
        lines += _denoised(ex["denoised"], report_dir, st)
    if "tradeoffs" in ex:
        lines += _tradeoffs(ex["tradeoffs"], report_dir)
    if "kernels" in ex:
        lines += _kernels(ex["kernels"])
    (report_dir / "README.md").write_text("\n".join(lines) + "\n")
    (report_dir / "results.json").write_text(json.dumps(results, indent=2))
