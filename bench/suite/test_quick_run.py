#!/usr/bin/env python3
"""The benchmark pipeline end to end at CI size (run by ctest as bench_quick): every experiment
writes its figures, plots and report, and a rerun of seeded renders reproduces the errors.
It checks that the pipeline works, not speed."""
import json
import math
import subprocess
import sys
import unittest
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))
import compare  # noqa: E402

OUT = Path(sys.argv.pop(1)) if len(sys.argv) > 1 else BENCH.parent / "build" / "bench-quick"


def run(out, *extra):
    subprocess.run([sys.executable, str(BENCH / "experiments.py"), "--quick", "--out", str(out), *extra], check=True)
    return json.loads((out / "results.json").read_text())


class QuickRun(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.results = run(OUT)

    def test_every_experiment_and_scene(self):
        ex = self.results["experiments"]
        self.assertEqual(set(ex), {"equal_frame", "equal_time", "flicker", "convergence", "tradeoffs", "kernels"})
        for name in ("equal_frame", "equal_time", "flicker", "convergence"):
            self.assertEqual(set(ex[name]), {"cornell-box", "cornell-indirect"}, name)
        self.assertEqual(set(ex["tradeoffs"]), {"cornell-indirect"})
        self.assertIn("benchmarks", ex["kernels"], ex["kernels"].get("skipped"))

    def test_figures_are_finite_and_plots_exist(self):
        ex = self.results["experiments"]
        for scene, r in ex["equal_frame"].items():
            for method in ("off", "pmm"):
                m = r["methods"][method]
                for key in ("relmse", "relmse_last8", "flip_ldr", "flip_hdr", "frame_ms"):
                    self.assertTrue(math.isfinite(m[key]) and m[key] > 0, f"{scene} {method} {key} = {m[key]}")
                self.assertLess(m["flip_ldr"], 1.0)
            self.assertEqual(set(r["sweep"]), {"2", "8"})
            self.assertTrue(Path(r["figure"]).exists())
        for scene, r in ex["convergence"].items():
            self.assertEqual(len(r["static"]["pmm"]), 8)
            self.assertEqual(r["path"]["pmm"]["frames"], [1, 4])
            self.assertTrue(all(e > 0 for e in r["path"]["off"]["relmse"]))
        for scene, r in ex["equal_time"].items():
            for c in r["curves"].values():
                self.assertEqual(len(c["time_ms"]), 6)
                self.assertTrue(all(b > a for a, b in zip(c["time_ms"], c["time_ms"][1:])), "time must increase")
        for r in ex["flicker"].values():
            self.assertGreater(r["methods"]["off"]["flicker_mse"], 0.0)
        rows = ex["tradeoffs"]["cornell-indirect"]["rows"]
        self.assertEqual(rows["PT (no guiding)"]["train_ms"], 0.0)
        self.assertGreater(rows["fixed N=20"]["train_ms"], 0.0)

    def test_each_experiment_has_its_own_json(self):
        for name in self.results["experiments"]:
            own = json.loads((OUT / f"{name}.json").read_text())
            self.assertEqual(own["experiment"], name)
            self.assertEqual(own["figures"], self.results["experiments"][name])
            self.assertIn("git_commit", own["machine"])

    def test_report(self):
        text = (OUT / "report" / "README.md").read_text()
        self.assertIn("| scene | PT FLIP | PG FLIP | ratio | relMSE ratio | frame time PT | frame time PG | guiding overhead |",
                      text)
        for figure in ("cornell-box-comparison.png", "cornell-indirect-equal-time.png",
                       "cornell-indirect-convergence.png", "cornell-indirect-tradeoffs.png"):
            self.assertTrue((OUT / "report" / "figures" / figure).exists(), figure)

    def test_rerun_reproduces_the_errors(self):
        rerun = run(OUT.with_name(OUT.name + "-rerun"), "--only", "equal_frame", "--scenes", "cornell-indirect")
        first = {"machine": {}, "experiments": {"equal_frame": {
            "cornell-indirect": self.results["experiments"]["equal_frame"]["cornell-indirect"]}}}
        summary = compare.compare(first, rerun, 0.0)
        self.assertTrue(summary["errors_within_tol"], summary)
        self.assertGreater(summary["error"]["count"], 10)


if __name__ == "__main__":
    unittest.main()
