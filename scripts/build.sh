#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs missing packages, then configures and builds hexatwist (Release) in build/.
#   bash scripts/build.sh              every target: the library, the CLI, tests, benchmarks, examples,
#                                      the Python package and the LinuxCNC module (scripts/test.sh)
#   bash scripts/build.sh TARGET...    only those and what they need (scripts/run.sh: hexatwist_cli)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
source scripts/ccache.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "${ccache_flags[@]}" >/dev/null
if [ ! -f build/build.ninja ] || [ ! -x build/hexatwist ]; then
  echo "hexatwist: building in build/ (the first build takes a few minutes on 2 cores)" >&2
fi
if [ $# -gt 0 ]; then
  targets=()
  for t in "$@"; do targets+=(--target "$t"); done
  cmake --build build "${targets[@]}"
else
  cmake --build build
fi
