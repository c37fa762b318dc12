#!/usr/bin/env bash
# Builds c3po with AddressSanitizer + UndefinedBehaviorSanitizer
# (-DC3PO_SANITIZE=ON: UB aborts, it is never only reported) into
# ./build-asan and runs the ctest suite there, except the tests labelled
# "heavy" (the long training and whole-dataset runs, `ctest -N -L heavy`; they
# run in the Release suite, and here they would take ~1 h of CI's budget):
#   scripts/sanitize.sh [extra ctest arguments, e.g. -R pattern]
#   C3PO_SANITIZE_ALL=1 scripts/sanitize.sh     # the heavy tests too
# -O1 keeps the build and the suite fast enough for CI; -g1 gives line numbers
# in the reports. LeakSanitizer is on (the default); the suite needs no leak
# suppression (the one known third-party leak, assimp 5.2's OBJ importer on
# malformed files, is only reached by the mesh fuzzer, see scripts/fuzz.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
build=${C3PO_ASAN_BUILD:-$src/build-asan}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DC3PO_SANITIZE=ON >/dev/null
cmake --build "$build" -j"$(nproc)"
export ASAN_OPTIONS="abort_on_error=0:detect_stack_use_after_return=0:strict_string_checks=1:check_initialization_order=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
# The bad-input corpus's huge cloud: 10^6 points here (10^7 in the Release run).
export C3PO_HUGE_POINTS=${C3PO_HUGE_POINTS:-1000000}
# interrupt_resume.sh (heavy): a smaller training run (epochs ~35x slower here).
export C3PO_ROBUSTNESS_LIGHT=${C3PO_ROBUSTNESS_LIGHT:-1}
labels=(-LE heavy)
[ "${C3PO_SANITIZE_ALL:-0}" = 1 ] && labels=()
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" --timeout 1200 "${labels[@]}" "$@"
