#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Builds the libFuzzer targets (clang, with ASan and UBSan) in build-fuzz/ and runs each for
# SECONDS (default 60). Each run reads the seed corpus fuzz/corpus/<target>/ and the saved
# regressions, writes the inputs it finds into a scratch corpus build-fuzz/corpus/<target>/
# (the repository stays clean) and stops at the first crash, leaving the input in
# build-fuzz/artifacts/<target>/.
#   bash scripts/fuzz.sh [SECONDS] [TARGET...]      TARGET: config, trajectory_csv, pose_line
# HEXATWIST_FUZZ_SEED=N fixes libFuzzer's random seed, so a run explores the same sequence of inputs
# every time (scripts/test.sh uses seed 1: a test must not pass or fail by chance). Unset, each
# run draws a new seed and explores new ground: that is how to hunt for bugs.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift $(( $# > 0 ? 1 : 0 ))
bash scripts/setup.sh
source scripts/ccache.sh

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for source in fuzz/fuzz_*.cpp; do
    name=$(basename "$source" .cpp)
    targets+=("${name#fuzz_}")
  done
fi

cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DHEXATWIST_FUZZ=ON \
  -DHEXATWIST_BUILD_APPS=OFF -DHEXATWIST_BUILD_TESTS=OFF -DHEXATWIST_BUILD_BENCHMARKS=OFF \
  -DHEXATWIST_BUILD_EXAMPLES=OFF "${ccache_flags[@]}" >/dev/null
cmake --build build-fuzz -- -j2

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:strict_string_checks=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
for target in "${targets[@]}"; do
  [ -x "build-fuzz/fuzz_$target" ] || { echo "hexatwist fuzz: no target '$target'" >&2; exit 2; }
  corpus=build-fuzz/corpus/$target artifacts=build-fuzz/artifacts/$target log=build-fuzz/fuzz_$target.log
  rm -rf "$artifacts"
  [ -n "${HEXATWIST_FUZZ_SEED:-}" ] && rm -rf "$corpus"  # a seeded run starts from the same inputs
  mkdir -p "$corpus" "$artifacts"
  inputs=("$corpus" "fuzz/corpus/$target")
  [ -d "fuzz/regressions/$target" ] && inputs+=("fuzz/regressions/$target")
  # A single allocation above 256 MB is a bug here (the inputs are a few kB) and is reported at
  # once; memory that grows by small steps is caught at 2 GB, but libFuzzer's report of it can hang
  # (seen with ASan): the outer timeout ends such a run.
  options=(-max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -malloc_limit_mb=256 -print_final_stats=1
           -artifact_prefix="$artifacts/")
  [ -f "fuzz/dict/$target.dict" ] && options+=(-dict="fuzz/dict/$target.dict")
  [ -n "${HEXATWIST_FUZZ_SEED:-}" ] && options+=(-seed="$HEXATWIST_FUZZ_SEED")
  echo "hexatwist fuzz: $target for ${seconds} s, seed ${HEXATWIST_FUZZ_SEED:-random} (log: $log)" >&2
  if ! timeout -k 10 $((seconds + 120)) "build-fuzz/fuzz_$target" "${options[@]}" "${inputs[@]}" >"$log" 2>&1; then
    tail -n 60 "$log" >&2
    echo "hexatwist fuzz: $target FAILED; the input is in $artifacts/. Fix the bug, then keep the input as a" \
         "regression test: cp $artifacts/<file> fuzz/regressions/$target/" >&2
    exit 1
  fi
  grep -E '^(stat::number_of_executed_units|stat::peak_rss_mb|Done)|cov: .*(DONE|INITED)' "$log" | tail -n 4 |
    sed "s/^/  /" >&2 || true
done
