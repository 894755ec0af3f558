#!/usr/bin/env python3
"""The library's subsystems depend one way (ARCHITECTURE.md):

    core (types, status, error) <- kinematics <- motion <- dynamics <- simulation <- calibration <- design

with io (files and formats) above them, used by the C API, the CLI and the bindings. Reads every
`#include "..."` of include/hexatwist/ and src/ and fails, naming file and line, on an include of a
subsystem above the includer's own: a back edge, which would make a cycle possible.

Usage: check_layers.py SOURCE_DIR
"""
import pathlib
import re
import sys

ORDER = ["core", "kinematics", "motion", "dynamics", "simulation", "calibration", "design", "io", "c_api"]
RANK = {name: rank for rank, name in enumerate(ORDER)}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def subsystem(path: str) -> str | None:
    """The subsystem a header or source belongs to, from its path below include/hexatwist/ or src/."""
    parts = pathlib.PurePosixPath(path).parts
    if parts and parts[0] == "hexatwist":
        parts = parts[1:]
    if not parts:
        return None
    if len(parts) == 1:
        return None if parts[0] == "hexatwist.hpp" else "core"  # the umbrella header includes everything
    head = "c_api" if parts[0] == "c" else parts[0]
    return head if head in RANK else None


def main() -> int:
    root = pathlib.Path(sys.argv[1]).resolve()
    edges = 0
    bad = []
    for base in (root / "include", root / "src"):
        for file in sorted(base.rglob("*")):
            if file.suffix not in (".hpp", ".cpp", ".h", ".c") or not file.is_file():
                continue
            own = subsystem(file.relative_to(base).as_posix())
            if own is None:
                continue
            for number, line in enumerate(file.read_text(encoding="utf-8").splitlines(), 1):
                match = INCLUDE.match(line)
                if not match:
                    continue
                target = subsystem(match.group(1))
                if target is None:
                    continue
                edges += 1
                if RANK[target] > RANK[own]:
                    bad.append(f"{file.relative_to(root)}:{number}: {own} includes {match.group(1)} ({target}, a "
                               f"layer above it)")
    for line in bad:
        print(line)
    print(f"check_layers: {edges} includes between subsystems read, {len(bad)} back edges "
          f"(order: {' <- '.join(ORDER)})")
    return 1 if bad or edges == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
