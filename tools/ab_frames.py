#!/usr/bin/env python3
"""Builds or settings compared on the same frames, in turns: each round runs `rtpg render` once per
--run and reads its stage times (`--stats-json`); printed are, per stage, each round's median over
the frames after the first --skip, then the median over the rounds; `wall` is the frame's wall
time (the stats' `wall_ms`: what the run does per frame beyond the timed stages too, such as the
statistics that --stats-json itself computes). A second table gives each later run's time over
the first run's, round by round (the two made minutes apart at most), and their median. On a
shared machine only runs made in turns compare (docs/host-path-tracer.md's before / after tables
are made so), and the order within a round matters too: the same binary run twice in a row on
Sponza took 1-4% less the second time in three rounds of four, and 1% more on the Cornell box
(docs/host-path-tracer.md, "The order within a round"). So the rounds alternate the order
(`--order alternate`, the default: the runs as given, then reversed, and so on), which cancels a
drift within a round over every two rounds; `--order fixed` keeps the order given. With alternate
orders the rounds must be even, and each summary is the median over pairs of rounds of the pair's
mean: a median over an odd number of rounds, or over single rounds, takes its value from one order
(with three rounds, the order two of them share).

A --run is "NAME: [VAR=VALUE ...] BINARY [ARGUMENT ...]": environment assignments, the rtpg binary,
and arguments added to `render SCENE --res RES --frames FRAMES`.

Usage:
  ab_frames.py --scene scenes/sponza.json [--res 960x540] [--frames 8] [--skip 2] [--rounds 4]
               [--order alternate|fixed] --run "before: /tmp/rtpg-old --guiding off" --run "after: build/rtpg --guiding off"
"""
import argparse
import json
import os
import shlex
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

# The frame's stages in the order of a frame (FrameStats "time_ms"); those a run has.
STAGES = ["wall", "total", "primary", "gbuffer", "guiding_begin", "first_bounce", "shade", "group_rays", "trace",
          "compact", "guiding_end", "reproject", "sample", "train", "svgf_total"]


def parse_run(text):
    name, sep, rest = text.partition(":")
    words = shlex.split(rest)
    env = {}
    while words and "=" in words[0] and not words[0].startswith("-"):
        var, _, value = words.pop(0).partition("=")
        env[var] = value
    if not sep or not name.strip() or not words:
        sys.exit(f"ab_frames: --run {text!r}: expected 'NAME: [VAR=VALUE ...] BINARY [ARGUMENT ...]'")
    return name.strip(), env, words[0], words[1:]


def stage_medians(stats_path, skip):
    frames = json.loads(Path(stats_path).read_text())["frames"]
    kept = frames[skip:]
    names = [s for s in STAGES if any(s in f["time_ms"] for f in kept)]
    medians = {s: statistics.median(f["time_ms"].get(s, 0.0) for f in kept) for s in names}
    if all("wall_ms" in f for f in kept):
        medians["wall"] = statistics.median(f["wall_ms"] for f in kept)
    return medians


def summary(values, alternate):
    """The median over pairs of rounds of each pair's mean (alternate orders: each pair holds both
    orders once), else the median over the rounds."""
    if alternate and len(values) >= 2:
        values = [0.5 * (values[k] + values[k + 1]) for k in range(0, len(values) - 1, 2)]
    return statistics.median(values)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", required=True)
    parser.add_argument("--res", default="960x540")
    parser.add_argument("--frames", type=int, default=8)
    parser.add_argument("--skip", type=int, default=2, help="frames left out at the start")
    parser.add_argument("--rounds", type=int, default=4, help="even with --order alternate")
    parser.add_argument("--order", choices=["alternate", "fixed"], default="alternate",
                        help="the runs' order within a round: as given, then reversed, and so on "
                             "(alternate), or always as given (fixed)")
    parser.add_argument("--run", action="append", required=True, help="see the usage above")
    args = parser.parse_args()
    if args.frames < 1 or args.rounds < 1 or not 0 <= args.skip < args.frames:
        sys.exit("ab_frames: --frames and --rounds must be at least 1, --skip at least 0 and below --frames")
    if args.order == "alternate" and args.rounds % 2 != 0:
        sys.exit("ab_frames: --rounds must be even with --order alternate (each order as often)")
    runs = [parse_run(r) for r in args.run]
    if len({name for name, _, _, _ in runs}) != len(runs):
        sys.exit("ab_frames: two runs share a name")

    results = {name: [] for name, _, _, _ in runs}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            order = runs if args.order == "fixed" or r % 2 == 0 else runs[::-1]
            for position, (name, env, binary, extra) in enumerate(order):
                stats = Path(tmp) / "stats.json"
                command = [binary, "render", args.scene, "--res", args.res, "--frames",
                           str(args.frames), "-q", "-o", str(Path(tmp) / "image.exr"),
                           "--stats-json", str(stats)] + extra
                done = subprocess.run(command, env={**os.environ, **env},
                                      stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                if done.returncode != 0:
                    sys.exit(f"ab_frames: run {name!r} failed ({done.returncode}): "
                             f"{shlex.join(command)}\n{done.stderr}")
                medians = stage_medians(stats, args.skip)
                results[name].append(medians)
                print(f"round {r + 1} ({position + 1}. in turn) {name}: " +
                      ", ".join(f"{s} {v:.2f}" for s, v in medians.items()), flush=True)

    stages = [s for s in STAGES if any(s in m for ms in results.values() for m in ms)]
    alternate = args.order == "alternate"
    label = "median of pair means" if alternate else "median"
    order = "each round's order the reverse of the one before" if args.order == "alternate" \
        else "the same order every round"
    print(f"\n{args.scene} at {args.res}, {args.frames} frames, medians of frames "
          f"{args.skip}-{args.frames - 1}, ms, rounds in turns ({order}):\n")
    print("| stage | " + " | ".join(results) + " |")
    print("|---" * (len(results) + 1) + "|")
    for s in stages:
        cells = []
        for ms in results.values():
            values = [m.get(s, 0.0) for m in ms]
            cells.append(", ".join(f"{v:.2f}" for v in values) +
                         (f" ({label} {summary(values, alternate):.2f})" if len(values) > 1 else ""))
        print(f"| {s} | " + " | ".join(cells) + " |")

    names = list(results)
    if len(names) < 2:
        return
    first = names[0]
    print(f"\nEach run's time over {first}'s in the same round, and their {label}:\n")
    print("| stage | " + " | ".join(f"{n} / {first}" for n in names[1:]) + " |")
    print("|---" * len(names) + "|")
    for s in stages:
        cells = []
        for n in names[1:]:
            ratios = [m.get(s, 0.0) / f[s] for m, f in zip(results[n], results[first])
                      if f.get(s, 0.0) > 0.0]
            # The pair means need every round (each pair holds both orders); a stage that some of
            # the first run's rounds lack (a grouping chosen away) gets its ratios alone.
            whole = len(ratios) == len(results[first])
            cells.append(", ".join(f"{v:.3f}" for v in ratios) +
                         ((f" ({label} {summary(ratios, alternate):.3f})" if whole
                           else f" (in {len(ratios)} of {len(results[first])} rounds)")
                          if len(ratios) > 1 else "")
                         if ratios else "-")
        print(f"| {s} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
