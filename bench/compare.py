#!/usr/bin/env python3
"""Compares two runs of bench/experiments.py (their results.json): does a rerun of the same
command reproduce the report within noise?

    python3 bench/compare.py docs/results/results.json build/bench-rerun/results.json \
        --markdown docs/results/reproducibility.md

Error figures (relMSE, FLIP, flicker) come from seeded renders and should agree to rounding;
times are wall-clock measurements on a shared machine and agree only within its noise. The
table's headline figures (FLIP ratio, relMSE ratio, guiding overhead, equal-time ratio) are
listed side by side. Exit status 1 when an error figure differs by more than --error-tol.
"""
import argparse
import json
import statistics
import sys
from pathlib import Path

ERROR_WORDS = ("relmse", "flip", "flicker", "mean_pi", "guided_fraction", "trained_fraction")


def leaves(node, prefix=""):
    """(path, value) of every number in a JSON tree."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield from leaves(v, f"{prefix}/{k}")
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from leaves(v, f"{prefix}[{i}]")
    elif isinstance(node, (int, float)) and not isinstance(node, bool):
        yield prefix, float(node)


def kind(path):
    p = path.lower()
    if "time_ms" in p or p.endswith("_ms") or "_ms[" in p or "seconds" in p:
        return "time"
    if "budget" in p or "time_to" in p or "time_ratio" in p:
        return "time"  # an error read off the time axis, or a time read off the error axis
    if "/kernels/" in p:
        return "time"  # microbenchmark rates and times
    if any(w in p for w in ERROR_WORDS):
        return "error"
    return "other"


def rel_diff(a, b):
    scale = max(abs(a), abs(b))
    return 0.0 if scale == 0.0 else abs(a - b) / scale


def headline(results):
    """The report's headline figures per scene."""
    rows = {}
    ex = results["experiments"]
    for scene, r in ex.get("equal_frame", {}).items():
        pt, pg = r["methods"]["off"], r["methods"]["pmm"]
        rows.setdefault(scene, {}).update({
            "FLIP ratio PT/PG": pt["flip_ldr"] / pg["flip_ldr"],
            "relMSE ratio PG/PT": pg["relmse_last8"] / pt["relmse_last8"],
            "guiding overhead": (pg["frame_ms"] - pt["frame_ms"]) / pt["frame_ms"],
        })
    for scene, r in ex.get("equal_time", {}).items():
        if r.get("time_ratio_pg_pt"):
            rows.setdefault(scene, {})["equal-time ratio PG/PT"] = r["time_ratio_pg_pt"]
    return rows


def compare(a, b, error_tol):
    la = dict(leaves(a["experiments"], ""))
    lb = dict(leaves(b["experiments"], ""))
    common = sorted(set(la) & set(lb))
    by_kind = {"error": [], "time": [], "other": []}
    for p in common:
        by_kind[kind(p)].append((rel_diff(la[p], lb[p]), p))
    out = {"common": len(common), "only_first": len(set(la) - set(lb)), "only_second": len(set(lb) - set(la))}
    for k, v in by_kind.items():
        if v:
            d = sorted(x for x, _ in v)
            out[k] = {"count": len(v), "median": statistics.median(d), "p90": d[int(0.9 * (len(d) - 1))],
                      "max": d[-1], "worst": max(v)[1]}
    out["errors_within_tol"] = not by_kind["error"] or max(x for x, _ in by_kind["error"]) <= error_tol
    return out


def markdown(a, b, summary, path_a, path_b):
    ha, hb = headline(a), headline(b)
    lines = ["# Reproducibility: the report against a rerun of the same command", "",
             f"- first: `{path_a}` ({a.get('started', '?')} to {a.get('finished', '?')}, commit "
             f"`{a['machine'].get('git_commit', '?')[:10]}`)",
             f"- rerun: `{path_b}` ({b.get('started', '?')} to {b.get('finished', '?')}, commit "
             f"`{b['machine'].get('git_commit', '?')[:10]}`)",
             f"- command: `{a.get('command', '?')}` and `{b.get('command', '?')}`", "",
             f"{summary['common']} figures in both runs. Relative differences |a - b| / max(|a|, |b|):", "",
             "| kind | figures | median | 90th percentile | max | largest at |", "|---|---|---|---|---|---|"]
    for k in ("error", "time", "other"):
        if k in summary:
            s = summary[k]
            worst = f"`{s['worst']}`" if s["max"] > 0 else "-"
            lines.append(f"| {k} | {s['count']} | {s['median']:.2%} | {s['p90']:.2%} | {s['max']:.2%} | {worst} |")
    lines += ["", "Error figures come from seeded renders (the same seed gives the same image), so they should agree "
              "to rounding; times are wall-clock on a shared 2-core machine.", "",
              "| scene | figure | first | rerun |", "|---|---|---|---|"]
    for scene in ha:
        for name, va in ha[scene].items():
            vb = hb.get(scene, {}).get(name)
            fmt = (lambda v: f"{v:+.0%}") if name == "guiding overhead" else (lambda v: f"{v:.3f}")
            lines.append(f"| {scene} | {name} | {fmt(va)} | {fmt(vb) if vb is not None else '-'} |")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("first")
    ap.add_argument("second")
    ap.add_argument("--markdown", help="write the comparison as Markdown here")
    ap.add_argument("--error-tol", type=float, default=1e-3, help="largest relative difference of an error figure")
    args = ap.parse_args()
    a = json.loads(Path(args.first).read_text())
    b = json.loads(Path(args.second).read_text())
    summary = compare(a, b, args.error_tol)
    print(json.dumps(summary, indent=2))
    if args.markdown:
        Path(args.markdown).write_text(markdown(a, b, summary, args.first, args.second))
    return 0 if summary["errors_within_tol"] else 1


if __name__ == "__main__":
    sys.exit(main())
