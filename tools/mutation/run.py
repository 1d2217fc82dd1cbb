#!/usr/bin/env python3
"""Mutation testing of rtpg's test suite (issue 15: "Tests that can fail: prove it").

Each mutant of tools/mutation/mutants.json is one small, realistic defect: an exact `find`
string (it must occur exactly once in its file) and its `replace`. This script copies the
working tree (uncommitted changes included) to WORK/src, configures and builds it once in
WORK/build with the options of the project's normal build (tools/build.sh, benchmarks off),
runs every mutant's test selection on the unmutated build (a selection that fails there is a
harness error), then for each mutant: applies it, rebuilds incrementally, runs its ctest
selection, records the outcome (killed, survived, killed by the compiler, timed out), restores
the file byte for byte and goes on. The report (docs/mutation-testing.md by default) is a
Markdown table with totals, the command line and the source commit.

Kernels are embedded at build time (cmake/EmbedKernels.cmake: the generated source depends on
every kernels/*.cl and kernels/shared/*.h), so a kernel mutant is rebuilt like a host one. The
program cache (host/cl/cl_runtime.cpp) is keyed by a hash of the resolved kernel source, and
PoCL's by the source too, so a mutated kernel is never served from a stale binary
(--clear-caches empties both anyway).

Run by hand, not in CI:
    python3 tools/mutation/run.py --list          # the mutants
    python3 tools/mutation/run.py --check         # every find string occurs exactly once
    python3 tools/mutation/run.py                 # everything (about half an hour on 2 cores)
    python3 tools/mutation/run.py --only ID,ID    # some (WORK/report.md, WORK/results-only.json)
"""

import argparse
import datetime
import json
import os
import platform
import re
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

SCRIPT_DIR = Path(__file__).resolve().parent
DEFAULT_SOURCE = SCRIPT_DIR.parents[1]
MUTANTS_FILE = SCRIPT_DIR / "mutants.json"
# tools/build.sh: Release, warnings as errors; tests on, benchmarks off (not needed here), and no
# link-time optimisation, which would re-optimise every test program a mutant relinks (the code's
# meaning is the same either way).
CMAKE_OPTIONS = [
    "-DCMAKE_BUILD_TYPE=Release",
    "-DRTPG_WERROR=ON",
    "-DRTPG_BUILD_TESTS=ON",
    "-DRTPG_BUILD_BENCH=OFF",
    "-DRTPG_LTO=OFF",
]
ID_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")

OUTCOME_KILLED = "killed"
OUTCOME_COMPILER = "killed by compiler"
OUTCOME_TIMEOUT = "timed out"
OUTCOME_SURVIVED = "survived"
OUTCOME_HARNESS = "harness error"


class HarnessError(Exception):
    pass


# ---- mutants -----------------------------------------------------------------------------


def load_mutants(path):
    data = json.loads(Path(path).read_text(encoding="utf-8"))
    mutants = data["mutants"] if isinstance(data, dict) else data
    seen = set()
    for m in mutants:
        for key in ("id", "file", "description", "find", "replace"):
            if key not in m or not isinstance(m[key], str):
                raise HarnessError(f"mutant {m.get('id', '?')}: '{key}' missing or not a string")
        if not ID_RE.match(m["id"]):
            raise HarnessError(f"mutant id '{m['id']}': use letters, digits, '.', '_', '-'")
        if m["id"] in seen:
            raise HarnessError(f"mutant id '{m['id']}' appears twice")
        seen.add(m["id"])
        if not m["find"] or m["find"] == m["replace"]:
            raise HarnessError(f"mutant {m['id']}: empty find, or replace equals find")
        if not (m.get("regex") or m.get("labels")):
            raise HarnessError(f"mutant {m['id']}: needs a ctest selection (regex and/or labels)")
    return mutants


def selection_args(m):
    args = []
    if m.get("regex"):
        args += ["-R", m["regex"]]
    if m.get("labels"):
        args += ["-L", m["labels"]]
    if m.get("exclude"):
        args += ["-E", m["exclude"]]
    return args


def selection_text(m):
    return " ".join(shlex.quote(a) for a in selection_args(m))


def occurrences(root, m):
    path = Path(root) / m["file"]
    if not path.is_file():
        return None
    return path.read_bytes().count(m["find"].encode("utf-8"))


# ---- processes ---------------------------------------------------------------------------


def run(cmd, cwd=None, log=None, timeout=None, env=None):
    """Runs cmd in its own process group (ended with it on timeout or interruption), its
    output (stdout and stderr) appended to log. Returns (returncode, output text, seconds);
    returncode None on timeout."""
    start = time.monotonic()
    out = open(log, "a", encoding="utf-8", errors="replace") if log else None
    if out:
        out.write(f"$ {shlex.join(str(c) for c in cmd)}\n")
        out.flush()
    proc = subprocess.Popen(
        [str(c) for c in cmd],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        errors="replace",
        start_new_session=True,
    )
    chunks = []

    def pump():
        for line in proc.stdout:
            chunks.append(line)
            if out:
                out.write(line)
                out.flush()

    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
    try:
        proc.wait(timeout=timeout)
        rc = proc.returncode
    except subprocess.TimeoutExpired:
        end_group(proc)
        rc = None
    except BaseException:
        end_group(proc)
        raise
    finally:
        reader.join(timeout=30)
        if out:
            out.close()
    return rc, "".join(chunks), time.monotonic() - start


def end_group(proc):
    try:
        os.killpg(proc.pid, signal.SIGTERM)
        proc.wait(timeout=10)
    except (ProcessLookupError, subprocess.TimeoutExpired):
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()


def git(source, *args):
    try:
        return subprocess.run(
            ["git", "-C", str(source), *args], capture_output=True, text=True, check=True
        ).stdout
    except (subprocess.CalledProcessError, FileNotFoundError):
        return None


def source_state(source):
    commit = (git(source, "rev-parse", "HEAD") or "").strip() or "unknown"
    subject = (git(source, "log", "-1", "--format=%s") or "").strip()
    status = git(source, "status", "--porcelain")
    changed = [line[3:] for line in (status or "").splitlines() if line.strip()]
    return {"commit": commit, "subject": subject, "dirty": bool(changed), "changed": changed}


# ---- the copy ----------------------------------------------------------------------------


def tree_files(source):
    """The working tree: tracked files that exist plus untracked ones git does not ignore."""
    listed = git(source, "ls-files", "-z", "--cached", "--others", "--exclude-standard")
    if listed is not None:
        files = {f for f in listed.split("\0") if f}
    else:  # not a git checkout: everything but build folders and caches
        files = set()
        for dirpath, dirnames, filenames in os.walk(source):
            rel = Path(dirpath).relative_to(source)
            dirnames[:] = [
                d
                for d in dirnames
                if not (str(rel) == "." and (d.startswith("build") or d in (".git", ".cache")))
                and d != "__pycache__"
            ]
            files.update(str(rel / f) if str(rel) != "." else f for f in filenames)
    return sorted(f for f in files if (source / f).is_file() or (source / f).is_symlink())


def sync_tree(source, dest):
    """Makes dest hold exactly the working tree of source. Files whose content differs are
    rewritten with the current time as mtime (so make rebuilds what depends on them, also a
    file left mutated by an interrupted run); identical files are left alone."""
    files = tree_files(source)
    keep = set(files)
    written = 0
    for rel in files:
        src, dst = source / rel, dest / rel
        if src.is_symlink():
            target = os.readlink(src)
            if dst.is_symlink() and os.readlink(dst) == target:
                continue
            if dst.exists() or dst.is_symlink():
                dst.unlink()
            dst.parent.mkdir(parents=True, exist_ok=True)
            os.symlink(target, dst)
            written += 1
            continue
        data = src.read_bytes()
        if dst.is_file() and not dst.is_symlink() and dst.read_bytes() == data:
            continue
        if dst.is_symlink() or dst.is_dir():
            shutil.rmtree(dst) if dst.is_dir() and not dst.is_symlink() else dst.unlink()
        dst.parent.mkdir(parents=True, exist_ok=True)
        dst.write_bytes(data)
        shutil.copymode(src, dst)
        written += 1
    removed = 0
    for dirpath, dirnames, filenames in os.walk(dest, topdown=False):
        for f in filenames:
            rel = str((Path(dirpath) / f).relative_to(dest))
            if rel not in keep:
                (Path(dirpath) / f).unlink()
                removed += 1
        if Path(dirpath) != dest and not any(Path(dirpath).iterdir()):
            Path(dirpath).rmdir()
    return len(files), written, removed


# ---- ctest -------------------------------------------------------------------------------

# "12/73 Test  #94: NAME ......   Passed    1.49 sec" (or ***Failed, ***Timeout, ...). Names of
# parameterised GoogleTest cases carry "  # GetParam() = ..." and so contain spaces.
RESULT_RE = re.compile(
    r"^\s*(?:\d+/\d+\s+)?Test\s+#(?P<number>\d+):\s(?P<name>.*?)\s\.*\s*"
    r"(?P<status>\*\*\*.+?|Passed|Not Run.*?)\s+(?P<secs>[\d.]+)\s+sec\s*$"
)


def classify(status):
    s = status.lstrip("*").strip().lower()
    if s.startswith("passed"):
        return "passed"
    if s.startswith("skipped") or s.startswith("not run (disabled)"):
        return "skipped"
    if s.startswith("timeout"):
        return "timeout"
    return "failed"


def parse_ctest(output, names=None):
    """[(name, kind, raw status, seconds, evidence, output)] in the order ctest reported them
    (output: what a failed test printed); names maps test numbers to names (ctest's listing)
    where the printed name is ambiguous."""
    lines = output.splitlines()
    results = []
    for i, line in enumerate(lines):
        m = RESULT_RE.match(line)
        if not m:
            continue
        kind = classify(m.group("status"))
        evidence, block = "", ""
        if kind in ("failed", "timeout"):
            block = "\n".join(test_output(lines[i + 1 :]))
            evidence = failure_evidence(block.splitlines()) or m.group("status").lstrip("*").strip()
        name = (names or {}).get(int(m.group("number")), m.group("name").strip())
        results.append((name, kind, m.group("status").lstrip("*").strip(),
                        float(m.group("secs")), evidence, block))
    return results


def test_output(lines):
    """The lines a failed test printed (--output-on-failure): up to the next test's."""
    block = []
    for line in lines:
        if RESULT_RE.match(line) or re.match(r"^\s*Start\s+\d+:", line):
            break
        block.append(line.rstrip())
    return block


# ClBuildError (host/cl/cl_error.cpp): "building <kernel>.cl for <device>: <build log>".
OPENCL_BUILD_RE = re.compile(r"building \S+\.cl for .*")


def failure_evidence(block):
    """The first failure message of a test's output, in one line."""
    for i, line in enumerate(block):
        if re.search(r"(:\d+|^unknown file): Failure$", line) or "Oclgrind reported" in line \
                or "error:" in line:
            parts = [line.strip()] + [b.strip() for b in block[i + 1 : i + 4] if b.strip()][:2]
            return shorten(" | ".join(parts), 220)
    for line in block:
        if re.search(r"(?i)\b(error|exception|abort|segmentation)\b", line):
            return shorten(line.strip(), 220)
    return ""


def shorten(text, n):
    text = re.sub(r"/\S*/(tests|host|kernels)/", r"\1/", text)  # paths relative to the tree
    return text if len(text) <= n else text[: n - 3] + "..."


def ctest_tests(build, args, env):
    rc, out, _ = run(["ctest", "--show-only=json-v1", *args], cwd=build, env=env)
    if rc != 0:
        raise HarnessError(f"ctest --show-only {' '.join(args)} failed:\n{out}")
    return json.loads(out[out.index("{"):])["tests"]


def build_targets(build, env):
    rc, out, _ = run(["cmake", "--build", build, "--target", "help"], env=env)
    return {line[4:].split()[0] for line in out.splitlines() if line.startswith("... ")}


def targets_of(tests, build, known):
    """The build targets the tests run (their binaries), or None when one of them needs the
    whole build (an install test, a script): then everything is built."""
    build = Path(build).resolve()
    targets = set()
    for t in tests:
        found = None
        for token in t.get("command") or []:
            for cand in (token, token.split("=", 1)[1] if token.startswith("-D") and "=" in token else ""):
                p = Path(cand) if cand else None
                if p and p.is_absolute() and build in p.parents and p.name in known:
                    found = p.name
        if found is None:
            return None
        targets.add(found)
    return sorted(targets)


# ---- the run -----------------------------------------------------------------------------


class Runner:
    def __init__(self, args, mutants):
        self.args = args
        self.mutants = mutants
        self.source = Path(args.source).resolve()
        self.work = Path(args.work).resolve()
        self.src = self.work / "src"
        self.build = self.work / "build"
        self.logs = self.work / "logs"
        self.env = dict(os.environ)
        self.env.pop("RTPG_KERNEL_DIR", None)  # kernels must come from the (mutated) build
        self.env["POCL_CACHE_DIR"] = str(self.build / "cache" / "pocl")
        self.env["RTPG_CACHE_DIR"] = str(self.build / "cache" / "rtpg")
        self.info = {}

    def say(self, text):
        stamp = datetime.datetime.now().strftime("%H:%M:%S")
        print(f"[{stamp}] {text}", flush=True)

    def prepare(self):
        if self.src == self.source or self.source in self.src.parents or self.src in self.source.parents:
            raise HarnessError(f"--work {self.work} must not overlap the source tree {self.source}")
        self.work.mkdir(parents=True, exist_ok=True)
        self.logs.mkdir(exist_ok=True)
        for old in self.logs.glob("*.log"):
            old.unlink()
        self.info["source"] = source_state(self.source)
        total, written, removed = sync_tree(self.source, self.src)
        self.say(f"copied {self.source} -> {self.src}: {total} files, {written} written, "
                 f"{removed} removed")
        # Scene assets sit beside the project (../shared/scenes): mirror that layout.
        shared = self.source.parent / "shared"
        link = self.work / "shared"
        if shared.is_dir() and not (link.exists() or link.is_symlink()):
            link.symlink_to(shared)
        config = {"options": CMAKE_OPTIONS, "source": str(self.src)}
        stamp = self.work / "configure.json"
        self.info["fresh_build"] = not (self.build / "CMakeCache.txt").exists()
        if not (self.build / "CMakeCache.txt").exists() or not stamp.exists() or \
                json.loads(stamp.read_text()) != config:
            self.say("configuring: cmake " + " ".join(CMAKE_OPTIONS))
            rc, out, _ = run(["cmake", "-S", self.src, "-B", self.build, *CMAKE_OPTIONS],
                             log=self.logs / "configure.log", env=self.env)
            if rc != 0:
                raise HarnessError(f"configure failed (see {self.logs / 'configure.log'}):\n{out[-3000:]}")
            stamp.write_text(json.dumps(config))
        self.say(f"building the unmutated tree (-j{self.args.build_jobs}) ...")
        ok, secs, err = self.build_step(None, self.logs / "baseline.build.log")
        if not ok:
            raise HarnessError(f"the unmutated tree does not build: {err} "
                               f"(see {self.logs / 'baseline.build.log'})")
        self.info["baseline_build_s"] = secs
        self.say(f"built in {secs:.0f} s")
        self.known_targets = build_targets(self.build, self.env)
        all_tests = ctest_tests(self.build, [], self.env)
        self.test_number = {t["name"]: i + 1 for i, t in enumerate(all_tests)}
        self.test_name = {i: n for n, i in self.test_number.items()}

    def build_step(self, targets, log):
        cmd = ["cmake", "--build", self.build, "-j", str(self.args.build_jobs)]
        if targets:
            cmd += ["--target", *targets]
        rc, out, secs = run(cmd, log=log, timeout=self.args.build_timeout, env=self.env)
        if rc == 0:
            return True, secs, ""
        if rc is None:
            return False, secs, f"build timed out after {self.args.build_timeout} s"
        lines = out.splitlines()
        first = next((l for l in lines if ": error:" in l or ": fatal error:" in l), None) or \
            next((l for l in lines if re.search(r"(?i)error", l)), None) or f"exit {rc}"
        return False, secs, shorten(first.strip(), 220)

    def ctest(self, args, log, stop_on_failure):
        cmd = ["ctest", "--output-on-failure", "--timeout", str(self.args.timeout),
               "-j", str(self.args.jobs), *args]
        if stop_on_failure:
            cmd.append("--stop-on-failure")
        rc, out, secs = run(cmd, cwd=self.build, log=log, env=self.env)
        if "No tests were found" in out:
            raise HarnessError("the selection matches no test")
        results = parse_ctest(out, self.test_name)
        if rc != 0 and not any(x[1] in ("failed", "timeout") for x in results):
            raise HarnessError(f"ctest exited {rc} without a failed test (see {log})")
        return results, secs

    def resolve(self, todo):
        for r in todo:
            m = r["mutant"]
            tests = ctest_tests(self.build, selection_args(m), self.env)
            r["tests"] = [t["name"] for t in tests]
            if not tests:
                r["outcome"], r["detail"] = OUTCOME_HARNESS, "the selection matches no test"
                continue
            r["targets"] = None if self.args.build_all else targets_of(tests, self.build,
                                                                        self.known_targets)

    def baseline(self, todo):
        names = []
        for r in todo:
            if r.get("outcome") is None:
                names += [n for n in r["tests"] if n not in names]
        if not names:
            return
        self.say(f"baseline: {len(names)} tests of the selections on the unmutated build ...")
        numbers = ",".join(str(self.test_number[n]) for n in names)
        results, secs = self.ctest(["-I", f"0,0,0,{numbers}"], self.logs / "baseline.ctest.log",
                                   stop_on_failure=False)
        self.info["baseline_tests_s"] = secs
        status = {x[0]: (x[1], x[2], x[3]) for x in results}
        bad_total = 0
        for r in todo:
            if r.get("outcome") is not None:
                continue
            bad = [n for n in r["tests"] if status.get(n, ("missing",))[0] not in ("passed", "skipped")]
            r["baseline_s"] = sum(status.get(n, (0, 0, 0.0))[2] for n in r["tests"])
            if bad:
                bad_total += 1
                r["outcome"] = OUTCOME_HARNESS
                r["detail"] = "fails unmutated: " + ", ".join(
                    f"{short_test(n)} ({status.get(n, ('not reported',))[0]})" for n in bad[:3])
            elif all(status[n][0] == "skipped" for n in r["tests"]):
                r["outcome"] = OUTCOME_HARNESS
                r["detail"] = "every test of the selection skips unmutated"
        self.say(f"baseline done in {secs:.0f} s; {bad_total} selection(s) fail unmutated")

    def mutate(self, r):
        m = r["mutant"]
        path = self.src / m["file"]
        find, replace = m["find"].encode("utf-8"), m["replace"].encode("utf-8")
        if not path.is_file():
            r["outcome"], r["detail"] = OUTCOME_HARNESS, f"{m['file']} does not exist"
            return
        original = path.read_bytes()
        count = original.count(find)
        if count != 1:
            r["outcome"], r["detail"] = OUTCOME_HARNESS, f"find occurs {count} times in {m['file']}"
            return
        start = time.monotonic()
        build_log = self.logs / f"{m['id']}.build.log"
        test_log = self.logs / f"{m['id']}.ctest.log"
        try:
            path.write_bytes(original.replace(find, replace, 1))
            if self.args.clear_caches:
                shutil.rmtree(self.build / "cache", ignore_errors=True)
            ok, r["build_s"], err = self.build_step(r.get("targets"), build_log)
            if not ok:
                r["outcome"], r["detail"] = OUTCOME_COMPILER, err
                return
            try:
                results, r["test_s"] = self.ctest(selection_args(m), test_log,
                                                  stop_on_failure=not self.args.all_tests)
            except HarnessError as e:
                r["outcome"], r["detail"] = OUTCOME_HARNESS, str(e)
                return
            r["ran"] = len(results)
            failed = [x for x in results if x[1] in ("failed", "timeout")]
            if not failed:
                r["outcome"] = OUTCOME_SURVIVED
                skipped = sum(1 for x in results if x[1] == "skipped")
                r["detail"] = f"{len(results)} passed" + (f" ({skipped} skipped)" if skipped else "")
            else:
                first = failed[0]
                r["outcome"] = OUTCOME_KILLED if any(x[1] == "failed" for x in failed) else OUTCOME_TIMEOUT
                r["first_failed"] = first[0]
                r["detail"] = first[4]
                r["failed"] = [x[0] for x in failed]
                # A kernel that no longer compiles fails its tests with a ClBuildError: that is
                # the OpenCL compiler's kill, not the tests'.
                cl_build = OPENCL_BUILD_RE.search(first[5])
                if cl_build:
                    r["outcome"] = OUTCOME_COMPILER
                    r["detail"] = "OpenCL: " + shorten(cl_build.group(0), 200)
        finally:
            path.write_bytes(original)  # byte for byte, with a new mtime: the next build recompiles
            r["seconds"] = time.monotonic() - start

    def go(self, todo):
        self.info["started"] = datetime.datetime.now().isoformat(timespec="seconds")
        self.info["host"] = f"{platform.node() or 'unknown host'} ({os.cpu_count()} cores)"
        self.prepare()
        self.resolve(todo)
        if not self.args.skip_baseline or self.args.baseline_only:
            self.baseline(todo)
        if self.args.baseline_only:
            for r in todo:
                state = r.get("outcome") or "passes unmutated"
                self.say(f"  {r['mutant']['id']:30} {len(r.get('tests', [])):3} tests "
                         f"{r.get('baseline_s', 0):6.1f} s  {state}"
                         + (f": {r['detail']}" if r.get("detail") else ""))
            return
        for n, r in enumerate(todo, 1):
            m = r["mutant"]
            if r.get("outcome") is not None:
                self.say(f"[{n}/{len(todo)}] {m['id']}: {r['outcome']}: {r.get('detail', '')}")
                continue
            self.say(f"[{n}/{len(todo)}] {m['id']} ({m['file']}) "
                     f"targets: {' '.join(r['targets']) if r.get('targets') else 'all'}")
            self.mutate(r)
            self.say(f"    -> {r['outcome']}"
                     + (f", first failed: {short_test(r['first_failed'])}" if r.get("first_failed") else "")
                     + f" ({r.get('seconds', 0):.0f} s: build {r.get('build_s', 0):.0f} s, "
                       f"tests {r.get('test_s', 0):.0f} s)"
                     + (f" [{r['detail']}]" if r.get("detail") else ""))
        self.info["finished"] = datetime.datetime.now().isoformat(timespec="seconds")


# ---- report ------------------------------------------------------------------------------


def short_test(name):
    return name.split("  # GetParam()")[0]


def md(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def code(text):
    return "`" + str(text).replace("|", "\\|").replace("`", "'") + "`"


def write_report(path, info, results, all_mutants):
    src = info.get("source", {})
    counts = {}
    for r in results:
        counts[r.get("outcome") or "not run"] = counts.get(r.get("outcome") or "not run", 0) + 1
    killed, timeouts = counts.get(OUTCOME_KILLED, 0), counts.get(OUTCOME_TIMEOUT, 0)
    survived, compiler = counts.get(OUTCOME_SURVIVED, 0), counts.get(OUTCOME_COMPILER, 0)
    harness = counts.get(OUTCOME_HARNESS, 0)
    judged = killed + timeouts + survived
    ran_ids = {r["mutant"]["id"] for r in results}
    partial = len(ran_ids) < len(all_mutants)
    timed = [r for r in results if r.get("outcome") in (OUTCOME_KILLED, OUTCOME_SURVIVED, OUTCOME_TIMEOUT, OUTCOME_COMPILER)]
    out = []
    w = out.append
    w("# Mutation testing")
    w("")
    w("Does the test suite notice real defects? `tools/mutation/run.py` applies each mutant of")
    w("`tools/mutation/mutants.json` (one small, realistic defect: a `find` string that occurs")
    w("exactly once and its `replace`) to a copy of the working tree, rebuilds it incrementally,")
    w("runs the ctest selection that should catch the defect, and restores the file. A mutant is")
    w("**killed** when a test of its selection fails, **killed by compiler** when it does not build")
    w("(reported apart: it says nothing about the tests), **timed out** when a test hangs past")
    w("`--timeout`, and **survived** when every test passes. Every selection is first run on the")
    w("unmutated build; one that fails there is a **harness error**, not a result. Kernel")
    w("mutants rebuild like host ones (the kernel sources are embedded at build time), and the")
    w("program caches are keyed by the kernel source's hash, so no stale binary is reused.")
    w("")
    w("It runs by hand, not in CI. The first run copies and builds the tree (3 minutes on 2")
    w("cores); then each mutant rebuilds only the targets its tests run (seconds for a host or")
    w("kernel file, longer for a shared header that many sources include) and runs its selection.")
    w("CI runs only `--check` (ctest `mutants_apply`, label `format`): a change to code that a")
    w("mutant targets must update the mutant with it (five had silently stopped applying by")
    w("2026-11-26, three days after the list was written).")
    w("")
    w("```sh")
    w("python3 tools/mutation/run.py --list       # the mutants and their selections")
    w("python3 tools/mutation/run.py --check      # every find string occurs exactly once")
    w("python3 tools/mutation/run.py              # all mutants; rewrites this file")
    w("python3 tools/mutation/run.py --only ID,ID # some; WORK/report.md, WORK/results-only.json")
    w("```")
    w("")
    w("Options: `--work DIR` (default /tmp/rtpg-mutation: `src/` copy, `build/`, `logs/` with each")
    w("mutant's build and ctest output; reused by the next run), `--jobs N` (ctest -j),")
    w("`--build-jobs N`, `--timeout S` (per test), `--all-tests` (no --stop-on-failure),")
    w("`--build-all` (build every target, not only the selection's), `--nice N`, `--clear-caches`,")
    w("`--baseline-only` (check that every selection passes unmutated, and its time).")
    w("A survivor is either equivalent (no test can tell it from the original) or a missing test:")
    w("write the verdict into the mutant's `verdict` field in `mutants.json`, then")
    w("`python3 tools/mutation/run.py --report-from /tmp/rtpg-mutation/results.json` rewrites this")
    w("file without running anything.")
    w("")
    w("## Last run" + (" (partial)" if partial else ""))
    w("")
    w(f"- Command: {code(info.get('command', '?'))}")
    subject = src.get("subject", "")
    subject = subject if len(subject) <= 72 else subject[:69] + "..."
    w(f"- Source: {src.get('commit', 'unknown')[:12]} ({md(subject)}), "
      + ("working tree **dirty**: " + ", ".join(code(c) for c in src.get("changed", [])[:12])
         + (f" and {len(src['changed']) - 12} more" if len(src.get("changed", [])) > 12 else "")
         if src.get("dirty") else "working tree clean"))
    w(f"- When: {info.get('started', '?')} to {info.get('finished', 'unfinished')}, on "
      f"{info.get('host', '?')}; build "
      f"{code('cmake ' + ' '.join(info.get('cmake_options', CMAKE_OPTIONS)))}, ctest "
      f"-j{info.get('jobs', '?')}, timeout {info.get('timeout', '?')} s per test"
      + (", stop on first failure" if not info.get("all_tests") else ""))
    if "baseline_build_s" in info:
        w(f"- Unmutated build {info['baseline_build_s']:.0f} s ("
          + ("fresh" if info.get("fresh_build") else "incremental: the work folder was reused")
          + "); baseline run of the selections "
          + (f"{info['baseline_tests_s']:.0f} s" if "baseline_tests_s" in info else "skipped"))
    if partial:
        w(f"- **Partial run**: {len(ran_ids)} of {len(all_mutants)} mutants. Run the whole list to "
          "replace this report.")
    w("")
    w(f"**Totals**: {len(results)} mutants: {killed} killed, {timeouts} timed out, {survived} "
      f"survived, {compiler} killed by the compiler, {harness} harness errors"
      + (f", {counts['not run']} not run (interrupted)" if counts.get("not run") else "") + ". "
      + (f"Mutation score (killed + timed out) / (killed + timed out + survived) = "
         f"{killed + timeouts}/{judged} = {100.0 * (killed + timeouts) / judged:.0f}%."
         if judged else ""))
    if timed:
        secs = sorted(r["seconds"] for r in timed)
        w(f"Time per mutant (build + tests): median {secs[len(secs) // 2]:.0f} s, longest "
          f"{secs[-1]:.0f} s, all {sum(secs) / 60:.1f} min.")
    w("")
    w("| id | file | defect | tests run | outcome | first failing test | s |")
    w("|---|---|---|---|---|---|---|")
    for r in results:
        m = r["mutant"]
        tests = selection_text(m) + (f" ({len(r['tests'])} tests)" if r.get("tests") else "")
        outcome = r.get("outcome") or "not run"
        if outcome == OUTCOME_SURVIVED:
            outcome = "**survived**"
        seconds = f"{r['seconds']:.0f}" if "seconds" in r else ""
        w(f"| {code(m['id'])} | {code(m['file'])} | {md(m['description'])} | {code(tests)} | "
          f"{outcome} | {md(short_test(r.get('first_failed', '')))} | {seconds} |")
    w("")
    killed_rows = [r for r in results if r.get("outcome") in (OUTCOME_KILLED, OUTCOME_TIMEOUT, OUTCOME_COMPILER)]
    if killed_rows:
        w("### How each was killed")
        w("")
        for r in killed_rows:
            extra = ""
            if r.get("failed") and len(r["failed"]) > 1:
                extra = f" (also: {', '.join(short_test(t) for t in r['failed'][1:4])})"
            w(f"- {code(r['mutant']['id'])}: {md(short_test(r.get('first_failed', r['outcome'])))}{md(extra)}: "
              f"{md(r.get('detail', ''))} (build {r.get('build_s', 0):.0f} s, tests "
              f"{r.get('test_s', 0):.0f} s)")
        w("")
    w("## Survivors")
    w("")
    survivors = [r for r in results if r.get("outcome") == OUTCOME_SURVIVED]
    if not survivors:
        w("None in this run.")
        w("")
    for r in survivors:
        m = r["mutant"]
        w(f"### {m['id']}: {m['description']}")
        w("")
        w(f"- `{m['file']}`: {code(m['find'])} -> {code(m['replace'] or '(deleted)')}")
        w(f"- Ran {code(selection_text(m))}: {md(r.get('detail', ''))}")
        if m.get("note"):
            w(f"- Analysis: {md(m['note'])}")
        w(f"- Verdict: {md(m['verdict']) if m.get('verdict') else '_to be written: equivalent, or which test is missing?_'}")
        w("")
    harness_rows = [r for r in results if r.get("outcome") == OUTCOME_HARNESS]
    if harness_rows:
        w("## Harness errors")
        w("")
        for r in harness_rows:
            w(f"- {code(r['mutant']['id'])}: {md(r.get('detail', ''))}")
        w("")
    if partial:
        w("## Not run in this report")
        w("")
        for m in all_mutants:
            if m["id"] not in ran_ids:
                w(f"- {code(m['id'])} ({code(m['file'])}): {md(m['description'])}; {code(selection_text(m))}")
        w("")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(out), encoding="utf-8")


# ---- main --------------------------------------------------------------------------------


def interrupt(signum, frame):
    raise KeyboardInterrupt(f"signal {signum}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--source", default=str(DEFAULT_SOURCE), help="the tree to copy (default: this repository)")
    p.add_argument("--work", default="/tmp/rtpg-mutation", help="copy, build and logs (reused)")
    p.add_argument("--mutants", default=str(MUTANTS_FILE), help="the mutant list (JSON)")
    p.add_argument("--only", action="append", default=[], metavar="ID[,ID...]", help="run these mutants only")
    p.add_argument("--list", action="store_true", help="list the mutants and exit")
    p.add_argument("--check", action="store_true",
                   help="check that every find string occurs exactly once in --source and exit")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="ctest -j (default: cores)")
    p.add_argument("--build-jobs", type=int, default=os.cpu_count() or 1, help="build -j (default: cores)")
    p.add_argument("--timeout", type=int, default=300, help="seconds per test (default 300)")
    p.add_argument("--build-timeout", type=int, default=3600, help="seconds per build (default 3600)")
    p.add_argument("--all-tests", action="store_true", help="run the whole selection after a failure")
    p.add_argument("--build-all", action="store_true", help="build every target for each mutant")
    p.add_argument("--skip-baseline", action="store_true", help="do not run the selections unmutated first")
    p.add_argument("--baseline-only", action="store_true",
                   help="copy, build and run the selections unmutated, then stop (no mutant)")
    p.add_argument("--clear-caches", action="store_true", help="empty the program caches before each mutant")
    p.add_argument("--nice", type=int, default=0, help="lower this run's CPU priority by N")
    p.add_argument("--report", help="Markdown report (default: SOURCE/docs/mutation-testing.md; "
                                    "with --only: WORK/report.md)")
    p.add_argument("--report-from", metavar="RESULTS_JSON",
                   help="only rewrite the report from a run's WORK/results.json (e.g. after "
                        "writing verdicts into mutants.json)")
    args = p.parse_args()

    try:
        mutants = load_mutants(args.mutants)
    except (HarnessError, json.JSONDecodeError, KeyError) as e:
        sys.exit(f"mutants: {e}")
    only = [i for chunk in args.only for i in chunk.split(",") if i]
    unknown = [i for i in only if i not in {m["id"] for m in mutants}]
    if unknown:
        sys.exit(f"unknown mutant id(s): {', '.join(unknown)} (see --list)")
    chosen = [m for m in mutants if not only or m["id"] in only]

    if args.list:
        for m in chosen:
            print(f"{m['id']:28} {m['file']:34} {selection_text(m)}\n{'':28} {m['description']}")
        print(f"{len(chosen)} mutants")
        return 0
    if args.check:
        bad = 0
        for m in chosen:
            n = occurrences(args.source, m)
            ok = n == 1
            bad += not ok
            print(f"{'ok  ' if ok else 'FAIL'} {m['id']:28} {m['file']:34} "
                  + ("" if ok else ("file missing" if n is None else f"find occurs {n} times")))
        print(f"{len(chosen) - bad} of {len(chosen)} mutants apply exactly once"
              + ("" if not bad else f"; {bad} do not"))
        return 1 if bad else 0

    if args.report_from:
        saved = json.loads(Path(args.report_from).read_text(encoding="utf-8"))
        by_id = {m["id"]: m for m in mutants}
        results = []
        for r in saved["results"]:
            if r["mutant"] not in by_id:
                sys.exit(f"{args.report_from}: mutant {r['mutant']} is no longer in {args.mutants}")
            results.append({**r, "mutant": by_id[r["mutant"]]})
        report = args.report or str(Path(args.source) / "docs" / "mutation-testing.md")
        write_report(report, saved["info"], results, mutants)
        print(f"report: {report}")
        return 0
    if args.nice:
        os.nice(args.nice)
    signal.signal(signal.SIGTERM, interrupt)
    report = args.report or (str(Path(args.work) / "report.md") if only
                             else str(Path(args.source) / "docs" / "mutation-testing.md"))
    command = "python3 " + shlex.join(sys.argv)
    runner = Runner(args, chosen)
    runner.info.update({"command": command, "jobs": args.jobs, "timeout": args.timeout,
                        "all_tests": args.all_tests, "cmake_options": CMAKE_OPTIONS})
    results = [{"mutant": m, "outcome": None} for m in chosen]
    interrupted = False
    try:
        runner.go(results)
    except HarnessError as e:
        print(f"harness error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        interrupted = True
        print("interrupted: the mutated file was restored; writing the report so far", file=sys.stderr)
    # A run of some mutants keeps its results apart, so that it does not replace the results of
    # the last full run that --report-from rewrites docs/mutation-testing.md from.
    name = ("results-baseline.json" if args.baseline_only else
            "results-only.json" if only else "results.json")
    (Path(args.work) / name).write_text(json.dumps(
        {"info": runner.info, "results": [{**r, "mutant": r["mutant"]["id"]} for r in results]},
        indent=1))
    if args.baseline_only:
        return 1 if any(r.get("outcome") for r in results) else 0
    write_report(report, runner.info, results, mutants)
    print(f"report: {report}")
    return 130 if interrupted else 0


if __name__ == "__main__":
    sys.exit(main())
