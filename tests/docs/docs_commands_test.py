#!/usr/bin/python3
"""Runs every command line documented in README.md and docs/*.md (ctest: docs.commands).

The convention (docs/cli.md, "Documented commands are tested"):
  - A documented command is a line in a code block (``` fenced, or indented by 4 spaces) whose
    first word is `lacuna`, `build/lacuna` or `./build/lacuna`, with its `\\` continuation lines.
  - The commands of one block run in order in one bash, after the block's variable assignments
    (lines `NAME=value`, e.g. `T=/usr/share/mricron/templates`), from the repository root: a
    scratch copy of it (README.md, docs/, presets/, tests/data/, scripts/; build/lacuna is the
    binary under test and `lacuna` is on PATH), so outputs such as head.png or docs/images/*.png
    never touch the checkout. Each must exit 0.
  - `lacuna bench ...` lines are listed but not run: benchmarks run for minutes, and the doc's
    tables are their measured output.
  - `lacuna serve` runs forever: it is started with `--port 0` added (the test must not need port
    8080), must print its URL, and must exit 0 on SIGINT.
  - A block that must not run says so on the line before it:
        <!-- docs-commands: skip: REASON -->
    (benchmarks that run for minutes, a synopsis with placeholders). The test lists the skipped
    blocks with their reasons; a marker not followed by a block with commands is an error.
The data are Debian's mricron templates (/usr/share/mricron/templates); without them the test is
skipped (exit 77).

Usage: tests/docs/docs_commands_test.py --lacuna build/lacuna [--root .] [--list] [--only FILE]
"""
import argparse
import glob
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

MRICRON = "/usr/share/mricron/templates"
COMMAND = re.compile(r"^(\./)?(build/)?lacuna\s")
ASSIGNMENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*=\S*$")
SKIP = re.compile(r"^<!--\s*docs-commands:\s*skip:\s*(.+?)\s*-->\s*$")


class Block:
    def __init__(self, path, line):
        self.path, self.line = path, line  # the block's first line (1-based)
        self.commands = []  # (line, text)
        self.assignments = []
        self.skip = None  # the reason, when marked

    def where(self):
        return f"{self.path}:{self.line}"


def blocks_of(path, text):
    """The code blocks of a Markdown file that hold documented commands."""
    lines = text.split("\n")
    out, block, fenced, pending_skip = [], None, False, None
    i = 0
    while i < len(lines):
        raw = lines[i]
        stripped = raw.strip()
        m = SKIP.match(stripped)
        if m and not fenced:
            if block is not None:
                out.append(block)
                block = None
            pending_skip = (m.group(1), i + 1)
            i += 1
            continue
        if stripped.startswith("```"):
            if fenced:
                fenced = False
                out.append(block)
                block = None
            else:
                fenced = True
                block = Block(path, i + 1)
                block.skip, pending_skip = (pending_skip[0] if pending_skip else None), None
            i += 1
            continue
        indented = not fenced and raw.startswith("    ") and stripped != ""
        if not fenced and not indented:
            if stripped != "":
                if block is not None:
                    out.append(block)
                    block = None
                if pending_skip:  # the marker must come right before its block
                    raise SystemExit(f"{path}:{pending_skip[1]}: a docs-commands skip marker not followed by a code block")
            i += 1
            continue
        if indented and block is None:
            block = Block(path, i + 1)
            block.skip, pending_skip = (pending_skip[0] if pending_skip else None), None
        start = i
        if COMMAND.match(stripped):
            cmd = stripped
            while cmd.endswith("\\") and i + 1 < len(lines):
                i += 1
                cmd = cmd[:-1].rstrip() + " " + lines[i].strip()
            block.commands.append((start + 1, cmd))
        elif ASSIGNMENT.match(stripped):
            block.assignments.append(stripped)
        i += 1
    if block is not None:
        out.append(block)
    if pending_skip:
        raise SystemExit(f"{path}:{pending_skip[1]}: a docs-commands skip marker with no block after it")
    result = [b for b in out if b.commands]
    for b in out:
        if b.skip and not b.commands:
            raise SystemExit(f"{b.where()}: a docs-commands skip marker on a block without commands")
    return result


def documented_blocks(root):
    files = [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md")))
    blocks = []
    for f in files:
        with open(f, encoding="utf-8") as fh:
            blocks += blocks_of(os.path.relpath(f, root), fh.read())
    return blocks


def scratch_root(root, lacuna):
    """A copy of what documented commands read, with build/lacuna the binary under test."""
    tmp = tempfile.mkdtemp(prefix="lacuna-docs-")
    for name in ["README.md"]:
        shutil.copy(os.path.join(root, name), tmp)
    for d in ["docs", "presets", os.path.join("tests", "data"), "scripts"]:
        if os.path.isdir(os.path.join(root, d)):
            shutil.copytree(os.path.join(root, d), os.path.join(tmp, d), symlinks=True)
    os.makedirs(os.path.join(tmp, "build"))
    os.symlink(os.path.abspath(lacuna), os.path.join(tmp, "build", "lacuna"))
    return tmp


def run_serve(assignments, cmd, cwd, env):
    """Starts a documented `lacuna serve`, waits for its URL, stops it with SIGINT."""
    command = "".join(a + "; " for a in assignments) + "exec " + cmd.split(" #")[0].strip() + " --port 0"
    p = subprocess.Popen(["bash", "-c", command], cwd=cwd, env=env, text=True,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out = ""
    deadline = time.time() + 120
    while time.time() < deadline:
        line = p.stdout.readline()
        if not line:
            break
        out += line
        if "lacuna viewer: http://" in line:
            p.send_signal(signal.SIGINT)
            try:
                rest, err = p.communicate(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                return 1, "did not stop within 30 s of SIGINT"
            return p.returncode, err
    p.kill()
    _, err = p.communicate()
    return p.returncode or 1, err or "no URL printed: " + out


def is_bench(cmd):
    words = cmd.split()
    return len(words) > 1 and words[1] == "bench"


def run_block(block, cwd, env, timeout):
    """Runs a block's commands in order; returns [(line, command, status, message)] of failures."""
    failures = []
    prefix = "set -o pipefail\n" + "".join(a + "\n" for a in block.assignments)
    for line, cmd in block.commands:
        if is_bench(cmd):
            print(f"skip {block.path}:{line} (a benchmark): {cmd}", flush=True)
            continue
        t0 = time.time()
        words = cmd.split()
        if len(words) > 1 and words[1] == "serve":
            status, err = run_serve(block.assignments, cmd, cwd, env)
        else:
            try:
                r = subprocess.run(["bash", "-c", prefix + cmd], cwd=cwd, env=env, text=True,
                                   capture_output=True, timeout=timeout)
                status, err = r.returncode, r.stderr
            except subprocess.TimeoutExpired:
                status, err = 124, f"timed out after {timeout} s"
        took = time.time() - t0
        tag = "ok" if status == 0 else "FAIL"
        print(f"{tag} {block.path}:{line} ({took:.1f} s): {cmd}", flush=True)
        if status != 0:
            last = [l for l in (err or "").strip().split("\n") if l.strip()]
            failures.append((f"{block.path}:{line}", cmd, status, last[-1] if last else ""))
    return failures


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lacuna", default="build/lacuna")
    ap.add_argument("--root", default=".")
    ap.add_argument("--list", action="store_true", help="print the commands and skips, run nothing")
    ap.add_argument("--only", help="run the blocks of this file only (e.g. README.md)")
    ap.add_argument("--timeout", type=int, default=300, help="seconds per command")
    a = ap.parse_args()
    blocks = documented_blocks(a.root)
    if a.only:
        blocks = [b for b in blocks if b.path == a.only]
    if a.list:
        for b in blocks:
            for line, cmd in b.commands:
                print(f"{'skip' if b.skip or is_bench(cmd) else 'run '} {b.path}:{line}: {cmd}")
            if b.skip:
                print(f"     ({b.where()} skipped: {b.skip})")
        return 0
    if not os.path.isfile(os.path.join(MRICRON, "ch2.nii.gz")):
        print(f"docs.commands: skipped: no {MRICRON} (Debian's mricron-data)")
        return 77
    root = scratch_root(a.root, a.lacuna)
    env = dict(os.environ)
    env["PATH"] = os.path.join(root, "build") + os.pathsep + env.get("PATH", "")
    failures, ran, skipped = [], 0, 0
    try:
        for b in blocks:
            if b.skip:
                skipped += len(b.commands)
                print(f"skip {b.where()} ({len(b.commands)} commands): {b.skip}")
                continue
            benches = sum(1 for _, c in b.commands if is_bench(c))
            ran += len(b.commands) - benches
            skipped += benches
            failures += run_block(b, root, env, a.timeout)
    finally:
        shutil.rmtree(root, ignore_errors=True)
    print(f"docs.commands: {ran} commands run, {skipped} skipped, {len(failures)} failed")
    for where, cmd, status, msg in failures:
        print(f"FAIL {where}: exit {status}: {cmd}\n     {msg}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
