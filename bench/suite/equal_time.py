"""Equal-time figures (bench/experiments.py, experiment equal_time) from the (cumulative wall time,
relMSE of the accumulated image) curves of repeated runs of PT and PG. One method throughout:

- every figure is read off one run's own curve and then the median over the runs is taken; never
  off per-frame medians of several runs (the median time and the median error of frame i may come
  from different runs, so that pair is not a point any run produced);
- between two samples of a curve, interpolation is linear in log time and log error, where an
  error falling as a power of time (Monte Carlo's 1/t) is a straight line, so it is exact there;
  nothing is extrapolated beyond a run's first or last sample;
- a run that never gets there within its frames (never reaches the error, or ends before the time)
  counts as larger than every run that does: a later time, or a larger error (for PG's error at
  PT's budget that is conservative: a PG run faster than PT's budget gives no error at it). When the
  median falls on such runs the figure is NOT_REACHED, a string, so that arithmetic on it fails
  loudly instead of passing for a number (a None was tested with `if x:`, where 0 reads the same).

The figures: PT's time budget is the median over PT runs of the time each took for all its frames,
and the target is the median of their final errors (PT at its own budget). PG's time to PT's error
is the median over PG runs of the time each reaches the target; PG's error at PT's budget is the
median over PG runs of each run's error at that time.

`runs` makes the curves (PT and PG alternating, each run accumulating its frames against a
reference) and `figures` reads them. Plain Python, no NumPy, so that the same experiment runs where
no package can be installed (tools/gpu_equal_time.py, on the GPU bundle's machine).
"""
import bisect
import itertools
import math
import statistics

from . import runner

NOT_REACHED = "not reached"


def check_curve(times, errors):
    """(times, errors) as lists of floats; ValueError unless both are finite and positive (their
    logs are taken), of the same non-zero length, and the times strictly increase (they are
    cumulative)."""
    try:
        times = [float(t) for t in times]
        errors = [float(e) for e in errors]
    except TypeError:
        raise ValueError("a curve's times and errors must be sequences of numbers") from None
    if len(times) != len(errors) or not times:
        raise ValueError(f"a curve needs as many times as errors, at least one: {len(times)}, {len(errors)}")
    if not all(math.isfinite(v) for v in times + errors):
        raise ValueError("a curve with a NaN or infinite time or error")
    if any(v <= 0.0 for v in times + errors):
        raise ValueError("times and errors must be positive (log-log interpolation)")
    if any(b <= a for a, b in zip(times, times[1:])):
        raise ValueError("cumulative times must strictly increase")
    return times, errors


def _check_value(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite positive number, not {value!r}")
    return float(value)


def _log_lerp(x0, x1, y0, y1, x):
    """y at x on the straight line through (log x0, log y0) and (log x1, log y1)."""
    lx0, lx1, ly0, ly1 = math.log(x0), math.log(x1), math.log(y0), math.log(y1)
    return math.exp(ly0 + (math.log(x) - lx0) * (ly1 - ly0) / (lx1 - lx0))


def time_to_reach(times, errors, target):
    """First time at which one run's error is at or below `target`: log-log between the last sample
    above it and the first at or below it; the first sample's time when that one already is (the
    earliest time measured); NOT_REACHED when no sample gets there."""
    times, errors = check_curve(times, errors)
    target = _check_value("target", target)
    i = next((k for k, e in enumerate(errors) if e <= target), None)
    if i is None:
        return NOT_REACHED
    if i == 0:
        return float(times[0])
    # Here the error is the abscissa: time as a power of error through the two samples.
    return _log_lerp(errors[i - 1], errors[i], times[i - 1], times[i], target)


def error_at_time(times, errors, t):
    """One run's error at time `t`, log-log between the samples around it; NOT_REACHED when `t` is
    outside the run's samples (it ended sooner, or had no image yet)."""
    times, errors = check_curve(times, errors)
    t = _check_value("time", t)
    if t < times[0] or t > times[-1]:
        return NOT_REACHED
    i = bisect.bisect_left(times, t)  # times[i - 1] < t <= times[i], or i = 0 when t = times[0]
    if times[i] == t:
        return float(errors[i])
    return _log_lerp(times[i - 1], times[i], errors[i - 1], errors[i], t)


def median_over_runs(values):
    """Median of per-run figures where NOT_REACHED counts as larger than any number: NOT_REACHED
    when the median falls on it (for an even count, when either middle value is NOT_REACHED)."""
    values = list(values)
    if not values:
        raise ValueError("no runs")
    keyed = [math.inf if v == NOT_REACHED else _check_value("a run's figure", v) for v in values]
    m = statistics.median(keyed)
    return NOT_REACHED if math.isinf(m) else float(m)


def figures(pt_runs, pg_runs):
    """The equal-time figures of results.json from PT's and PG's runs, each a (times, errors) pair
    (see the module's docstring); relmse_at_pt_budget["off"] is the target, PT at its own budget."""
    pt = [check_curve(t, e) for t, e in pt_runs]
    pg = [check_curve(t, e) for t, e in pg_runs]
    if not pt or not pg:
        raise ValueError("each method needs at least one run")
    budget = statistics.median(float(t[-1]) for t, _ in pt)
    target = statistics.median(float(e[-1]) for _, e in pt)
    pg_times = [time_to_reach(t, e, target) for t, e in pg]
    pg_time = median_over_runs(pg_times)
    return {"pt_time_ms": budget,
            "relmse_at_pt_budget": {"off": target,
                                    "pmm": median_over_runs(error_at_time(t, e, budget) for t, e in pg)},
            "pg_time_to_pt_error_ms": pg_time, "pg_time_to_pt_error_runs_ms": pg_times,
            "time_ratio_pg_pt": NOT_REACHED if pg_time == NOT_REACHED else pg_time / budget}


def method_order(repeat):
    """The methods' order in repeat `repeat` (from 0): PT then PG, then PG then PT, and so on. A
    run's place in the pair moves its frame times by 1-4% on the 2-core machine
    (docs/host-path-tracer.md, "The order within a round"); taking both places in turn keeps
    that out of the ratio of the two methods' times (exactly so for an even number of repeats)."""
    return runner.METHODS if repeat % 2 == 0 else runner.METHODS[::-1]


def runs(scene, res, frames, repeats, out, reference, extra=(), pg_extra=()):
    """The curves of `repeats` runs of each method (`rtpg render --accumulate --reference`, seeds
    100, 101, ...), PT and PG alternating run by run (method_order: each repeat's pair in the
    reverse order of the one before), so that a machine whose speed drifts slows both alike
    rather than one method's block of runs: {method: {"runs": [{"time_ms": cumulative
    frame totals, "relmse": accumulated relMSE per frame}]}}. Frame 0 also builds the OpenCL
    programs (from the disk cache) and compiles work-group functions, a one-time start-up cost, so
    its time is replaced by the median frame's. `extra`: more rtpg arguments for both methods;
    `pg_extra`: for the guided runs only (a variant of guiding against the same path tracing)."""
    curves = {method: {"runs": []} for method in runner.METHODS}
    for r in range(repeats):
        for method in method_order(r):
            stats, _ = runner.render(scene, res, frames, method, out, f"{method}-r{r}", reference=reference,
                                     extra=["--accumulate", "--seed", 100 + r, *extra,
                                            *(pg_extra if method == "pmm" else ())])
            ms = [f["time_ms"]["total"] for f in stats["frames"]]
            ms[0] = statistics.median(ms[1:]) if len(ms) > 1 else ms[0]
            curves[method]["runs"].append({"time_ms": list(itertools.accumulate(ms)),
                                           "relmse": [f["relmse_accumulated"] for f in stats["frames"]]})
    return curves


def figures_of(curves):
    """figures() of the curves `runs` made."""
    return figures([(r["time_ms"], r["relmse"]) for r in curves["off"]["runs"]],
                   [(r["time_ms"], r["relmse"]) for r in curves["pmm"]["runs"]])
