#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""The library's subsystems depend one way (ARCHITECTURE.md):

    core (types, status, error) <- kinematics <- motion <- dynamics <- simulation <- calibration <- design

with io (files and formats) above them, used by the C API, the CLI and the bindings. Reads every
`#include "..."` of include/hexatwist/ and src/ and fails, naming file and line, on an include of a
subsystem above the includer's own: a back edge, which would make a cycle possible.

The layers over the library use it, not each other's internals: an include of apps/hexatwist/ (the
CLI) or bindings/python/ (the Python module) is a file of its own folder or a public header
(include/hexatwist/), never one of src/ or of another front end; the LinuxCNC module
(integrations/linuxcnc/) includes only the C API (hexatwist/c/) besides LinuxCNC's own headers; and
the Python package (python/hexatwist/) imports only itself and its compiled module.

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
    front = front_end_includes(root, bad)
    for line in bad:
        print(line)
    print(f"check_layers: {edges} includes between subsystems read, {front} of the front ends, {len(bad)} "
          f"problems (order: {' <- '.join(ORDER)})")
    return 1 if bad or edges == 0 or front == 0 else 0


# Each front end's folder and the public headers it may include (a prefix below include/).
FRONT_ENDS = {"apps/hexatwist": "hexatwist/", "bindings/python": "hexatwist/", "integrations/linuxcnc": "hexatwist/c/"}
IMPORT = re.compile(r"^\s*(?:from\s+(\S+)\s+import|import\s+(\S+))")


def front_end_includes(root: pathlib.Path, bad: list[str]) -> int:
    """Checks the front ends' includes (and the Python package's imports); returns how many were read."""
    internal = [root / "src", root / "apps" / "hexatwist", root / "bindings" / "python"]
    read = 0
    for folder, public in FRONT_ENDS.items():
        for file in sorted((root / folder).rglob("*")):
            if file.suffix not in (".hpp", ".cpp", ".h", ".c") or not file.is_file():
                continue
            for number, line in enumerate(file.read_text(encoding="utf-8").splitlines(), 1):
                match = INCLUDE.match(line)
                if not match:
                    continue
                read += 1
                name = match.group(1)
                if (file.parent / name).is_file():
                    continue  # its own folder
                if (root / "include" / name).is_file():
                    if not name.startswith(public):
                        bad.append(f"{file.relative_to(root)}:{number}: includes {name}; {folder} may include "
                                   f"only {public}")
                    continue
                owner = next((d for d in internal if (d / name).is_file()), None)
                if owner is not None:
                    bad.append(f"{file.relative_to(root)}:{number}: includes {name}, an internal header of "
                               f"{owner.relative_to(root)}")
                # Anything else is outside the tree: the system's, LinuxCNC's.
    for file in sorted((root / "python" / "hexatwist").glob("*.py")):
        for number, line in enumerate(file.read_text(encoding="utf-8").splitlines(), 1):
            match = IMPORT.match(line)
            if not match:
                continue
            read += 1
            module = match.group(1) or match.group(2)
            if module.startswith("hexatwist") and not module.startswith("hexatwist."):
                continue
            if module.startswith(("apps", "bindings", "src", "tests")):
                bad.append(f"{file.relative_to(root)}:{number}: imports {module}, outside the package")
    return read


if __name__ == "__main__":
    sys.exit(main())
