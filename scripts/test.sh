#!/usr/bin/env bash
# Set up, build, and run every test through ctest (unit, property, CLI, install, examples,
# benchmark smoke run).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j2
