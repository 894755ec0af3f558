#!/usr/bin/env python3
"""Runs every `$ hexatwist ...` example of README.md and compares its output, digit for digit.

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

Usage: readme_examples.py README.md path/to/hexatwist [--keep]
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


def main():
    readme_path, cli = sys.argv[1], os.path.abspath(sys.argv[2])
    root = os.path.dirname(os.path.abspath(readme_path))
    with open(readme_path, encoding="utf-8") as f:
        readme = f.read()
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
                    print(f"README.md:{line_no}: setup failed: {command}\n{made.stdout}")
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
                    print(f"README.md:{line_no}: $ {command}")
                    for k in range(max(len(expected), len(actual))):
                        e = expected[k] if k < len(expected) else "<none>"
                        a = actual[k] if k < len(actual) else "<none>"
                        if e == "<none>" or a == "<none>" or not matches(e, a):
                            print(f"  line {k + 1}:\n    README: {e}\n    actual: {a}")
        finally:
            if "--keep" not in sys.argv:
                shutil.rmtree(scratch, ignore_errors=True)
    print(f"{checked} README examples run, {failures} differ")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
