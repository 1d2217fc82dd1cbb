#!/usr/bin/env python3
"""rtpg's path-traced frame against Embree's own tutorial path tracer on the same frame (issue 14's
yardstick; docs/host-path-tracer.md, "Against Embree's tutorial path tracer").

    python3 bench/embree_tutorial.py                       # Sponza, 960x540, 4 frames, 2 rounds
    python3 bench/embree_tutorial.py --res 1920x1080 --rounds 3 --json out.json

The tutorial is /usr/bin/pathtracer from Debian's embree-tools (the single-ray C++ version of
Embree's tutorials/pathtracer). Both programs run on all cores, one after the other, in --rounds
interleaved rounds, each taking the first place every other round; the figures are medians over
rounds.

What is matched: the OBJ (the scene file's one mesh), the camera (position, look-at, up, vertical
fov), the resolution, 1 sample per pixel, the path length (the tutorial's --max-path-length counts
the camera ray, so it is the scene's max_bounces + 1), and the lights' directions: the sun as a
distant light of the same direction and angular radius, the constant sky as an ambient light.

What is not, and why the per-path and per-ray figures differ: the tutorial shades one ray at a
time (megakernel), ends a path only when its throughput falls below 0.01 (no Russian roulette) and
traces one shadow ray per light at every vertex (two here), so it traces several times more rays
per path than rtpg (one shadow ray per vertex, roulette from bounce 3). This Debian build also reads
no PNG or TGA textures (those materials take their MTL colour) and does not alpha-test; light
intensities and the scene file's material overrides do not reach the tutorial (it takes the MTL's
colours). Its rays per second come from its own counters (BENCHMARK_RENDER_MRAYPS: every
rtcIntersect1 and rtcOccluded1 call); rtpg's from its statistics (camera, bounce and shadow rays of
the frame over the frame's total time).
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from suite import runner  # noqa: E402

TUTORIAL = "/usr/bin/pathtracer"


class SetupError(Exception):
    pass


def asset_root(scene_file):
    """Where the scene's assets are, in the order rtpg looks (host/scene/asset_paths.cpp)."""
    env = os.environ.get("RTPG_ASSET_ROOT")
    if env:
        return Path(env)
    scene_dir = Path(scene_file).resolve().parent
    for c in (Path.cwd() / ".." / "shared" / "scenes", scene_dir / ".." / ".." / "shared" / "scenes",
              scene_dir / ".." / "shared" / "scenes"):
        if c.is_dir():
            return c
    raise SetupError("no asset root: set RTPG_ASSET_ROOT to the folder that holds the scene's assets")


def tutorial_arguments(scene_file, width, height):
    """The tutorial's command-line for the scene file's static camera and lights."""
    scene = json.loads(Path(scene_file).read_text())
    meshes = scene.get("meshes", [])
    if len(meshes) != 1 or "file" not in meshes[0] or not meshes[0]["file"].lower().endswith(".obj"):
        raise SetupError(f"{scene_file}: the tutorial reads one OBJ; this scene has {len(meshes)} meshes")
    if scene.get("shapes"):
        raise SetupError(f"{scene_file}: the tutorial cannot draw rtpg's procedural shapes")
    obj = asset_root(scene_file) / meshes[0]["file"]
    if not obj.is_file():
        raise SetupError(f"{scene_file}: {obj} does not exist")
    cam = scene["camera"]
    args = ["-i", str(obj), "--vp", *cam["position"], "--vi", *cam["look_at"], "--vu", *cam.get("up", [0, 1, 0]),
            "--fov", cam["fov"], "--size", width, height, "--spp", 1,
            "--max-path-length", int(scene.get("max_bounces", 8)) + 1]
    env = scene.get("environment", {})
    if "file" in env:
        raise SetupError(f"{scene_file}: the tutorial has no environment map light")
    if "color" in env:
        args += ["--ambientlight", *env["color"]]
    sun = scene.get("sun")
    if sun:
        d = sun["direction"]  # towards the sun; the tutorial's direction is the light's travel
        args += ["--distantlight", *(-float(x) for x in d), *sun["irradiance"],
                 sun.get("angular_radius_deg", 0.0)]
    return [str(a) for a in args]


def parse_benchmark(text):
    """The tutorial's --benchmark summary: frames per second and million rays per second (averages)."""
    values = dict(re.findall(r"^(BENCHMARK_RENDER_\w+) ([-+0-9.eE]+)$", text, re.MULTILINE))
    if "BENCHMARK_RENDER_AVG" not in values or "BENCHMARK_RENDER_MRAYPS_AVG" not in values:
        raise SetupError("the tutorial printed no benchmark summary (BENCHMARK_RENDER_AVG, _MRAYPS_AVG)")
    return float(values["BENCHMARK_RENDER_AVG"]), float(values["BENCHMARK_RENDER_MRAYPS_AVG"])


def run_tutorial(args, frames):
    r = subprocess.run([TUTORIAL, *args, "--benchmark", "1", str(frames)], capture_output=True, text=True)
    if r.returncode != 0:
        raise SetupError(f"{TUTORIAL} failed ({r.returncode}): {r.stderr.strip()[-400:]}")
    fps, mrays = parse_benchmark(r.stdout)
    if not (fps > 0.0 and mrays > 0.0):
        raise SetupError(f"the tutorial reported {fps} frames/s and {mrays} M rays/s")
    frame_ms = 1e3 / fps
    rays = mrays * 1e6 / fps
    return {"frame_ms": frame_ms, "rays_per_frame": rays, "mrays_per_s": mrays}


def rtpg_frame_figures(stats):
    """Median over frames (frame 0 left out) of frame time and rays of a `rtpg render` run."""
    frames = stats["frames"][1:] or stats["frames"]
    frame_ms = runner.median_frame_ms(stats)
    rays = statistics.median(sum(f["rays"][k] for k in ("primary", "secondary", "shadow")) for f in frames)
    return {"frame_ms": frame_ms, "rays_per_frame": rays, "mrays_per_s": rays / frame_ms * 1e-3}


def run_rtpg(scene_file, res, frames, out_dir):
    stats = Path(out_dir) / "rtpg.json"
    runner.run(["render", scene_file, "--res", res, "--frames", frames + 1, "--guiding", "off",
                "--stats-json", stats, "-o", Path(out_dir) / "rtpg.exr", "-q"])
    return rtpg_frame_figures(json.loads(stats.read_text()))


def summarise(rounds, pixels):
    """Medians over rounds, and the ratios rtpg / tutorial (above 1: rtpg is faster)."""
    out = {}
    for who in ("tutorial", "rtpg"):
        med = {k: statistics.median(r[who][k] for r in rounds) for k in rounds[0][who]}
        med["mpaths_per_s"] = pixels / med["frame_ms"] * 1e-3
        med["rays_per_path"] = med["rays_per_frame"] / pixels
        out[who] = med
    out["rays_per_s_ratio"] = out["rtpg"]["mrays_per_s"] / out["tutorial"]["mrays_per_s"]
    out["paths_per_s_ratio"] = out["rtpg"]["mpaths_per_s"] / out["tutorial"]["mpaths_per_s"]
    return out


def table(summary):
    lines = ["| program | frame ms | rays / path | M rays/s | M paths/s |", "|---|---|---|---|---|"]
    for who in ("tutorial", "rtpg"):
        s = summary[who]
        lines.append(f"| {who} | {s['frame_ms']:.1f} | {s['rays_per_path']:.2f} | {s['mrays_per_s']:.2f} | "
                     f"{s['mpaths_per_s']:.3f} |")
    lines.append(f"\nrtpg / tutorial: rays per second {summary['rays_per_s_ratio']:.2f}, paths per second "
                 f"{summary['paths_per_s_ratio']:.2f}")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default=str(runner.ROOT / "scenes" / "sponza.json"))
    ap.add_argument("--res", default="960x540")
    ap.add_argument("--frames", type=int, default=4, help="measured frames per program and round")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--json", help="also write the figures here")
    a = ap.parse_args()
    m = re.fullmatch(r"(\d+)x(\d+)", a.res)
    if not m or a.frames < 1 or a.rounds < 1:
        ap.error("--res must be WxH, --frames and --rounds at least 1")
    width, height = int(m.group(1)), int(m.group(2))
    try:
        if not shutil.which(TUTORIAL):
            raise SetupError(f"{TUTORIAL} is missing: apt-get install embree-tools")
        args = tutorial_arguments(a.scene, width, height)
        rounds = []
        with tempfile.TemporaryDirectory() as tmp:
            for i in range(a.rounds):
                # Each program takes the first place every other round: the second of two runs
                # in a row moved Sponza's frames by 1-4% (docs/host-path-tracer.md, "The order
                # within a round").
                if i % 2 == 0:
                    tutorial = run_tutorial(args, a.frames)
                    ours = run_rtpg(a.scene, a.res, a.frames, tmp)
                else:
                    ours = run_rtpg(a.scene, a.res, a.frames, tmp)
                    tutorial = run_tutorial(args, a.frames)
                rounds.append({"tutorial": tutorial, "rtpg": ours})
                print(f"round {i + 1}: tutorial {rounds[-1]['tutorial']['frame_ms']:.1f} ms, "
                      f"rtpg {rounds[-1]['rtpg']['frame_ms']:.1f} ms", flush=True)
    except (SetupError, RuntimeError) as e:
        print(f"embree_tutorial.py: {e}", file=sys.stderr)
        return 1
    summary = summarise(rounds, width * height)
    print(f"{Path(a.scene).name} at {a.res}, 1 spp, medians of {a.rounds} rounds of {a.frames} frames\n")
    print(table(summary))
    print("\ntutorial:", TUTORIAL, " ".join(args))
    if a.json:
        Path(a.json).write_text(json.dumps({"settings": vars(a), "tutorial_args": args, "rounds": rounds,
                                            "summary": summary, "machine": runner.machine_info()}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
