#!/usr/bin/env python3
"""Checks of the reference cache's source hash (bench/suite/runner.py; run by ctest): which sources can
change what `rtpg reference` renders, and that the hash follows them and only them; and of the binary
fingerprint the variant sweep keys its renders by."""
import contextlib
import os
import shutil
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from suite import runner  # noqa: E402


def set_environment(values):
    """Sets each variable of `values`, or unsets it where its value is None."""
    for k, v in values.items():
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v


@contextlib.contextmanager
def environment(**values):
    """The environment with `values` set (None: unset) for the block, as it was after it."""
    saved = {k: os.environ.get(k) for k in values}
    try:
        set_environment(values)
        yield
    finally:
        set_environment(saved)


class BinaryFingerprintTests(unittest.TestCase):
    def test_follows_the_executable_and_an_overriding_kernel_folder(self):
        with tempfile.TemporaryDirectory() as d:
            root = Path(d)
            binary = root / "rtpg"
            binary.write_bytes(b"first build")
            kernels = root / "k" / "kernels"
            (kernels / "wide").mkdir(parents=True)
            (root / "k" / "include" / "rtpg").mkdir(parents=True)
            (kernels / "wide" / "lanes.h").write_text("// lanes\n")
            (root / "k" / "include" / "rtpg" / "guiding_layout.h").write_text("// layout\n")
            with environment(RTPG_BINARY=str(binary), RTPG_KERNEL_DIR=None):
                base = runner.binary_fingerprint()
                self.assertEqual(runner.binary_fingerprint(), base)
                binary.write_bytes(b"second build")
                rebuilt = runner.binary_fingerprint()
                self.assertNotEqual(rebuilt, base)
                os.environ["RTPG_KERNEL_DIR"] = str(kernels)
                with_dir = runner.binary_fingerprint()
                self.assertNotEqual(with_dir, rebuilt)
                (kernels / "wide" / "lanes.h").write_text("// lanes, edited\n")
                self.assertNotEqual(runner.binary_fingerprint(), with_dir)
                edited = runner.binary_fingerprint()
                (root / "k" / "include" / "rtpg" / "guiding_layout.h").write_text("// layout, edited\n")
                self.assertNotEqual(runner.binary_fingerprint(), edited)


    def test_follows_the_program_a_script_runs(self):
        """tools/rtpg_device_beside_host.sh as RTPG_BINARY: the script stays the same when the renderer it
        runs (RTPG) is rebuilt, so the fingerprint must hold that program's bytes too."""
        with tempfile.TemporaryDirectory() as d:
            script, program = Path(d) / "wrapper.sh", Path(d) / "rtpg"
            script.write_text('#!/usr/bin/env bash\nexec "$RTPG" "$@"\n')
            program.write_bytes(b"first build")
            with environment(RTPG_BINARY=str(script), RTPG=str(program), RTPG_KERNEL_DIR=None):
                self.assertEqual(runner.rtpg_executable(), program)
                base = runner.binary_fingerprint()
                program.write_bytes(b"second build")
                self.assertNotEqual(runner.binary_fingerprint(), base)
                os.environ["RTPG_BINARY"] = str(program)
                self.assertEqual(runner.rtpg_executable(), program)


class BuiltAfterSourcesTests(unittest.TestCase):
    def test_a_program_older_than_a_reference_source_is_refused(self):
        """A reference is stored under the tree's source hash: a program built before a source it depends
        on changed (the tree not rebuilt) must not render it. Sources no reference depends on do not count."""
        with tempfile.TemporaryDirectory() as d:
            root = Path(d)
            for rel in ("host/render/path_tracer.cpp", "host/guiding/guider.cpp"):
                (root / rel).parent.mkdir(parents=True, exist_ok=True)
                (root / rel).write_text("// " + rel + "\n")
            program = root / "rtpg"
            program.write_bytes(b"build")
            with environment(RTPG_BINARY=str(program)):
                os.utime(program, (2000, 2000))
                for rel in ("host/render/path_tracer.cpp", "host/guiding/guider.cpp"):
                    os.utime(root / rel, (1000, 1000))
                runner.check_built_after_sources(root)  # built after every source
                os.utime(root / "host/guiding/guider.cpp", (3000, 3000))
                runner.check_built_after_sources(root)  # the guider: no reference depends on it
                os.utime(root / "host/render/path_tracer.cpp", (3000, 3000))
                with self.assertRaises(SystemExit) as refused:
                    runner.check_built_after_sources(root)
                self.assertIn("host/render/path_tracer.cpp", str(refused.exception))


class ReferenceSourceTests(unittest.TestCase):
    def test_host_path_tracer_sources_count_and_device_only_ones_do_not(self):
        for rel in ("host/render/path_tracer.cpp", "host/scene/scene.cpp", "host/trace/embree_scene.cpp",
                    "host/app/commands.cpp", "kernels/shared/pmm.h", "kernels/shared/bsdf.h",
                    "include/rtpg/guiding_layout.h", "kernels/shared/bit_packing.h",
                    "kernels/shared/vpl_packing.h"):
            self.assertFalse(runner.reference_independent(rel), rel)
        for rel in ("kernels/train_wide.cl", "kernels/sample.cl", "kernels/wide/lanes.h", "host/guiding/guider.cpp",
                    "host/cl/device.cpp", "host/denoise/svgf_denoiser.cpp", "kernels/svgf_atrous.cl",
                    "kernels/shared/svgf.h", "host/render/guided_first_bounce.cpp",
                    "host/render/guided_first_bounce.h", "host/render/temporal_flicker.cpp", "include/rtpg/guider.h",
                    "host/render/host_transfer.cpp", "host/render/pinned_staging.h",
                    "host/render/gbuffer_packer.cpp", "kernels/shared/gbuffer_packing.h"):
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



class ReferenceSceneTests(unittest.TestCase):
    def test_an_edited_scene_file_gets_a_new_reference(self):
        """The cache key holds the scene file's bytes: a scene whose bounces or lights changed is
        rendered again, not served the old image."""
        with tempfile.TemporaryDirectory() as d:
            root = Path(d)
            scene = root / "box.json"
            scene.write_text('{"integrator": {"max_bounces": 2}}\n')
            rendered = []

            def fake_run(args, quiet=True):
                out = Path(args[args.index("-o") + 1])
                out.write_bytes(b"exr")
                rendered.append(out)
                return ""

            saved = (runner.run, runner.scene_path, runner.check_built_after_sources)
            runner.run, runner.scene_path = fake_run, lambda name: str(root / f"{name}.json")
            runner.check_built_after_sources = lambda: None  # no program is run
            try:
                cache = runner.ReferenceCache(root / "refs")
                first = cache.get("box", "8x8", 4)
                self.assertEqual(cache.get("box", "8x8", 4), first)
                self.assertEqual(len(rendered), 1)
                scene.write_text('{"integrator": {"max_bounces": 8}}\n')
                second = cache.get("box", "8x8", 4)
                self.assertNotEqual(second, first)
                self.assertEqual(len(rendered), 2)
            finally:
                runner.run, runner.scene_path, runner.check_built_after_sources = saved


if __name__ == "__main__":
    unittest.main()
