#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Every C and C++ file of the project is formatted as .clang-format says (Debian's clang-format 14):
runs `clang-format --dry-run --Werror` over them and fails naming each file that would change.

Usage: check_format.py SOURCE_DIR [CLANG_FORMAT]
"""
import pathlib
import subprocess
import sys

FOLDERS = ("apps", "bench", "bindings", "examples", "fuzz", "include", "integrations", "src", "tests")
SUFFIXES = (".c", ".h", ".cpp", ".hpp")


def main() -> int:
    root = pathlib.Path(sys.argv[1]).resolve()
    tool = sys.argv[2] if len(sys.argv) > 2 else "clang-format"
    files = sorted(str(f) for folder in FOLDERS for f in (root / folder).rglob("*")
                   if f.suffix in SUFFIXES and f.is_file())
    if not files:
        print(f"check_format: no source files under {root}")
        return 1
    bad = []
    for start in range(0, len(files), 50):
        batch = files[start:start + 50]
        try:
            run = subprocess.run([tool, "--dry-run", "--Werror", *batch], capture_output=True, text=True, timeout=300)
        except FileNotFoundError:
            print(f"check_format: '{tool}' not found: install Debian's clang-format (scripts/setup.sh does)")
            return 1
        if run.returncode != 0:
            bad.extend(sorted({line.split(":")[0] for line in run.stderr.splitlines() if ": error:" in line}))
    for file in bad:
        print(f"{pathlib.Path(file).relative_to(root)}: not formatted (clang-format -i {file})")
    print(f"check_format: {len(files)} files, {len(bad)} not formatted")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
