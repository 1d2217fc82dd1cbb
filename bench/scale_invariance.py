#!/usr/bin/env python3
"""Scale invariance of references (docs/robustness.md, "Scale invariance").

Writes each scene scaled by s (every position, the camera and its paths; directions, colours
and the sun unchanged) into a temporary folder, renders a reference of each with `rtpg
reference` (same seed), and compares it with the reference at scale 1: the image mean and the
per-pixel relMSE, next to the relMSE of two scale-1 references with different seeds (what
noise alone gives).

    python3 bench/scale_invariance.py [--spp 2048] [--res 128x128] [--scenes cornell-box,sponza]
"""
import argparse
import copy
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
from suite.metrics import load_exr  # noqa: E402

SCALES = [1e-4, 1e-3, 1e3, 1e5]
POINT_KEYS = {"position", "look_at", "corner", "edge1", "edge2", "min", "max", "center",
              "translate"}


def scaled_scene(scene, s, source_dir):
    """A copy of the scene JSON with every length times s; mesh files get a leading scale."""
    out = copy.deepcopy(scene)

    def walk(node, key=None):
        if isinstance(node, dict):
            for k, v in node.items():
                if k in POINT_KEYS and isinstance(v, list):
                    node[k] = [x * s for x in v]
                elif k == "radius" and isinstance(v, (int, float)):
                    node[k] = v * s
                else:
                    walk(v, k)
        elif isinstance(node, list):
            for v in node:
                walk(v, key)

    for shape in out.get("shapes", []):
        walk(shape)
    for key in ("camera", "camera_paths"):
        if key in out:
            walk(out[key])
    for mesh in out.get("meshes", []):
        if "transform" in mesh:
            # T' = S(s) T: scale after the mesh's own transform is a scale of its translation
            # and of its own scale.
            t = mesh["transform"]
            if "translate" in t:
                t["translate"] = [x * s for x in t["translate"]]
            sc = t.get("scale", 1.0)
            t["scale"] = [x * s for x in sc] if isinstance(sc, list) else sc * s
            if "matrix" in t:
                raise SystemExit("matrix transforms are not handled")
        else:
            mesh["transform"] = {"scale": s}
        f = mesh["file"]
        if not os.path.isabs(f) and (source_dir / f).exists():
            mesh["file"] = str((source_dir / f).resolve())
    return out


def render(binary, scene_path, out, spp, res, seed):
    subprocess.run([binary, "reference", str(scene_path), "-o", str(out), "--spp", str(spp),
                    "--res", res, "--seed", str(seed), "-q"], check=True)
    return load_exr(out).astype(np.float64)


def relmse(a, b):
    return float(np.mean((a - b) ** 2 / (b ** 2 + 1e-2)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", default=os.environ.get("RTPG_BINARY", str(ROOT / "build/rtpg")))
    ap.add_argument("--spp", type=int, default=2048)
    ap.add_argument("--res", default="128x128")
    ap.add_argument("--scenes", default="cornell-box,sponza")
    args = ap.parse_args()
    print("| scene | scale | mean / mean at 1 | relMSE vs scale 1 | relMSE of two seeds at 1 |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name in args.scenes.split(","):
            src = ROOT / "scenes" / f"{name}.json"
            scene = json.loads(src.read_text())
            base = render(args.binary, src, tmp / "base.exr", args.spp, args.res, 1)
            other_seed = render(args.binary, src, tmp / "seed2.exr", args.spp, args.res, 2)
            noise = relmse(other_seed, base)
            for s in SCALES:
                path = tmp / f"{name}-{s:g}.json"
                path.write_text(json.dumps(scaled_scene(scene, s, src.parent)))
                img = render(args.binary, path, tmp / "scaled.exr", args.spp, args.res, 1)
                print(f"| {name} | {s:g} | {img.mean() / base.mean():.5f} | "
                      f"{relmse(img, base):.2e} | {noise:.2e} |", flush=True)


if __name__ == "__main__":
    main()
