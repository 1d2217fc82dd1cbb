#!/usr/bin/env python3
"""The table of a GPU bundle's frame runs (tools/gpu_bundle_run.sh with RENDER=1 writes
OUT/frames/SCENE-WxH-RUN.json, `rtpg render --stats-json`): per scene and size, each run's median
frame and its ratio to the path-traced one ("off"), the guiding stages (upload, read-back, the
kernels: reproject, sample, train and the packed G-buffer's unpack) and SVGF's upload and total,
medians over the frames after the first SKIP (a run's rounds, files ...-RUN-rN.json, pooled),
and the median of the frames' wall_ms (each frame's start to the next's: what the frame's total
leaves out, and where work the device does beside the host would hide) with its ratio to PT's.

Usage: gpu_frames_summary.py OUT/frames [--skip N]   (prints a Markdown table)
"""
import argparse
import json
import re
import statistics
import sys
from pathlib import Path

NAME = re.compile(r"^(?P<scene>.+)-(?P<size>\d+x\d+)-(?P<run>[a-z-]+?)(?:-r\d+)?\.json$")
ORDER = ["off", "pinned", "packed", "pageable", "in-place", "auto", "overlap-off", "overlap-on"]


def median_stage(frames, stage):
    return statistics.median(f["time_ms"].get(stage, 0.0) for f in frames)


def summarise(folder, skip):
    runs = {}
    for path in sorted(Path(folder).glob("*.json")):
        m = NAME.match(path.name)
        if not m:
            continue
        frames = json.loads(path.read_text())["frames"]
        frames = frames[skip:] or frames
        # The rounds of one run (ROUNDS in gpu_bundle_run.sh, files ...-RUN-rN.json) pool.
        runs.setdefault((m["scene"], m["size"], m["run"]), []).extend(frames)
    if not runs:
        sys.exit(f"gpu_frames_summary: no SCENE-WxH-RUN.json files in {folder}")

    def order(key):
        scene, size, run = key
        base = run[:-5] if run.endswith("-svgf") else run
        rank = ORDER.index(base) if base in ORDER else len(ORDER)
        return scene, int(size.split("x")[0]), run.endswith("-svgf"), rank, run

    lines = ["| scene | size | run | frame ms | / PT | wall ms | / PT | upload | read-back | kernels"
             " | train wait | SVGF upload | SVGF |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for key in sorted(runs, key=order):
        scene, size, run = key
        frames = runs[key]
        total = median_stage(frames, "total")
        base = runs.get((scene, size, "off"))
        ratio = f"{total / median_stage(base, 'total'):.3f}" if base else "-"
        has_wall = all("wall_ms" in f for f in frames)
        wall = statistics.median(f["wall_ms"] for f in frames) if has_wall else None
        wall_ratio = (f"{wall / statistics.median(f['wall_ms'] for f in base):.3f}"
                      if has_wall and base and all("wall_ms" in f for f in base) else "-")
        kernels = sum(median_stage(frames, s) for s in ("reproject", "sample", "train", "unpack"))
        guided = any("train" in f["time_ms"] for f in frames)
        svgf = any("svgf_total" in f["time_ms"] for f in frames)
        cells = [scene, size, run, f"{total:.1f}", ratio,
                 f"{wall:.1f}" if has_wall else "-", wall_ratio,
                 f"{median_stage(frames, 'upload'):.2f}" if guided else "-",
                 f"{median_stage(frames, 'readback'):.2f}" if guided else "-",
                 f"{kernels:.2f}" if guided else "-",
                 f"{median_stage(frames, 'train_wait'):.2f}"
                 if any("train_wait" in f["time_ms"] for f in frames) else "-",
                 f"{median_stage(frames, 'svgf_upload'):.2f}" if svgf else "-",
                 f"{median_stage(frames, 'svgf_total'):.2f}" if svgf else "-"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder")
    parser.add_argument("--skip", type=int, default=4, help="frames left out at the start (default 4)")
    args = parser.parse_args()
    print(summarise(args.folder, args.skip))


if __name__ == "__main__":
    main()
