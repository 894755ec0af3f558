#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Runs every `$ hexatwist ...` example of README.md and of the user guide (docs/guide/*.md) and
compares its output, digit for digit.

An example is a fenced block (```) whose first line starts with "$ ". Each "$ " line is run with
bash (stdout and stderr merged, as a terminal shows them) in one scratch folder per block, in
order, with `hexatwist` on PATH and the repository's examples/ and configs/ beside it; the lines
up to the next "$ " line are its expected output. A step whose expected lines all begin with
"hexatwist: " (the error examples) shows standard error alone, and is compared with it.

Volatile text is not compared:
  - the wall-clock times "in 1.3 s" and "in 3.2 s in all" (any number there matches);
  - in an expected line, "…" matches any text (README.md writes it where output varies).
A block that needs files the reader makes (high.csv, short.csv ...) makes them first, out of
sight, with one or more lines
    <!-- readme-example: setup: BASH COMMAND -->
just before its opening fence, run in order in the block's scratch folder (examples/ and configs/
are there). A block that cannot be run here at all (a real-time loop, a build tree) is skipped by
putting
    <!-- readme-example: skip -->
on the line just before its opening fence (or before its setup lines).

Usage: readme_examples.py FILE.md [FILE.md ...] path/to/hexatwist [--keep]
(examples/ and configs/ are those of the repository holding the first file.)
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

SKIP = "<!-- readme-example: skip -->"
SETUP = re.compile(r"^<!-- readme-example: setup: (.*) -->$")
WALL_TIME = re.compile(r"\bin \d+(\.\d+)? s\b")


def blocks(readme):
    """(line number, [setup commands], [(command, [expected lines])]) of every example block."""
    lines = readme.splitlines()
    out = []
    k = 0
    while k < len(lines):
        if lines[k].strip() == "```" and k + 1 < len(lines) and lines[k + 1].startswith("$ "):
            setup = []
            before = k - 1
            while before >= 0 and SETUP.match(lines[before].strip()):
                setup.insert(0, SETUP.match(lines[before].strip()).group(1))
                before -= 1
            skip = before >= 0 and lines[before].strip() == SKIP
            start = k + 1
            end = start
            while lines[end].strip() != "```":
                end += 1
            if not skip:
                steps = []
                for line in lines[start:end]:
                    if line.startswith("$ "):
                        steps.append((line[2:], []))
                    else:
                        steps[-1][1].append(line)
                out.append((start + 1, setup, steps))
            k = end + 1
        else:
            k += 1
    return out


def normalise(line):
    return WALL_TIME.sub("in <time> s", line.rstrip())


def matches(expected, actual):
    expected, actual = normalise(expected), normalise(actual)
    if "…" not in expected:
        return expected == actual
    pattern = ".*".join(re.escape(part) for part in expected.split("…"))
    return re.fullmatch(pattern, actual) is not None


def repository_root(path):
    """The nearest folder above `path` that holds examples/ and configs/."""
    folder = os.path.dirname(os.path.abspath(path))
    while not all(os.path.isdir(os.path.join(folder, d)) for d in ("examples", "configs")):
        parent = os.path.dirname(folder)
        if parent == folder:
            sys.exit(f"{path}: no repository (examples/ and configs/) above it")
        folder = parent
    return folder


def main():
    args = [a for a in sys.argv[1:] if a != "--keep"]
    if len(args) < 2:
        sys.exit(__doc__)
    paths, cli = args[:-1], os.path.abspath(args[-1])
    root = repository_root(paths[0])
    failures = checked = 0
    for path in paths:
        with open(path, encoding="utf-8") as f:
            text = f.read()
        name = os.path.relpath(path, root)
        file_failures, file_checked = check_file(name, text, root, cli)
        failures += file_failures
        checked += file_checked
    print(f"{checked} examples run in {len(paths)} file{'' if len(paths) == 1 else 's'}, {failures} differ")
    return 1 if failures else 0


def check_file(name, readme, root, cli):
    """Runs the examples of one file; returns (failures, examples run)."""
    failures = 0
    checked = 0
    for line_no, setup, steps in blocks(readme):
        scratch = tempfile.mkdtemp(prefix="hexatwist_readme_")
        try:
            bin_dir = os.path.join(scratch, ".bin")
            os.mkdir(bin_dir)
            os.symlink(cli, os.path.join(bin_dir, "hexatwist"))
            for d in ("examples", "configs"):
                os.symlink(os.path.join(root, d), os.path.join(scratch, d))
            env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get("PATH", ""))
            for command in setup:
                made = subprocess.run(["bash", "-c", command], cwd=scratch, env=env, stdout=subprocess.PIPE,
                                      stderr=subprocess.STDOUT, text=True, timeout=600)
                if made.returncode != 0:
                    failures += 1
                    print(f"{name}:{line_no}: setup failed: {command}\n{made.stdout}")
            for command, expected in steps:
                checked += 1
                errors_only = bool(expected) and all(e.startswith("hexatwist: ") for e in expected)
                run = subprocess.run(["bash", "-c", command], cwd=scratch, env=env,
                                     stdout=subprocess.DEVNULL if errors_only else subprocess.PIPE,
                                     stderr=subprocess.PIPE if errors_only else subprocess.STDOUT, text=True,
                                     timeout=600)
                actual = (run.stderr if errors_only else run.stdout).splitlines()
                ok = len(actual) == len(expected) and all(matches(e, a) for e, a in zip(expected, actual))
                if not ok:
                    failures += 1
                    print(f"{name}:{line_no}: $ {command}")
                    for k in range(max(len(expected), len(actual))):
                        e = expected[k] if k < len(expected) else "<none>"
                        a = actual[k] if k < len(actual) else "<none>"
                        if e == "<none>" or a == "<none>" or not matches(e, a):
                            print(f"  line {k + 1}:\n    shown:  {e}\n    actual: {a}")
        finally:
            if "--keep" not in sys.argv:
                shutil.rmtree(scratch, ignore_errors=True)
    return failures, checked


if __name__ == "__main__":
    sys.exit(main())
