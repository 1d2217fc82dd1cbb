#!/usr/bin/env python3
"""bench/variant_sweep.py (run by ctest as bench_variant_sweep): its statistics on hand-computed
cases, a tiny sweep end to end (a finite ratio per variant; a rerun from the cached renders prints
the same table) and the refusal of malformed variants."""
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))
import variant_sweep  # noqa: E402
from suite import runner  # noqa: E402


class Statistics(unittest.TestCase):
    def test_mean_and_standard_error(self):  # the shared helper the sweep uses
        m, se = runner.mean_sem([1.0, 2.0, 3.0])
        self.assertEqual(m, 2.0)
        self.assertAlmostEqual(se, 1.0 / math.sqrt(3.0), places=15)  # stdev 1 over sqrt(3)
        m, se = runner.mean_sem([0.7])
        self.assertEqual(m, 0.7)
        self.assertTrue(math.isnan(se))  # one seed: no error estimate

    def test_window_is_the_last_frames(self):
        stats = {"frames": [{"relmse": float(i)} for i in range(10)]}
        self.assertEqual(variant_sweep.window_relmse(stats, 3), 8.0)  # frames 7, 8, 9
        self.assertEqual(variant_sweep.window_relmse(stats, 10), 4.5)

    def test_curve_is_each_windows_ratio_of_sums(self):
        def run(errors):
            return {"frames": [{"relmse": e} for e in errors]}
        # Seed 1: windows (1+3)/(2+2) = 1 and (2+2)/(4+4) = 0.5; seed 2: 4/8 and 2/4 = 0.5.
        pg = [run([1.0, 3.0, 2.0, 2.0, 9.0]), run([2.0, 2.0, 1.0, 1.0, 9.0])]
        pt = [run([2.0, 2.0, 4.0, 4.0, 1.0]), run([4.0, 4.0, 2.0, 2.0, 1.0])]
        # The fifth frame is no whole window: left out.
        self.assertEqual(variant_sweep.window_curve(pg, pt, 2), [(1, 2, 0.75), (3, 4, 0.5)])
        self.assertEqual(variant_sweep.window_curve(pg, pt, 5), [(1, 5, (17 / 13 + 15 / 13) / 2)])

    def test_table_has_a_row_per_variant_and_the_mean(self):
        table = {"a": {"s1": (0.5, 0.01), "s2": (1.0, 0.02)}}
        text = variant_sweep.markdown_table(["s1", "s2"], table)
        self.assertEqual(text.splitlines()[0], "| variant | s1 | s2 | mean |")
        self.assertEqual(text.splitlines()[2], "| a | 0.500 ± 0.010 | 1.000 ± 0.020 | 0.750 |")


class CacheKey(unittest.TestCase):
    def test_follows_the_scene_files_bytes(self):
        """A run cached before its scene file was edited is not served after: its errors were against
        the old scene's reference."""
        with tempfile.TemporaryDirectory() as d:
            scene = Path(d) / "box.json"
            scene.write_text('{"integrator": {"max_bounces": 2}}\n')
            saved = runner.scene_path
            runner.scene_path = lambda name: str(Path(d) / f"{name}.json")
            try:
                def key():
                    return variant_sweep.cache_key("b", "box", ["--pg-k-max", 2], "8x8", 4, 16, 1)
                first = key()
                self.assertEqual(key(), first)
                scene.write_text('{"integrator": {"max_bounces": 8}}\n')
                self.assertNotEqual(key(), first)
            finally:
                runner.scene_path = saved


class EndToEnd(unittest.TestCase):
    def test_tiny_sweep(self):
        with tempfile.TemporaryDirectory() as out:
            cmd = [sys.executable, str(BENCH / "variant_sweep.py"), "--scenes", "cornell-box", "--seeds", "1", "2",
                   "--res", "24x16", "--frames", "4", "--window", "2", "--ref-spp", "16", "--out", out, "--variants",
                   json.dumps({"guided": [], "interval 2": ["--pg-train-interval", "2"]})]
            first = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
            runs = sorted((Path(out) / "cornell-box").glob("*.json"))
            again = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
            self.assertEqual(first, again)  # the rerun reads the cached renders
            self.assertEqual(sorted((Path(out) / "cornell-box").glob("*.json")), runs)
            # Another binary (the same one with a byte appended) renders every run again.
            other = Path(out) / "rtpg-other"
            other.write_bytes(runner.rtpg_binary().read_bytes() + b"\0")
            other.chmod(0o755)
            env = dict(os.environ, RTPG_BINARY=str(other))
            subprocess.run(cmd, check=True, capture_output=True, text=True, env=env)
            self.assertEqual(len(list((Path(out) / "cornell-box").glob("*.json"))), 2 * len(runs))
            table = json.loads((Path(out) / "sweep.json").read_text())["table"]
            for name in ("guided", "interval 2"):
                ratio, se = table[name]["cornell-box"]
                self.assertTrue(math.isfinite(ratio) and ratio > 0.0 and se >= 0.0, (name, ratio, se))
                self.assertIn(f"| {name} |", first)

    def test_tiny_sweep_along_the_camera_path(self):
        with tempfile.TemporaryDirectory() as out:
            cmd = [sys.executable, str(BENCH / "variant_sweep.py"), "--scenes", "cornell-box", "--seeds", "1", "2",
                   "--res", "24x16", "--frames", "4", "--window", "2", "--ref-spp", "16", "--out", out, "--camera-path",
                   "--checkpoints", "1", "3", "--variants", json.dumps({"guided": []})]
            first = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
            again = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
            self.assertEqual(first, again)  # the rerun reads the cached figures
            ratio, se = json.loads((Path(out) / "sweep.json").read_text())["table"]["guided"]["cornell-box"]
            self.assertTrue(math.isfinite(ratio) and ratio > 0.0 and se >= 0.0, (ratio, se))
            run = json.loads(next((Path(out) / "cornell-box").glob("path-pg-guided-1-*.relmse.json")).read_text())
            self.assertEqual(run["camera_path"], runner.first_camera_path("cornell-box"))
            self.assertEqual(run["checkpoints"], [1, 3])
            self.assertAlmostEqual(run["relmse"], sum(run["relmse_per_checkpoint"]) / 2, places=12)
            # One reference per checkpoint frame, none for the static camera.
            self.assertEqual(len(list((Path(out) / "references").glob("*.exr"))), 2)
            # Other checkpoints: the cached figure of the same runs is not reused.
            cmd[cmd.index("--checkpoints") + 1] = "2"
            subprocess.run(cmd, check=True, capture_output=True, text=True)
            run = json.loads(next((Path(out) / "cornell-box").glob("path-pg-guided-1-*.relmse.json")).read_text())
            self.assertEqual(run["checkpoints"], [2, 3])

    def test_tiny_sweep_with_a_curve(self):
        with tempfile.TemporaryDirectory() as out:
            cmd = [sys.executable, str(BENCH / "variant_sweep.py"), "--scenes", "cornell-box", "--seeds", "1",
                   "--res", "24x16", "--frames", "4", "--window", "4", "--curve", "2", "--ref-spp", "16", "--out",
                   out, "--variants", json.dumps({"guided": []})]
            text = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
            curve = next(line for line in text.splitlines() if "1-2:" in line).split()
            self.assertEqual([curve[0], curve[2]], ["1-2:", "3-4:"])
            self.assertTrue(all(math.isfinite(float(curve[i])) and float(curve[i]) > 0 for i in (1, 3)), curve)

    def test_bad_curve_is_refused(self):
        base = [sys.executable, str(BENCH / "variant_sweep.py"), "--variants", "{}", "--frames", "4", "--window", "2"]
        for extra in (["--curve", "0"], ["--curve", "5"], ["--curve", "2", "--camera-path"]):
            r = subprocess.run(base + extra, capture_output=True, text=True)
            self.assertEqual(r.returncode, 2, extra)
            self.assertIn("--curve", r.stderr)

    def test_bad_checkpoints_are_refused(self):
        base = [sys.executable, str(BENCH / "variant_sweep.py"), "--variants", "{}", "--frames", "4", "--window", "2"]
        for extra in (["--checkpoints", "1"], ["--camera-path", "--checkpoints", "4"],
                      ["--camera-path", "--checkpoints", "-1"]):
            r = subprocess.run(base + extra, capture_output=True, text=True)
            self.assertEqual(r.returncode, 2, extra)
            self.assertIn("--checkpoints", r.stderr)

    def test_bad_variants_are_refused(self):
        for bad in ["not json", '["a list"]', '{"a": "not a list"}']:
            r = subprocess.run([sys.executable, str(BENCH / "variant_sweep.py"), "--variants", bad],
                               capture_output=True, text=True)
            self.assertEqual(r.returncode, 2, bad)
            self.assertIn("--variants", r.stderr)


if __name__ == "__main__":
    unittest.main()
