#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Every source file names its licence (LICENSE, BSD-3-Clause) in an SPDX line among its first
two (after a #! line): C and C++ sources and headers, Python, shell and CMake files, below the
source folder except build folders, hidden folders (.ci is read) and test data.

Usage: check_licence.py SOURCE_DIR
"""
import pathlib
import sys

TAG = "SPDX-License-Identifier: BSD-3-Clause"
SUFFIXES = {".cpp", ".hpp", ".h", ".c", ".py", ".pyi", ".sh", ".cmake"}
NAMES = {"CMakeLists.txt", "run"}


def sources(root: pathlib.Path):
    for file in sorted(root.rglob("*")):
        rel = file.relative_to(root)
        top = rel.parts[0]
        if not file.is_file() or top.startswith("build") or (top.startswith(".") and top != ".ci"):
            continue
        if "data" in rel.parts[:-1] or "corpus" in rel.parts[:-1] or "__pycache__" in rel.parts:
            continue
        if file.suffix in SUFFIXES or file.name in NAMES or file.name.endswith((".cpp.in", ".cmake.in")):
            yield file, rel


def main() -> int:
    root = pathlib.Path(sys.argv[1]).resolve()
    read, missing = 0, []
    for file, rel in sources(root):
        read += 1
        head = file.read_text(encoding="utf-8").splitlines()[:2]
        if not any(TAG in line for line in head):
            missing.append(str(rel))
    for name in missing:
        print(f"{name}: no '{TAG}' line among the first two")
    licence = (root / "LICENSE").read_text(encoding="utf-8")
    if not licence.startswith("BSD 3-Clause License"):
        print("LICENSE: not the BSD 3-Clause License the SPDX lines name")
        missing.append("LICENSE")
    print(f"check_licence: {read} source files read, {len(missing)} without the licence")
    return 1 if missing or read == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
