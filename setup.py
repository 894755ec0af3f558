# SPDX-License-Identifier: BSD-3-Clause
"""The build of `pip install .` (pyproject.toml): the pure-Python package from python/hexatwist and
the extension module hexatwist._hexatwist built by CMake from this source tree (the target
hexatwist_python, Release, for this computer's x86-64 level as the CMake build is), in build-python/
beside build/ so that ccache (when installed) reuses the objects of an earlier build of the same
sources. Nothing is downloaded: CMake finds Eigen, yaml-cpp, Ceres and pybind11 from Debian's
packages (scripts/setup.sh)."""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
BUILD = ROOT / "build-python"


def version() -> str:
    text = (ROOT / "include/hexatwist/version.hpp").read_text(encoding="utf-8")
    parts = [re.search(rf"#define HEXATWIST_VERSION_{p} (\d+)", text) for p in ("MAJOR", "MINOR", "PATCH")]
    if not all(parts):
        raise RuntimeError("setup.py: include/hexatwist/version.hpp does not define HEXATWIST_VERSION_MAJOR/MINOR/PATCH")
    return ".".join(m.group(1) for m in parts if m)


class CMakeBuild(build_ext):
    """Builds the extension with the project's own CMake instead of setuptools' compiler calls."""

    def build_extension(self, ext: Extension) -> None:
        cmake = shutil.which("cmake")
        if cmake is None:
            raise RuntimeError("setup.py: cmake not found (apt-get install cmake, or bash scripts/setup.sh)")
        build = BUILD
        env = dict(os.environ)
        flags = ["-DCMAKE_BUILD_TYPE=Release", f"-DPython_EXECUTABLE={sys.executable}", "-DHEXATWIST_PYTHON=ON",
                 "-DHEXATWIST_BUILD_TESTS=OFF", "-DHEXATWIST_BUILD_BENCHMARKS=OFF", "-DHEXATWIST_BUILD_EXAMPLES=OFF",
                 "-DHEXATWIST_BUILD_APPS=OFF", "-DHEXATWIST_LINUXCNC=OFF", "-DHEXATWIST_MUJOCO=OFF"]
        if shutil.which("ninja"):
            flags += ["-G", "Ninja"]
        if shutil.which("ccache") and env.get("HEXATWIST_CCACHE", "1") != "0":
            # As scripts/ccache.sh: paths hashed relative to the sources, so build/ and build-python/
            # (one level below them both) share the objects.
            env.update(CCACHE_BASEDIR=str(ROOT), CCACHE_NOHASHDIR="1")
            flags += ["-DCMAKE_C_COMPILER_LAUNCHER=ccache", "-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"]
        jobs = str(os.cpu_count() or 1)
        subprocess.run([cmake, "-S", str(ROOT), "-B", str(build), *flags], check=True, env=env, cwd=ROOT)
        subprocess.run([cmake, "--build", str(build), "--target", "hexatwist_python", "--parallel", jobs], check=True,
                       env=env, cwd=ROOT)
        built = sorted((build / "python/hexatwist").glob("_hexatwist*.so"))
        if len(built) != 1:
            raise RuntimeError(f"setup.py: expected one _hexatwist module in {build / 'python/hexatwist'}, found "
                               f"{len(built)}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built[0], target)


BUILD.mkdir(exist_ok=True)
setup(
    version=version(),
    packages=["hexatwist"],
    package_dir={"": "python"},
    package_data={"hexatwist": ["py.typed", "*.pyi"]},
    ext_modules=[Extension("hexatwist._hexatwist", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": str(BUILD / "setuptools")},
             "egg_info": {"egg_base": str(BUILD)}},
    zip_safe=False,
)
