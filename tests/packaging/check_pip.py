#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""`pip install .` as a user runs it (pyproject.toml, setup.py), checked: the source tree is copied
(without its build folders and .git) to a scratch folder, pip builds and installs the package from
the copy with Debian's build tools (--no-build-isolation --no-deps --no-index: nothing is
downloaded) into a scratch target, and Debian's python3 imports it from there: its version is the
library's, and its compensated commands on random poses are those of the build tree's module bit
for bit. Run by ctest (packaging.pip_install_builds_the_python_package):

    check_pip.py SOURCE_DIR BUILD_DIR WORK_DIR
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

PROBE = """
import sys, numpy as np, hexatwist
print(hexatwist.__file__)
print(hexatwist.__version__)
rng = np.random.default_rng(7)
poses = np.column_stack([rng.uniform(-0.2, 0.2, (50, 3)), rng.uniform(-0.2, 0.2, (50, 3))])
r = hexatwist.commands(hexatwist.load_model(hexatwist.seed_config_yaml()), poses, strategy="compensated")
print(np.asarray(r.commands).tobytes().hex())
print(np.asarray(r.status).tobytes().hex())
"""


def probe(pythonpath: Path) -> list[str]:
    env = dict(os.environ, PYTHONPATH=str(pythonpath))
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, env=env, timeout=120)
    if out.returncode != 0:
        raise SystemExit(f"check_pip: importing hexatwist from {pythonpath} failed:\n{out.stderr}")
    return out.stdout.splitlines()


def main() -> int:
    source, build, work = (Path(a).resolve() for a in sys.argv[1:4])
    shutil.rmtree(work, ignore_errors=True)
    copy = work / "hexatwist-src"
    # A user's tree: the sources without build products (build/, build-*/, .git).
    shutil.copytree(source, copy, ignore=lambda d, names: [n for n in names if Path(d) == source and
                                                           (n.startswith("build") or n == ".git")])
    target = work / "site-packages"
    cmd = [sys.executable, "-m", "pip", "install", "--no-build-isolation", "--no-deps", "--no-index",
           "--disable-pip-version-check", "--target", str(target), str(copy)]
    print("check_pip:", " ".join(cmd), flush=True)
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=1500)
    if result.returncode != 0:
        print(result.stdout[-6000:], result.stderr[-6000:], sep="\n", file=sys.stderr)
        print(f"check_pip: pip install failed (exit {result.returncode})", file=sys.stderr)
        return 1
    installed, built = probe(target), probe(build / "python")
    if not installed[0].startswith(str(target)):
        print(f"check_pip: hexatwist was imported from {installed[0]}, not from the pip target {target}",
              file=sys.stderr)
        return 1
    version = (source / "include/hexatwist/version.hpp").read_text(encoding="utf-8")
    if installed[1] != built[1] or f"VERSION_MAJOR {installed[1].split('.')[0]}" not in version:
        print(f"check_pip: version {installed[1]} against the build tree's {built[1]}", file=sys.stderr)
        return 1
    if installed[2:] != built[2:]:
        print("check_pip: the installed package's commands differ from the build tree's", file=sys.stderr)
        return 1
    for f in ("py.typed", "_hexatwist.pyi", "cluster.py"):
        if not (target / "hexatwist" / f).is_file():
            print(f"check_pip: {f} was not installed", file=sys.stderr)
            return 1
    print(f"check_pip: hexatwist {installed[1]} installed by pip into {target}; its commands are the build's")
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
