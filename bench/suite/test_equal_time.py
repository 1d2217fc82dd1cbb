#!/usr/bin/env python3
"""Checks of the equal-time figures (bench/suite/equal_time.py) on hand-computed curves (run by ctest)."""
import json
import math
import sys
import unittest
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from suite import equal_time  # noqa: E402
from suite.equal_time import NOT_REACHED  # noqa: E402


def frames(s, k, n=4):
    """A run whose frame i (from 0) ends at s (i + 1) with error k / (i + 1): error = k s / time."""
    return [s * (i + 1) for i in range(n)], [k / (i + 1) for i in range(n)]


class EqualTimeTests(unittest.TestCase):
    def test_methods_take_both_places_in_turn(self):
        self.assertEqual(equal_time.method_order(0), ("off", "pmm"))
        self.assertEqual(equal_time.method_order(1), ("pmm", "off"))
        self.assertEqual(equal_time.method_order(2), ("off", "pmm"))
        for r in range(5):
            self.assertEqual(sorted(equal_time.method_order(r)), ["off", "pmm"])

    def test_power_law_is_interpolated_exactly(self):
        # error = 3 t^-0.7 at uneven times: a straight line in log-log, so the answer is exact.
        t = [1.0, 1.7, 4.2, 9.0, 16.0]
        e = [3.0 * x ** -0.7 for x in t]
        target = 3.0 * 5.3 ** -0.7
        self.assertLess(abs(equal_time.time_to_reach(t, e, target) - 5.3), 1e-12)
        self.assertLess(abs(equal_time.error_at_time(t, e, 5.3) - target), 1e-15)
        # Linear interpolation misses by more than 1% here: the case tells the two apart.
        self.assertGreater(abs(float(np.interp(target, e[::-1], t[::-1])) - 5.3), 0.05)
        self.assertGreater(abs(float(np.interp(5.3, t, e)) - target), 0.01 * target)
        # error = 1 / t: 0.25 is reached at t = 4, between the samples at 2 and 8.
        self.assertAlmostEqual(equal_time.time_to_reach([1.0, 2.0, 8.0], [1.0, 0.5, 0.125], 0.25), 4.0, places=12)
        # On a sample, the sample.
        self.assertEqual(equal_time.error_at_time(t, e, 9.0), e[3])
        self.assertEqual(equal_time.error_at_time(t, e, 1.0), e[0])

    def test_target_reached_at_the_first_point(self):
        # The first sample's time, not an extrapolation before it (0.9 would be at t < 2 on this curve).
        t, e = [2.0, 4.0, 8.0], [0.5, 0.3, 0.2]
        self.assertEqual(equal_time.time_to_reach(t, e, 0.5), 2.0)
        self.assertEqual(equal_time.time_to_reach(t, e, 0.9), 2.0)

    def test_first_crossing_of_a_curve_that_rises_again(self):
        # Accumulated error is noisy: the first time it gets there counts. 0.4 is half-way from 0.8 to
        # 0.2 in log error, so half-way from 1 to 2 in log time: sqrt(2), not the crossing after t = 3.
        t, e = [1.0, 2.0, 3.0, 4.0], [0.8, 0.2, 0.9, 0.1]
        self.assertAlmostEqual(equal_time.time_to_reach(t, e, 0.4), math.sqrt(2.0), places=12)

    def test_curve_that_never_reaches_the_target(self):
        t, e = [1.0, 2.0, 8.0], [1.0, 0.5, 0.2]
        self.assertEqual(equal_time.time_to_reach(t, e, 0.1), NOT_REACHED)
        self.assertEqual(equal_time.error_at_time(t, e, 9.0), NOT_REACHED)  # the run ended sooner
        self.assertEqual(equal_time.error_at_time(t, e, 0.5), NOT_REACHED)  # no image yet
        # Explicit, and no number: arithmetic on it fails instead of going on with a None or a 0.
        self.assertEqual(NOT_REACHED, "not reached")
        with self.assertRaises(TypeError):
            NOT_REACHED / 2.0
        # Every PG run stays above PT's final error of 0.1.
        f = equal_time.figures([(t, [1.0, 0.3, 0.1])], [(t, e), ([1.5, 3.0, 9.0], [0.9, 0.4, 0.15])])
        self.assertEqual(f["pg_time_to_pt_error_ms"], NOT_REACHED)
        self.assertEqual(f["time_ratio_pg_pt"], NOT_REACHED)
        self.assertEqual(f["pg_time_to_pt_error_runs_ms"], [NOT_REACHED, NOT_REACHED])
        # So in results.json too (json writes a None as null).
        self.assertIn('"time_ratio_pg_pt": "not reached"', json.dumps(f))

    def test_median_over_runs_counts_not_reached_as_largest(self):
        self.assertEqual(equal_time.median_over_runs([3.0, NOT_REACHED, 1.0]), 3.0)
        self.assertEqual(equal_time.median_over_runs([3.0, NOT_REACHED, NOT_REACHED]), NOT_REACHED)
        self.assertEqual(equal_time.median_over_runs([1.0, NOT_REACHED]), NOT_REACHED)  # a middle value is
        self.assertEqual(equal_time.median_over_runs([1.0, 3.0]), 2.0)
        with self.assertRaises(ValueError):
            equal_time.median_over_runs([])

    def test_each_run_is_interpolated_on_its_own(self):
        # PG: A = frames(1, 1) (error 1/t), B = frames(2, 4) (8/t), C = frames(4, 2) (8/t). PT's runs
        # end at 5, 6, 7 ms with errors 0.7, 0.8, 0.9: budget 6, target 0.8.
        pt = [([1.0, 5.0], [2.0, 0.7]), ([1.5, 6.0], [2.0, 0.8]), ([2.0, 7.0], [2.0, 0.9])]
        pg = [frames(1.0, 1.0), frames(2.0, 4.0), frames(4.0, 2.0)]
        f = equal_time.figures(pt, pg)
        self.assertEqual(f["pt_time_ms"], 6.0)
        self.assertEqual(f["relmse_at_pt_budget"]["off"], 0.8)
        # A reaches 0.8 at 1/0.8 = 1.25, B never (it ends at error 1), C at 8/0.8 = 10: median 10.
        runs = f["pg_time_to_pt_error_runs_ms"]
        self.assertAlmostEqual(runs[0], 1.25, places=12)
        self.assertEqual(runs[1], NOT_REACHED)
        self.assertAlmostEqual(runs[2], 10.0, places=12)
        self.assertAlmostEqual(f["pg_time_to_pt_error_ms"], 10.0, places=12)
        self.assertAlmostEqual(f["time_ratio_pg_pt"], 10.0 / 6.0, places=12)
        # At t = 6: A ended at 4 (counts as largest), B is on its sample 1.333, C at 8/6: median 4/3.
        self.assertAlmostEqual(f["relmse_at_pt_budget"]["pmm"], 4.0 / 3.0, places=12)
        # Per-frame medians pair B's times (2, 4, 6, 8) with C's errors (2, 1, 0.67, 0.5), error 4/t,
        # a curve no run produced: it reaches 0.8 at 5, not 10.
        per_index = equal_time.time_to_reach(np.median([r[0] for r in pg], axis=0),
                                             np.median([r[1] for r in pg], axis=0), 0.8)
        self.assertAlmostEqual(per_index, 5.0, places=12)

    def test_nan_and_bad_inputs_are_rejected(self):
        t, e = [1.0, 2.0, 4.0], [1.0, 0.5, 0.25]
        nan = float("nan")
        for times, errors in (([1.0, nan, 4.0], e), (t, [1.0, nan, 0.25]), (t, [1.0, math.inf, 0.25]),
                              ([1.0, 2.0, math.inf], e), (t, [1.0, 0.0, 0.25]), ([1.0, 1.0, 4.0], e),
                              ([2.0, 1.0, 4.0], e), (t, e[:2]), ([], [])):
            with self.assertRaises(ValueError, msg=f"{times} {errors}"):
                equal_time.time_to_reach(times, errors, 0.3)
            with self.assertRaises(ValueError, msg=f"{times} {errors}"):
                equal_time.error_at_time(times, errors, 3.0)
            with self.assertRaises(ValueError, msg=f"{times} {errors}"):
                equal_time.figures([(t, e)], [(times, errors)])
            with self.assertRaises(ValueError, msg=f"{times} {errors}"):
                equal_time.figures([(times, errors)], [(t, e)])
        for bad in (nan, math.inf, 0.0, -1.0, None, "0.3"):
            with self.assertRaises(ValueError, msg=repr(bad)):
                equal_time.time_to_reach(t, e, bad)
            with self.assertRaises(ValueError, msg=repr(bad)):
                equal_time.error_at_time(t, e, bad)
        with self.assertRaises(ValueError):
            equal_time.median_over_runs([1.0, nan])
        with self.assertRaises(ValueError):
            equal_time.figures([], [(t, e)])


if __name__ == "__main__":
    unittest.main()
