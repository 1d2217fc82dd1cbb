#!/usr/bin/env python3
"""The benchmark pipeline end to end at CI size (run by ctest as bench_quick): every experiment
writes its figures, plots and report, and a rerun of seeded renders reproduces the errors.
It checks that the pipeline works, not speed."""
import json
import math
import statistics
import subprocess
import sys
import unittest
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))
import compare  # noqa: E402
import experiments  # noqa: E402
from suite import equal_time, metrics, runner  # noqa: E402

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
        self.assertEqual(set(ex), {"equal_frame", "equal_time", "flicker", "convergence", "denoised", "tradeoffs",
                                   "kernels"})
        for name in ("equal_frame", "equal_time", "flicker", "convergence", "denoised"):
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
            self.assertEqual(set(r["sweep"]), {"2", "8"})
            self.assertTrue(Path(r["figure"]).exists())
        for scene, r in ex["convergence"].items():
            self.assertEqual(len(r["static"]["pmm"]), 8)
            self.assertEqual(r["path"]["pmm"]["frames"], [1, 4])
            self.assertTrue(all(e > 0 for e in r["path"]["off"]["relmse"]))
        for scene, r in ex["equal_time"].items():
            for c in r["curves"].values():
                self.assertEqual(len(c["runs"]), 2)
                for run in c["runs"]:
                    t = run["time_ms"]
                    self.assertEqual((len(t), len(run["relmse"])), (6, 6))
                    self.assertTrue(all(b > a for a, b in zip(t, t[1:])), "time must increase")
            pt = r["curves"]["off"]["runs"]
            self.assertEqual(r["pt_time_ms"], statistics.median(run["time_ms"][-1] for run in pt))
            self.assertEqual(r["relmse_at_pt_budget"]["off"], statistics.median(run["relmse"][-1] for run in pt))
            for key in ("time_ratio_pg_pt", "pg_time_to_pt_error_ms"):
                v = r[key]
                self.assertTrue(v == equal_time.NOT_REACHED or (math.isfinite(v) and v > 0), f"{scene} {key} = {v}")
        for r in ex["flicker"].values():
            self.assertGreater(r["methods"]["off"]["flicker_mse"], 0.0)
        for scene, r in ex["denoised"].items():
            for method in ("off", "pmm"):
                m = r["static"][method]
                for key in ("relmse", "relmse_last8", "flip_ldr", "flip_ldr_noisy", "relmse_noisy"):
                    self.assertTrue(math.isfinite(m[key]) and m[key] > 0, f"{scene} {method} {key} = {m[key]}")
                self.assertGreater(m["time_ms"]["svgf_atrous"], 0.0)
                self.assertEqual(r["path"][method]["frames"], [1, 4])
            self.assertEqual(set(r["cost"]), {"48x32", "96x64"})
            self.assertTrue(Path(r["figure"]).exists())
        rows = ex["tradeoffs"]["cornell-indirect"]["rows"]
        self.assertEqual(rows["PT (no guiding)"]["train_ms"], 0.0)
        self.assertGreater(rows["fixed N=20"]["train_ms"], 0.0)

    def test_flip_is_that_of_frame_t_and_beats_a_black_image(self):
        # FLIP is in [0, 1] by construction, so "below 1" says nothing. The figure must be FLIP of
        # the frame after T frames (saved by --save-frames) against the run's reference, and lower
        # than a black image's FLIP against that reference: a render that lost its light or turned
        # to NaN (the tonemap shows NaN as black) fails. A constant image of the reference's mean is
        # no bound at this size: at 1 spp, cornell-indirect's FLIP is above that image's.
        for scene, r in self.results["experiments"]["equal_frame"].items():
            ref = metrics.load_exr(r["reference"])
            exposure = r.get("exposure", 1.0)
            black = metrics.flip_ldr(np.zeros_like(ref), ref, exposure)
            for method in ("off", "pmm"):
                frame = runner.saved_frame(OUT / "static" / scene / f"{method}.exr", r["T"] - 1)
                flip = r["methods"][method]["flip_ldr"]
                self.assertAlmostEqual(flip, metrics.flip_ldr(metrics.load_exr(frame), ref, exposure), places=6,
                                       msg=frame)
                self.assertLess(flip, black, f"{scene} {method}")

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
        self.assertTrue(summary["reproduced"], summary)
        self.assertGreater(summary["error"]["count"], 10)


if __name__ == "__main__":
    unittest.main()
