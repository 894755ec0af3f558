#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The main job: set up, build, and run hexatwist. Arguments go to hexatwist; the default is
# `study`: the paper's four tests on the seed platform, written to ./study-out/ in the folder you
# run this from. Example: bash scripts/run.sh ik --pose=0,0,0.1,0,0,30
# Paths you give (--config, --trajectory, --out) are taken relative to where you are.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# Build progress goes to stderr (the first build takes several minutes); stdout is hexatwist's.
bash "$root/scripts/build.sh" hexatwist_cli >&2
if [ $# -eq 0 ]; then set -- study; fi
exec "$root/build/hexatwist" "$@"
