#!/usr/bin/env python3
"""Checks of the metric wrappers on known cases (run by ctest)."""
import sys
import unittest
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from suite import metrics  # noqa: E402


class MetricTests(unittest.TestCase):
    def setUp(self):
        rng = np.random.default_rng(1)
        self.reference = rng.uniform(0.05, 2.0, size=(64, 96, 3)).astype(np.float32)

    def test_identical_images_give_zero(self):
        r = self.reference
        self.assertEqual(metrics.relmse(r, r), 0.0)
        self.assertEqual(metrics.flip_ldr(r, r), 0.0)
        self.assertEqual(metrics.flip_hdr(r, r), 0.0)
        self.assertEqual(metrics.flicker([r, r, r]), 0.0)

    def test_paired_ratio_compares_frame_by_frame(self):
        base = [1.0, 2.0, None, 4.0]
        other = [2.0, 4.0, 5.0, 8.0]  # twice base wherever both have a frame
        r = metrics.paired_ratio(base, other)
        self.assertEqual(r["pairs"], 3)
        self.assertEqual(r["higher"], 3)
        self.assertAlmostEqual(r["ratio_of_means"], 2.0)
        self.assertAlmostEqual(r["mean_base"], 7.0 / 3.0)  # frames with a value in both runs only
        self.assertAlmostEqual(r["mean_other"], 14.0 / 3.0)
        self.assertAlmostEqual(r["mean_ratio"], 2.0)
        self.assertAlmostEqual(r["sem"], 0.0)
        # Common noise cancels: frames that vary 10x between them but keep a 1.1 ratio.
        r = metrics.paired_ratio([1.0, 10.0, 0.5, 3.0], [1.1, 11.0, 0.55, 3.3])
        self.assertAlmostEqual(r["mean_ratio"], 1.1)
        self.assertLess(r["sem"], 1e-12)
        self.assertEqual(metrics.paired_ratio([1.0, 2.0], [1.0, 1.0])["higher"], 0)
        with self.assertRaises(ValueError):
            metrics.paired_ratio([None], [1.0])

    def test_key_exposure_puts_the_lit_log_average_at_the_key(self):
        # Half the pixels at luminance 0.045 and half at 0.18: log-average 0.09, so exposure 2
        # (0.18 / 0.09); black background pixels are left out, a non-power of two rounds to one.
        img = np.zeros((4, 6, 3), np.float32)
        img[:2, :2] = 0.045
        img[2:, :2] = 0.18
        self.assertEqual(metrics.key_exposure(img), 2.0)
        self.assertEqual(metrics.key_exposure(np.full((2, 2, 3), 0.18 / 3.0, np.float32)), 4.0)  # log2(3) = 1.58
        with self.assertRaises(ValueError):
            metrics.key_exposure(np.zeros((2, 2, 3), np.float32))
        # A brighter LDR image at the scene's exposure is what FLIP compares: exposure changes FLIP.
        self.assertNotEqual(metrics.flip_ldr(self.reference * 0.5, self.reference, 1.0),
                            metrics.flip_ldr(self.reference * 0.5, self.reference, 0.05))

    def test_known_perturbation_gives_expected_relmse(self):
        # I = R + d everywhere: relMSE = mean(d^2 / (R^2 + 0.01)), computed independently here.
        d = 0.1
        expected = float(np.mean(d * d / (self.reference.astype(np.float64) ** 2 + 0.01)))
        self.assertAlmostEqual(metrics.relmse(self.reference + d, self.reference), expected, places=6)
        # Scaling by (1 + s) on a bright image: relMSE ~ s^2 R^2 / (R^2 + 0.01) < s^2.
        self.assertLess(metrics.relmse(self.reference * 1.1, self.reference), 0.01)

    def test_flip_rises_with_noise(self):
        rng = np.random.default_rng(2)
        previous = (0.0, 0.0)
        for sigma in (0.02, 0.1, 0.4):
            noisy = np.maximum(self.reference * (1.0 + sigma * rng.standard_normal(self.reference.shape)), 0.0)
            now = (metrics.flip_ldr(noisy.astype(np.float32), self.reference),
                   metrics.flip_hdr(noisy.astype(np.float32), self.reference))
            self.assertGreater(now[0], previous[0])
            self.assertGreater(now[1], previous[1])
            previous = now

    def test_flicker_is_mean_squared_difference(self):
        a = np.zeros((4, 4, 3), np.float32)
        b = np.full((4, 4, 3), 0.5, np.float32)
        self.assertAlmostEqual(metrics.flicker([a, b, a]), 0.25)

    def test_box_downsample_averages_blocks(self):
        img = np.arange(4 * 6 * 3, dtype=np.float32).reshape(4, 6, 3)
        small = metrics.downsample_box(img, 2)
        self.assertEqual(small.shape, (2, 3, 3))
        self.assertAlmostEqual(float(small[1, 2, 0]), float(np.mean(img[2:4, 4:6, 0])), places=5)
        self.assertAlmostEqual(float(small.mean()), float(img.mean()), places=4)
        with self.assertRaises(ValueError):
            metrics.downsample_box(img, 4)

    def test_tonemap_matches_documented_curve(self):
        # 0 -> 0, large -> 1, and the ACES fit at x = 1 (0.8038...) through the sRGB curve.
        t = metrics.tonemap_srgb(np.array([[[0.0, 1.0, 1e6]]], np.float32))[0, 0]
        aces1 = (2.51 + 0.03) / (2.43 + 0.59 + 0.14)
        self.assertAlmostEqual(float(t[0]), 0.0)
        self.assertAlmostEqual(float(t[1]), 1.055 * aces1 ** (1 / 2.4) - 0.055, places=5)
        self.assertAlmostEqual(float(t[2]), 1.0, places=5)


if __name__ == "__main__":
    unittest.main()
