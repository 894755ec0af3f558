#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs the Debian packages hexatwist needs to build and test, if any is missing.
# Non-interactive; runs apt-get as root (or through sudo). Safe to run again: it installs nothing
# when everything is present.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config ccache  # toolchain (ccache: scripts/ccache.sh)
  libeigen3-dev libyaml-cpp-dev libcli11-dev libfmt-dev   # library and CLI
  libceres-dev                                      # identification (nonlinear least squares)
  libgtest-dev libgmock-dev libbenchmark-dev        # tests and benchmarks
  libmujoco-dev                                     # MuJoCo 2.2: the tests and benchmark of the MJCF export
  gnuplot-nox                                       # figures
  clang libclang-rt-dev                             # fuzzing and sanitizer builds (libFuzzer, ASan, UBSan)
  clang-format python3-mypy                         # the format check and the Python stubs' type check (tests)
  linuxcnc-uspace linuxcnc-uspace-dev               # the LinuxCNC kinematics module and its tests (LinuxCNC 2.9)
  python3-pytest                                    # the tests that drive LinuxCNC and the Python package (Debian's python3)
  python3-jsonschema                                # the JSON outputs validated against docs/schemas/ (tests)
  mkdocs doxygen                                    # the documentation as an HTML site (scripts/docs_site.py, tests)
  python3-pip python3-setuptools python3-wheel python3-venv  # pip install . without downloads (pyproject.toml, tests)
  pybind11-dev python3-pybind11 python3-dev python3-numpy  # the Python package (bindings/python)
  python3-matplotlib python3-dask python3-distributed     # its examples and the Dask helper
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "hexatwist setup: installing ${missing[*]}" >&2
if [ "$(id -u)" -eq 0 ]; then
  sudo=()
elif command -v sudo >/dev/null 2>&1; then
  sudo=(sudo)
else
  echo "hexatwist setup: not root and no sudo; install as root: apt-get install ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
