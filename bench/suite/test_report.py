#!/usr/bin/env python3
"""Checks of the report's verdicts (bench/suite/report.py; run by ctest): PT and PG render with one
seed, so their per-frame errors move together and the verdict pairs them."""
import random
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from suite import report  # noqa: E402


def runs(shift, seed=3, frames=8):
    """Two methods' per-frame errors: a shared frame-to-frame noise (the seed's), a little of each
    method's own, and PG `shift` below PT."""
    rng = random.Random(seed)
    shared = [rng.gauss(1.0, 0.1) for _ in range(frames)]
    pt = [s + rng.gauss(0.0, 0.005) for s in shared]
    pg = [(1.0 - shift) * s + rng.gauss(0.0, 0.005) for s in shared]
    return pt, pg


def mean_sem(values):
    m = sum(values) / len(values)
    return m, (sum((v - m) ** 2 for v in values) / (len(values) - 1) / len(values)) ** 0.5


class PairedVerdictTests(unittest.TestCase):
    def test_a_shift_hidden_by_the_shared_noise_is_found(self):
        pt, pg = runs(0.05)
        (a, sa), (b, sb) = mean_sem(pt), mean_sem(pg)
        self.assertEqual(report.verdict(a, sa, b, sb), "no significant difference")
        said, mean, sem = report.paired_verdict(pt, pg)
        self.assertEqual(said, "PG better")
        self.assertLess(mean, 0.0)
        self.assertGreater(sem, 0.0)
        self.assertEqual(report.paired_verdict(pg, pt)[0], "PT better")

    def test_no_shift_is_no_difference(self):
        for seed in range(20):
            pt, pg = runs(0.0, seed)
            self.assertEqual(report.paired_verdict(pt, pg)[0], "no significant difference", seed)

    def test_the_frames_come_from_the_convergence_curve_where_the_figures_lack_them(self):
        curve = [float(i) for i in range(32)]
        self.assertEqual(report._frames_of({}, {"s": {"static": {"off": curve}}}, "s", "off", 32), curve[24:32])
        self.assertEqual(report._frames_of({"relmse_frames": [1.0, 2.0]}, None, "s", "off", 32), [1.0, 2.0])
        self.assertIsNone(report._frames_of({}, None, "s", "off", 32))


if __name__ == "__main__":
    unittest.main()
