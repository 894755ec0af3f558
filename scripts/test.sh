#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Set up, build, and run every test: the Release suite through ctest (unit, property, CLI, install,
# examples, fuzz-input replays, stream stress test, benchmark smoke run); the same suite built with
# AddressSanitizer + UndefinedBehaviorSanitizer in build-asan/; a bounded run of each libFuzzer
# target (scripts/fuzz.sh, HEXATWIST_FUZZ_SECONDS per target, default 60, with the fixed seed
# HEXATWIST_FUZZ_SEED, default 1, so that the stage explores the same inputs on every run).
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
stage_start=$SECONDS
stage_done() {
  echo "hexatwist test: $1 passed in $((SECONDS - stage_start)) s" >&2
  stage_start=$SECONDS
}

bash scripts/build.sh
source scripts/ccache.sh
ctest --test-dir build --output-on-failure -j2
stage_done "Release build and tests"

# Any finding stops the program (-fno-sanitize-recover=all; ASan halts by itself) with an abort,
# so that no test can take it for an ordinary exit code.
sanitizer_env=(ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:check_initialization_order=1:detect_stack_use_after_return=1
               UBSAN_OPTIONS=print_stacktrace=1:abort_on_error=1)
if [ ! -f build-asan/build.ninja ]; then
  echo "hexatwist: building with the sanitizers in build-asan/ (the first build takes several minutes)" >&2
fi
# At the AVX2 level (x86-64-v3), so that this build runs the leg kernels in their two-packet form (src/kinematics/lanes.hpp)
# where the Release build, on a CPU with AVX-512, runs the one-packet form.
# The examples are left to the Release stage (their library calls run here in the tests).
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DHEXATWIST_SANITIZE=ON \
  -DHEXATWIST_BUILD_BENCHMARKS=OFF -DHEXATWIST_BUILD_EXAMPLES=OFF -DHEXATWIST_ARCH=x86-64-v3 "${ccache_flags[@]}" >/dev/null
env "${sanitizer_env[@]}" cmake --build build-asan -- -j2
# Left to the Release stage, to keep CI within its time (this build runs ~25x slower):
# - the printed digits of the README and the guide, which are the Release build's (the same commands run here in their
#   own tests; this build, without AVX-512 and at -O1, differs in an identification's last digits);
# - the JSON outputs against their schemas (the same writer in both builds);
# - a closed standard output walked across every command (the same roll back as a failed write,
#   which CliOutputs tests here), and the log clock through identify (test_log_clock runs here);
# - statistics that repeat one computation over many seeds, platforms or grids, whose code paths
#   the other tests of the same file run here once;
# - the option table's second walk (every option given another value: whether the run's outputs
#   change, 89 runs of the tool, 340 s here): the first walk runs the same options here.
release_only=(
  'CliReadme[.]'
  'Docs[.]EveryJsonOutputIsValidAgainstItsSchema$'
  'CliSignals[.]AClosedStandardOutputIsAFailedWriteRolledBack$'
  'CliIdentify[.]TheLogsClockIsFoundFromTheRestsAndALogOfAnotherRunIsRefusedAsMeasureRefusesIt$'
  'WorkspaceVolume[.]SymmetriesOfTheSeedGiveEqualVolumesWithinTheStatedError$'
  'WorkspaceVolume[.]AgreesWithAnIndependentMonteCarloEstimateToOnePercent$'
  'WorkspaceVolume[.]StatedErrorBoundsTheErrorAgainstAFinerGrid$'
  'AxisDesign[.]EveryObjectiveAndSymmetryDoesNoWorseThanTheModelOnRandomPlatforms$'
  'StationPlan[.]PlannedStationsBeatRandomOnesOnThePredictedWorstError$'
  'Identification[.]ReportedStandardDeviationsAreHonestOverFiftySeeds$'
  'CliOptionTable[.]EveryOtherValueOfAnOptionChangesWhatIsDoneOrIsRefused$'
)
exclude="^($(IFS='|'; echo "${release_only[*]}"))"
env "${sanitizer_env[@]}" ctest --test-dir build-asan --output-on-failure -j2 -E "$exclude"
stage_done "ASan + UBSan build and tests"

HEXATWIST_FUZZ_SEED=${HEXATWIST_FUZZ_SEED:-1} bash scripts/fuzz.sh "${HEXATWIST_FUZZ_SECONDS:-60}"
stage_done "fuzzing"
echo "hexatwist test: all passed in $((SECONDS - start)) s" >&2
