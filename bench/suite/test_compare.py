#!/usr/bin/env python3
"""Checks of bench/compare.py on synthetic results (run by ctest)."""
import copy
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import compare  # noqa: E402

RESULTS = {"machine": {"git_commit": "abc"}, "experiments": {
    "equal_frame": {"s": {"methods": {
        "off": {"flip_ldr": 0.2, "relmse_last8": 0.4, "frame_ms": 100.0, "time_ms": {"total": 100.0}},
        "pmm": {"flip_ldr": 0.1, "relmse_last8": 0.2, "frame_ms": 150.0, "time_ms": {"total": 150.0}}}}},
    "equal_time": {"s": {"relmse_at_pt_budget": {"off": 0.01, "pmm": 0.02}, "time_ratio_pg_pt": 1.5}}}}


class CompareTests(unittest.TestCase):
    def test_identical_runs_agree(self):
        s = compare.compare(RESULTS, copy.deepcopy(RESULTS), 0.0)
        self.assertTrue(s["errors_within_tol"])
        self.assertEqual(s["error"]["max"], 0.0)
        self.assertEqual(s["time"]["max"], 0.0)

    def test_time_noise_is_not_an_error_difference(self):
        b = copy.deepcopy(RESULTS)
        b["experiments"]["equal_frame"]["s"]["methods"]["pmm"]["frame_ms"] = 300.0
        b["experiments"]["equal_time"]["s"]["relmse_at_pt_budget"]["pmm"] = 0.03
        s = compare.compare(RESULTS, b, 0.0)
        self.assertTrue(s["errors_within_tol"])
        self.assertAlmostEqual(s["time"]["max"], 0.5)

    def test_changed_error_is_reported(self):
        b = copy.deepcopy(RESULTS)
        b["experiments"]["equal_frame"]["s"]["methods"]["off"]["flip_ldr"] = 0.25
        s = compare.compare(RESULTS, b, 1e-3)
        self.assertFalse(s["errors_within_tol"])
        self.assertAlmostEqual(s["error"]["max"], 0.2)
        self.assertIn("flip_ldr", s["error"]["worst"])

    def test_headline_figures(self):
        h = compare.headline(RESULTS)["s"]
        self.assertAlmostEqual(h["FLIP ratio PT/PG"], 2.0)
        self.assertAlmostEqual(h["relMSE ratio PG/PT"], 0.5)
        self.assertAlmostEqual(h["guiding overhead"], 0.5)
        self.assertAlmostEqual(h["equal-time ratio PG/PT"], 1.5)


if __name__ == "__main__":
    unittest.main()
