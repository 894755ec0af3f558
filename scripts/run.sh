#!/usr/bin/env bash
# The main job: set up, build, and run hexatwist. Arguments go to hexatwist (default: `study`, the
# paper's four tests on the seed platform, written to study-out/). Example: bash scripts/run.sh ik --pose=0,0,0.1,0,0,30
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
if [ $# -eq 0 ]; then set -- study; fi
exec ./build/hexatwist "$@"
