#!/usr/bin/env bash
# Installs missing packages, then configures and builds hexatwist (Release) in build/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
if [ ! -f build/build.ninja ] || [ ! -x build/hexatwist ]; then
  echo "hexatwist: building in build/ (the first build takes several minutes on 2 cores)" >&2
fi
cmake --build build
