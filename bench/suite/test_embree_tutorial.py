#!/usr/bin/env python3
"""bench/embree_tutorial.py (run by ctest as bench_embree_tutorial): the tutorial's command-line for
Sponza, the parsing of its benchmark summary, the refusal of scenes it cannot draw, and a tiny
side-by-side run end to end (skipped without /usr/bin/pathtracer or the Sponza assets)."""
import json
import math
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))
import embree_tutorial  # noqa: E402

SCENES = BENCH.parent / "scenes"


def sponza_assets():
    try:
        return (embree_tutorial.asset_root(SCENES / "sponza.json") / "crytek-sponza" / "sponza.obj").is_file()
    except embree_tutorial.SetupError:
        return False


class Arguments(unittest.TestCase):
    @unittest.skipUnless(sponza_assets(), "no Sponza assets (scenes/README.md, 'Without ../shared/scenes')")
    def test_sponza_camera_lights_and_path_length(self):
        args = embree_tutorial.tutorial_arguments(SCENES / "sponza.json", 320, 180)
        scene = json.loads((SCENES / "sponza.json").read_text())

        def after(flag, n):
            i = args.index(flag)
            return [float(x) for x in args[i + 1:i + 1 + n]]

        self.assertEqual(after("--vp", 3), scene["camera"]["position"])
        self.assertEqual(after("--vi", 3), scene["camera"]["look_at"])
        self.assertEqual(after("--fov", 1), [scene["camera"]["fov"]])
        self.assertEqual(after("--size", 2), [320, 180])
        self.assertEqual(after("--spp", 1), [1])
        self.assertEqual(after("--max-path-length", 1), [9])  # camera ray + rtpg's 8 bounces
        self.assertEqual(after("--ambientlight", 3), scene["environment"]["color"])
        light = after("--distantlight", 7)
        self.assertEqual(light[:3], [-x for x in scene["sun"]["direction"]])  # travel, not towards
        self.assertEqual(light[6], scene["sun"]["angular_radius_deg"])

    def test_procedural_scenes_are_refused(self):
        with self.assertRaises(embree_tutorial.SetupError) as e:
            embree_tutorial.tutorial_arguments(SCENES / "cornell-box.json", 64, 64)
        self.assertIn("cornell-box.json", str(e.exception))

    @unittest.skipUnless(sponza_assets(), "no Sponza assets (scenes/README.md, 'Without ../shared/scenes')")
    def test_environment_maps_are_refused(self):  # the tutorial could not match that light
        with self.assertRaises(embree_tutorial.SetupError) as e:
            embree_tutorial.tutorial_arguments(SCENES / "sponza-sky.json", 64, 64)
        self.assertIn("environment map", str(e.exception))


class Parsing(unittest.TestCase):
    def test_benchmark_summary(self):
        text = ("frame [  1 -   5]: min = 0.37 fps\nBENCHMARK_RENDER_MIN 0.3787\nBENCHMARK_RENDER_AVG 0.5\n"
                "BENCHMARK_RENDER_MRAYPS_AVG 4.25\n")
        self.assertEqual(embree_tutorial.parse_benchmark(text), (0.5, 4.25))
        with self.assertRaises(embree_tutorial.SetupError):
            embree_tutorial.parse_benchmark("BENCHMARK_RENDER_AVG 0.5\n")  # a build without RAY_STATS

    def test_rtpg_figures_leave_out_frame_zero(self):
        frames = [{"time_ms": {"total": 900.0}, "rays": {"primary": 1, "secondary": 1, "shadow": 1}}]
        frames += [{"time_ms": {"total": t}, "rays": {"primary": 100, "secondary": 200, "shadow": 100}}
                   for t in (10.0, 20.0, 30.0)]
        f = embree_tutorial.rtpg_frame_figures({"frames": frames})
        self.assertEqual(f["frame_ms"], 20.0)
        self.assertEqual(f["rays_per_frame"], 400)
        self.assertAlmostEqual(f["mrays_per_s"], 400 / 20e-3 * 1e-6)


class EndToEnd(unittest.TestCase):
    @unittest.skipUnless(shutil.which(embree_tutorial.TUTORIAL) and sponza_assets(),
                         "needs /usr/bin/pathtracer (embree-tools) and the Sponza assets")
    def test_tiny_side_by_side(self):
        with tempfile.TemporaryDirectory() as out:
            js = Path(out) / "et.json"
            subprocess.run([sys.executable, str(BENCH / "embree_tutorial.py"), "--res", "64x36", "--frames", "1",
                            "--rounds", "1", "--json", str(js)], check=True, capture_output=True, text=True)
            s = json.loads(js.read_text())["summary"]
            for who in ("tutorial", "rtpg"):
                self.assertTrue(s[who]["frame_ms"] > 0 and s[who]["rays_per_path"] >= 1.0, (who, s[who]))
            self.assertTrue(math.isfinite(s["rays_per_s_ratio"]) and s["rays_per_s_ratio"] > 0)


if __name__ == "__main__":
    unittest.main()
