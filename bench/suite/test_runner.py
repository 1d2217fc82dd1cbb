#!/usr/bin/env python3
"""Checks of the reference cache's source hash (bench/suite/runner.py; run by ctest): which sources can
change what `rtpg reference` renders, and that the hash follows them and only them."""
import shutil
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from suite import runner  # noqa: E402


class ReferenceSourceTests(unittest.TestCase):
    def test_host_path_tracer_sources_count_and_device_only_ones_do_not(self):
        for rel in ("host/render/path_tracer.cpp", "host/scene/scene.cpp", "host/trace/embree_scene.cpp",
                    "host/app/commands.cpp", "kernels/shared/pmm.h", "kernels/shared/bsdf.h",
                    "include/rtpg/guiding_layout.h"):
            self.assertFalse(runner.reference_independent(rel), rel)
        for rel in ("kernels/train_wide.cl", "kernels/sample.cl", "kernels/wide/lanes.h", "host/guiding/guider.cpp",
                    "host/cl/device.cpp", "host/denoise/svgf_denoiser.cpp", "kernels/svgf_atrous.cl",
                    "kernels/shared/svgf.h", "host/render/guided_first_bounce.cpp",
                    "host/render/guided_first_bounce.h", "host/render/temporal_flicker.cpp", "include/rtpg/guider.h",
                    "host/render/host_transfer.cpp", "host/render/pinned_staging.h"):
            self.assertTrue(runner.reference_independent(rel), rel)

    def test_hash_moves_with_a_path_tracer_source_only(self):
        with tempfile.TemporaryDirectory() as d:
            root = Path(d)
            for rel in ("host/render/path_tracer.cpp", "kernels/train.cl", "kernels/shared/bsdf.h",
                        "host/guiding/guider.cpp"):
                (root / rel).parent.mkdir(parents=True, exist_ok=True)
                (root / rel).write_text("// " + rel + "\n")
            base = runner.renderer_source_hash(root)
            for rel in ("kernels/train.cl", "host/guiding/guider.cpp"):
                (root / rel).write_text("// changed\n")
                self.assertEqual(runner.renderer_source_hash(root), base, rel)
            for rel in ("kernels/shared/bsdf.h", "host/render/path_tracer.cpp"):
                (root / rel).write_text("// changed " + rel + "\n")
                changed = runner.renderer_source_hash(root)
                self.assertNotEqual(changed, base, rel)
                base = changed


if __name__ == "__main__":
    unittest.main()
