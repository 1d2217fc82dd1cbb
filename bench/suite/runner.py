"""Drives the rtpg binary: renders with statistics, cached references."""
import hashlib
import json
import os
import statistics
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
# The scene suite (scenes/README.md): the variant sweep's and the variance split's default scenes,
# in their tables' order, and experiments.py's `--scenes all`. The paper's two Sponza scenes (its Glossy Sponza and the sky-lit stand-in for its San
# Miguel) joined on 2026-11-27; docs/guiding.md's tables before that date are over the first
# eight (docs/guiding.md, "The paper's scenes in the sweep").
SUITE_SCENES = ["cornell-box", "cornell-indirect", "cornell-glossy", "veach-ajar", "sponza", "slit-room",
                "corridor", "sunlit-room", "sponza-glossy", "sponza-sky"]
SOURCE_DIRS = ("host", "kernels", "include")
# Sources that only the denoiser builds from: `rtpg reference` never runs SVGF (host/app/commands.cpp,
# run_reference), so a change to them leaves every reference valid (docs/denoising.md).
DENOISER_ONLY = ("host/denoise/", "kernels/svgf_", "kernels/wide/svgf_wide.h", "kernels/shared/svgf.h",
                 "kernels/shared/planar.h")
# Sources that only run on an OpenCL device or drive one: `rtpg reference` is plain path tracing on the
# host (BsdfFirstBounce, no ClRuntime), so the guider (host/guiding/), the OpenCL layer (host/cl/), the
# kernels' own files (kernels/*.cl) and their vector-lane code (kernels/wide/) cannot change a reference.
# kernels/shared/ stays in the hash: the host path tracer compiles those headers.
DEVICE_ONLY = ("host/cl/", "host/guiding/", "kernels/wide/")
# Host sources of the guided render alone: `rtpg reference` samples the first bounce with BsdfFirstBounce,
# never the guided one and its device buffers (host/render/guided_first_bounce.*, include/rtpg/guider.h,
# the host-device copies of host/render/host_transfer.* and host/render/pinned_staging.*, and the G-buffer
# packed for them by host/render/gbuffer_packer.* with kernels/shared/gbuffer_packing.h, which nothing else
# includes), and reports no flicker (host/render/temporal_flicker.*). On 2026-11-26 two changes to these
# re-rendered every reference of the suite, and on 2026-11-27 the packed G-buffer (docs/guiding.md).
METHODS = ("off", "pmm")  # path tracing and PMM path guiding: the values of rtpg render --guiding
GUIDED_RENDER_ONLY = ("host/render/guided_first_bounce.", "host/render/temporal_flicker.", "include/rtpg/guider.h",
                      "host/render/host_transfer.", "host/render/pinned_staging.", "host/render/gbuffer_packer.",
                      "kernels/shared/gbuffer_packing.h")


def reference_independent(rel):
    """Whether a source file (path relative to the repository) cannot change what `rtpg reference` renders."""
    top_level_kernel = rel.startswith("kernels/") and rel.count("/") == 1 and rel.endswith(".cl")
    return rel.startswith(DENOISER_ONLY + DEVICE_ONLY + GUIDED_RENDER_ONLY) or top_level_kernel


def rtpg_binary():
    return Path(os.environ.get("RTPG_BINARY", ROOT / "build" / "rtpg"))


def rtpg_executable():
    """The rtpg program that RTPG_BINARY runs: the binary itself, or, where RTPG_BINARY is a script (such as
    tools/rtpg_device_beside_host.sh), the program the script executes: RTPG, else build/rtpg, as that script
    chooses it. A script's own bytes do not change when the renderer is rebuilt."""
    binary = rtpg_binary()
    with open(binary, "rb") as f:
        if f.read(2) != b"#!":
            return binary
    return Path(os.environ.get("RTPG", ROOT / "build" / "rtpg"))


def scene_file_hash(scene):
    """The scene file's bytes: a scene edited (its bounces, lights, camera) renders another image. Its assets
    are the shared ones (../shared/scenes), which do not change. 16 hex digits."""
    return hashlib.sha256(Path(scene_path(scene)).read_bytes()).hexdigest()[:16]


def renderer_source_hash(root=ROOT):
    """Hash of every source file a reference may depend on (all of host/, kernels/ and include/ but the
    reference_independent ones): a reference made by other code is stale."""
    h = hashlib.sha256()
    for d in SOURCE_DIRS:
        for p in sorted((Path(root) / d).rglob("*")):
            rel = p.relative_to(root).as_posix()
            if p.is_file() and p.suffix in (".h", ".hpp", ".cpp", ".cl") and not reference_independent(rel):
                h.update(rel.encode())
                h.update(p.read_bytes())
    return h.hexdigest()[:16]


def binary_fingerprint():
    """What decides a render besides its arguments: the rtpg executable's bytes (its kernels are embedded;
    a script's and the program it runs, rtpg_executable) and, where RTPG_KERNEL_DIR overrides those, the kernel files read from there and the public headers
    beside them (<dir>/../include/rtpg, as host/cl/kernel_source.cpp reads them). 16 hex digits."""
    h = hashlib.sha256()
    for program in dict.fromkeys([rtpg_binary(), rtpg_executable()]):
        with open(program, "rb") as f:
            for chunk in iter(lambda: f.read(1 << 20), b""):
                h.update(chunk)
    kernel_dir = os.environ.get("RTPG_KERNEL_DIR")
    if kernel_dir:
        for d in (Path(kernel_dir), Path(kernel_dir).parent / "include" / "rtpg"):
            for p in sorted(d.rglob("*")):
                if p.is_file():
                    h.update(p.relative_to(d).as_posix().encode())
                    h.update(p.read_bytes())
    return h.hexdigest()[:16]


def run(args, quiet=True):
    cmd = [str(rtpg_binary())] + [str(a) for a in args]
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({result.returncode}): {result.stderr.strip()}")
    return result.stdout


def scene_path(name):
    p = ROOT / "scenes" / f"{name}.json"
    return str(p)


def render(scene, res, frames, guiding, out_dir, tag, reference=None, extra=(), output_ext=".exr"):
    """Renders; returns (stats dict, path of the last frame's image)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    stats = out_dir / f"{tag}.json"
    image = out_dir / f"{tag}{output_ext}"
    args = ["render", scene_path(scene), "--res", res, "--frames", frames, "--guiding", guiding,
            "--stats-json", stats, "-o", image, "-q", *extra]
    if reference:
        args += ["--reference", reference]
    run(args)
    return json.loads(stats.read_text()), image


def saved_frame(image_path, frame):
    """Where `rtpg render --save-frames` put `frame` (host/app frame_output_path: NAME-fNNNN.EXT)."""
    return Path(image_path).with_name(f"{Path(image_path).stem}-f{frame:04d}{Path(image_path).suffix}")


def first_camera_path(name):
    """The scene's first camera path by name (scenes/README.md, "camera_paths"), or "" if it has none."""
    paths = json.loads(Path(scene_path(name)).read_text()).get("camera_paths", {})
    return sorted(paths)[0] if paths else ""


def scene_exposure(name):
    """The scene file's "exposure" (scenes/README.md; default 1): PNG output and LDR-FLIP multiply
    radiance by it before the display transform."""
    return float(json.loads(Path(scene_path(name)).read_text()).get("exposure", 1.0))


def mean_sem(values):
    """Mean and its standard error, for independent values (frames of one run, seeds); the error
    of a single value is unknown (NaN)."""
    values = list(values)
    sem = statistics.stdev(values) / len(values) ** 0.5 if len(values) > 1 else float("nan")
    return statistics.mean(values), sem


def median_frame_ms(stats, key="total"):
    """Median over frames; frame 0 is left out (it builds programs and warms caches)."""
    frames = stats["frames"][1:] or stats["frames"]
    return statistics.median(f["time_ms"].get(key, 0.0) for f in frames)


def check_built_after_sources(root=ROOT):
    """A reference is stored under the hash of the sources in the tree, so the program that renders it must
    have been built from them: one older than a source it depends on (the tree edited, not yet rebuilt; or an
    older build's copy) would store its image under the new sources' key. Not proof (a copy made later of an
    old build passes), but it catches the usual slip."""
    program = rtpg_executable()
    built = program.stat().st_mtime
    for d in SOURCE_DIRS:
        for p in (Path(root) / d).rglob("*"):
            rel = p.relative_to(root).as_posix()
            if p.is_file() and p.suffix in (".h", ".hpp", ".cpp", ".cl") and not reference_independent(rel) \
                    and p.stat().st_mtime > built:
                raise SystemExit(f"{program} is older than {rel}, which a reference depends on: rebuild it (or "
                                 "copy the build made from these sources) before rendering references")


class ReferenceCache:
    """References cached on disk by scene, resolution, samples, seed, camera and a hash of the
    renderer's sources (so a reference is never reused after the renderer changed)."""

    def __init__(self, folder):
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.source_hash = renderer_source_hash()
        self.timings = {}  # what each reference used in this run cost (_note)

    def get(self, scene, res, spp, seed=1000, camera_path="", frame=0, max_bounces=0):
        key = json.dumps([scene, res, spp, seed, camera_path, frame, max_bounces, self.source_hash,
                          scene_file_hash(scene)])
        digest = hashlib.sha256(key.encode()).hexdigest()[:20]
        path = self.folder / f"{scene}-{res}-{spp}spp-{digest}.exr"
        timing = self.folder / f"{path.stem}.stats.json"
        if path.exists():
            self._note(scene, res, spp, camera_path, frame, timing)
            return path
        args = ["reference", scene_path(scene), "--res", res, "--spp", spp, "--seed", seed, "-o", path, "-q",
                "--stats-json", timing]
        check_built_after_sources()
        if camera_path:
            args += ["--camera-path", camera_path, "--frame", frame]
        if max_bounces:
            args += ["--max-bounces", max_bounces]
        run(args)
        (self.folder / f"{path.stem}.key.json").write_text(key + "\n")
        self._note(scene, res, spp, camera_path, frame, timing)
        return path

    def _note(self, scene, res, spp, camera_path, frame, timing):
        """Remembers what a reference cost (rtpg reference --stats-json); a reference cached by an
        older rtpg has no such file and is listed without figures."""
        entry = {"scene": scene, "res": res, "spp": spp, "camera": f"{camera_path} frame {frame}" if camera_path else ""}
        if timing.exists():
            stats = json.loads(timing.read_text())
            entry.update(seconds=stats["seconds"], samples_per_second=stats["samples_per_second"])
        self.timings[str(timing)] = entry


def machine_info():
    info = {"cpu": "", "cores": os.cpu_count()}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                info["cpu"] = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        info["devices"] = run(["devices"]).strip().splitlines()
    except RuntimeError as e:
        info["devices"] = [str(e)]
    try:
        info["git_commit"] = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True,
                                            text=True).stdout.strip()
        info["git_dirty"] = bool(subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--", *SOURCE_DIRS],
                                                capture_output=True, text=True).stdout.strip())
    except OSError:
        info["git_commit"] = "unknown"
    return info


def parse_variants(parser, text, example):
    """--variants as JSON: an object of variant name -> list of extra rtpg arguments, or a usage
    error naming the flag."""
    try:
        variants = json.loads(text)
    except json.JSONDecodeError as e:
        parser.error(f"--variants is not JSON: {e}")
    if not isinstance(variants, dict) or not all(isinstance(v, list) for v in variants.values()):
        parser.error(f"--variants must be a JSON object of argument lists, e.g. {example}")
    return variants
