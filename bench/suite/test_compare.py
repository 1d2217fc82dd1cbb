#!/usr/bin/env python3
"""Checks of bench/compare.py on synthetic results (run by ctest)."""
import contextlib
import copy
import io
import json
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import compare  # noqa: E402

RESULTS = {"machine": {"git_commit": "abc"}, "experiments": {
    "equal_frame": {"s": {"methods": {
        "off": {"flip_ldr": 0.2, "relmse_last8": 0.4, "frame_ms": 100.0, "time_ms": {"total": 100.0}},
        "pmm": {"flip_ldr": 0.1, "relmse_last8": 0.2, "frame_ms": 150.0, "time_ms": {"total": 150.0}}}}},
    "equal_time": {"s": {"curves": {"off": {"runs": [{"time_ms": [50.0, 100.0], "relmse": [0.02, 0.01]}]},
                                    "pmm": {"runs": [{"time_ms": [75.0, 150.0], "relmse": [0.04, 0.02]}]}},
                         "relmse_at_pt_budget": {"off": 0.01, "pmm": 0.02}, "time_ratio_pg_pt": 1.5}}}}


def set_leaf(results, path, value):
    """Sets the figure at a compare.leaves path ("/a/b[1]/c") in a copy of results."""
    out = copy.deepcopy(results)
    node, parts = out["experiments"], []
    for part in path.strip("/").split("/"):
        name, *indices = part.replace("]", "").split("[")
        parts += [name] + [int(i) for i in indices]
    for key in parts[:-1]:
        node = node[key]
    node[parts[-1]] = value
    return out


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

    def test_convergence_curves_are_errors(self):
        # The static curves are per-frame relMSE lists without the word in their path.
        self.assertEqual(compare.kind("/convergence/s/static/off[3]"), "error")
        self.assertEqual(compare.kind("/convergence/s/path/pmm/relmse[1]"), "error")
        self.assertEqual(compare.kind("/convergence/s/path/pmm/frames[1]"), "other")

    def test_relmse_at_pt_budget_of_pt_is_an_error(self):
        # PT's error at its own budget is its final error, seeded: a 20% change is a failure.
        b = set_leaf(RESULTS, "/equal_time/s/relmse_at_pt_budget/off", 0.012)
        s = compare.compare(RESULTS, b, 1e-3)
        self.assertFalse(s["errors_within_tol"])
        self.assertFalse(s["reproduced"])
        self.assertAlmostEqual(s["error"]["max"], 0.2 / 1.2)
        self.assertEqual(s["error"]["worst"], "/equal_time/s/relmse_at_pt_budget/off")

    def test_relmse_at_pt_budget_of_pg_moves_with_time_but_its_errors_do_not(self):
        # PG's entry is read at PT's wall-clock time (compare.py's docstring): time noise alone
        # moves it, and it is not held to the error tolerance...
        self.assertEqual(compare.kind("/equal_time/s/relmse_at_pt_budget/pmm"), "time")
        b = set_leaf(RESULTS, "/equal_time/s/relmse_at_pt_budget/pmm", 0.024)
        self.assertTrue(compare.compare(RESULTS, b, 1e-3)["reproduced"])
        # ...but a 20% change of PG's errors, the seeded part of it, is a failure.
        b = set_leaf(b, "/equal_time/s/curves/pmm/runs[0]/relmse[1]", 0.024)
        s = compare.compare(RESULTS, b, 1e-3)
        self.assertFalse(s["errors_within_tol"])
        self.assertEqual(s["error"]["worst"], "/equal_time/s/curves/pmm/runs[0]/relmse[1]")

    def test_figure_missing_from_the_rerun_fails(self):
        b = copy.deepcopy(RESULTS)
        del b["experiments"]["equal_frame"]["s"]["methods"]["pmm"]["frame_ms"]  # a time, not held to a tolerance
        s = compare.compare(RESULTS, b, 1e-3)
        self.assertEqual(s["only_first"], ["/equal_frame/s/methods/pmm/frame_ms"])
        self.assertEqual(s["only_second"], [])
        self.assertTrue(s["errors_within_tol"])
        self.assertFalse(s["reproduced"])

    def test_figure_new_in_the_rerun_fails(self):
        b = copy.deepcopy(RESULTS)
        b["experiments"]["equal_frame"]["s"]["methods"]["pmm"]["mean_pi"] = 0.3
        s = compare.compare(RESULTS, b, 1e-3)
        self.assertEqual(s["only_second"], ["/equal_frame/s/methods/pmm/mean_pi"])
        self.assertFalse(s["reproduced"])
        # Both ways round: the first run's extra figure is missing from the rerun.
        self.assertEqual(compare.compare(b, RESULTS, 1e-3)["only_first"], ["/equal_frame/s/methods/pmm/mean_pi"])

    def test_number_against_not_reached_fails(self):
        b = set_leaf(RESULTS, "/equal_time/s/time_ratio_pg_pt", "not reached")
        s = compare.compare(RESULTS, b, 1e-3)
        self.assertEqual(s["only_first"], ["/equal_time/s/time_ratio_pg_pt"])
        self.assertFalse(s["reproduced"])
        self.assertEqual(compare.headline(b)["s"]["equal-time ratio PG/PT"], "not reached")

    def test_nan_or_infinite_figure_fails_wherever_it_is(self):
        # Every figure in turn, in either run or both: with max() over the differences a NaN
        # anywhere but first passed.
        paths = [p for p, _ in compare.leaves(RESULTS["experiments"])]
        self.assertGreater(len(paths), 10)
        for path in paths:
            for bad in (float("nan"), float("inf")):
                b = set_leaf(RESULTS, path, bad)
                for first, second in ((RESULTS, b), (b, RESULTS), (b, b)):
                    s = compare.compare(first, second, 1e-3)
                    self.assertEqual(s["nonfinite"], [path], path)
                    self.assertFalse(s["reproduced"], f"{path} = {bad}")
                    if compare.kind(path) == "error":
                        self.assertFalse(s["errors_within_tol"], f"{path} = {bad}")

    def test_exit_status_and_markdown(self):
        missing = copy.deepcopy(RESULTS)
        del missing["experiments"]["equal_time"]["s"]["time_ratio_pg_pt"]
        with tempfile.TemporaryDirectory() as d:
            for name, r in (("a", RESULTS), ("b", RESULTS), ("c", missing)):
                (Path(d) / f"{name}.json").write_text(json.dumps(r))
            for second, expected in (("b", 0), ("c", 1)):
                argv = sys.argv
                sys.argv = ["compare.py", str(Path(d) / "a.json"), str(Path(d) / f"{second}.json"),
                            "--markdown", str(Path(d) / "out.md")]
                try:
                    with contextlib.redirect_stdout(io.StringIO()):  # the summary as JSON
                        self.assertEqual(compare.main(), expected, second)
                finally:
                    sys.argv = argv
            text = (Path(d) / "out.md").read_text()
        self.assertIn("Only in the first run (1):", text)
        self.assertIn("- `/equal_time/s/time_ratio_pg_pt`", text)
        self.assertIn("Verdict: NOT reproduced", text)

    def test_headline_figures(self):
        h = compare.headline(RESULTS)["s"]
        self.assertAlmostEqual(h["FLIP ratio PT/PG"], 2.0)
        self.assertAlmostEqual(h["relMSE ratio PG/PT"], 0.5)
        self.assertAlmostEqual(h["guiding overhead"], 0.5)
        self.assertAlmostEqual(h["equal-time ratio PG/PT"], 1.5)


if __name__ == "__main__":
    unittest.main()
