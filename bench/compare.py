#!/usr/bin/env python3
"""Compares two runs of bench/experiments.py (their results.json): does a rerun of the same
command reproduce the report within noise?

    python3 bench/compare.py docs/results/results.json build/bench-rerun/results.json \
        --markdown docs/results/reproducibility.md

A figure is a number in the tree under "experiments", named by its path. Error figures (relMSE,
FLIP, flicker) come from seeded renders and should agree to rounding; times are wall-clock
measurements on a shared machine and agree only within its noise, so they are listed, not held
to a tolerance. A figure derived from both kinds goes with the times: PG's error at PT's time
budget (relmse_at_pt_budget/pmm) is read at a wall-clock time, which moved it by 10% on
cornell-box between the two committed full runs (docs/results/first-run.json, results.json) while
every error curve agreed exactly; PT's entry there (relmse_at_pt_budget/off) is PT's own final
error, an error figure. The table's headline figures (FLIP ratio, relMSE ratio, guiding overhead,
equal-time ratio) are listed side by side.

Exit status 1 (the rerun does not reproduce the first run) when
- an error figure differs by more than --error-tol;
- a figure is in one run only, either way. A rerun of the same command measures the same figures,
  so a figure missing from the rerun is one it failed to reproduce, and one new in the rerun is
  one the first run lacked (another scene set, a skipped experiment, a "not reached" in one run and
  a number in the other): either way the two runs are not the same measurement;
- a figure is NaN or infinite in either run, whatever its kind: no difference to it can be
  measured, and max() over differences would skip a NaN or stop at it depending on the order.
"""
import argparse
import json
import math
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


# Errors read at a wall-clock time (see the docstring): they move with the machine's noise.
TIMED_ERRORS = ("/relmse_at_pt_budget/pmm",)


def kind(path):
    p = path.lower()
    if "time_ms" in p or p.endswith("_ms") or "_ms[" in p or "seconds" in p:
        return "time"
    if "time_to" in p or "time_ratio" in p:
        return "time"  # a time read off the error axis
    if "/kernels/" in p:
        return "time"  # microbenchmark rates and times
    if any(p.endswith(w) for w in TIMED_ERRORS):
        return "time"
    if any(w in p for w in ERROR_WORDS):
        return "error"
    if p.startswith("/convergence/") and "/static/" in p:
        return "error"  # the static camera's per-frame relMSE, listed without the word
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
        if r.get("time_ratio_pg_pt") is not None:  # a number, or "not reached" (bench/suite/equal_time.py)
            rows.setdefault(scene, {})["equal-time ratio PG/PT"] = r["time_ratio_pg_pt"]
    return rows


def compare(a, b, error_tol):
    la = dict(leaves(a["experiments"], ""))
    lb = dict(leaves(b["experiments"], ""))
    common = sorted(set(la) & set(lb))
    nonfinite = sorted({p for leaf in (la, lb) for p, v in leaf.items() if not math.isfinite(v)})
    by_kind = {"error": [], "time": [], "other": []}
    for p in common:
        if p not in set(nonfinite):
            by_kind[kind(p)].append((rel_diff(la[p], lb[p]), p))
    out = {"common": len(common), "only_first": sorted(set(la) - set(lb)), "only_second": sorted(set(lb) - set(la)),
           "nonfinite": nonfinite, "error_tol": error_tol}
    for k, v in by_kind.items():
        if v:
            d = sorted(x for x, _ in v)
            out[k] = {"count": len(v), "median": statistics.median(d), "p90": d[int(0.9 * (len(d) - 1))],
                      "max": d[-1], "worst": max(v)[1]}
    out["errors_within_tol"] = all(x <= error_tol for x, _ in by_kind["error"]) and \
        not any(kind(p) == "error" for p in nonfinite)
    out["reproduced"] = out["errors_within_tol"] and not (out["only_first"] or out["only_second"] or nonfinite)
    return out


def _paths(title, paths, limit=20):
    """A Markdown list of figure paths (the first `limit`)."""
    if not paths:
        return []
    more = [f"- and {len(paths) - limit} more"] if len(paths) > limit else []
    return [f"{title} ({len(paths)}):", ""] + [f"- `{p}`" for p in paths[:limit]] + more + [""]


def _cell(name, value):
    if value is None:
        return "-"
    if not isinstance(value, (int, float)):
        return str(value)  # "not reached"
    return f"{value:+.0%}" if name == "guiding overhead" else f"{value:.3f}"


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
              "to rounding; times are wall-clock on a shared 2-core machine (PG's error at PT's time budget is read "
              "at a wall-clock time and counts as a time).", ""]
    lines += _paths("Only in the first run", summary["only_first"])
    lines += _paths("Only in the rerun", summary["only_second"])
    lines += _paths("NaN or infinite in either run", summary["nonfinite"])
    lines += [f"Verdict: {'reproduced' if summary['reproduced'] else 'NOT reproduced'} (error figures within "
              f"{summary['error_tol']:g}: {'yes' if summary['errors_within_tol'] else 'no'}; figures in one run only: "
              f"{len(summary['only_first']) + len(summary['only_second'])}; NaN or infinite: "
              f"{len(summary['nonfinite'])}).", "",
              "| scene | figure | first | rerun |", "|---|---|---|---|"]
    for scene in ha:
        for name, va in ha[scene].items():
            vb = hb.get(scene, {}).get(name)
            lines.append(f"| {scene} | {name} | {_cell(name, va)} | {_cell(name, vb)} |")
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
    return 0 if summary["reproduced"] else 1


if __name__ == "__main__":
    sys.exit(main())
