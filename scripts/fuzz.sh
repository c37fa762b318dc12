#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, -DC3PO_FUZZ=ON) and runs each for
# SECONDS, one after another: scripts/fuzz.sh SECONDS [TARGET...]
# Prints executions per target and any crash/timeout/oom/leak file; exits 1
# if a target found one or did not run cleanly (UB aborts: the fuzz build
# uses -fno-sanitize-recover=undefined). New corpus entries go to BUILD/fuzz-corpus/<target>
# (the seeds in tests/fuzz/corpus and tests/fixtures are never modified).
set -u
seconds=${1:?usage: scripts/fuzz.sh SECONDS [TARGET...]}
shift
src=$(cd "$(dirname "$0")/.." && pwd)
build=${C3PO_FUZZ_BUILD:-$src/build-fuzz}
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(ply pcd xyz manifest object_json mesh poses model png bop_json rle npy eval_samples)

CC=clang CXX=clang++ cmake -S "$src" -B "$build" -G Ninja -DC3PO_FUZZ=ON -DC3PO_BUILD_TESTS=OFF >/dev/null || exit 2
cmake --build "$build" --target $(printf 'fuzz_%s ' "${targets[@]}") -j2 >/dev/null || exit 2

seeds_for() {
  case $1 in
    ply|pcd|xyz) echo "$src/tests/fixtures/clouds" ;;
    object_json) echo "$src/tests/fixtures/objects" ;;
    *) echo "" ;;
  esac
}

status=0
printf '%-12s %12s %10s  %s\n' target executions exec/s findings
for t in "${targets[@]}"; do
  exe=$build/tests/fuzz/fuzz_$t
  work=$build/fuzz-corpus/$t
  artifacts=$build/fuzz-artifacts/$t
  rm -rf "$artifacts"   # findings of earlier runs are not this run's
  mkdir -p "$work" "$artifacts"
  log=$build/fuzz-logs/$t.log
  mkdir -p "$(dirname "$log")"
  # Seed folders that exist (git keeps no empty folder in a clean clone).
  seeds=()
  for dir in "$src/tests/fuzz/corpus/$t" $(seeds_for "$t"); do [ -d "$dir" ] && seeds+=("$dir"); done
  "$exe" "$work" "${seeds[@]}" \
    -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    -artifact_prefix="$artifacts/" >"$log" 2>&1
  code=$?
  runs=$(grep -m1 '^stat::number_of_executed_units' "$log" | awk '{print $2}')
  rate=$(grep -m1 '^stat::average_exec_per_sec' "$log" | awk '{print $2}')
  found=$(ls "$artifacts" 2>/dev/null | tr '\n' ' ')
  # A finding is an artifact file; a non-zero exit or no statistics (the
  # fuzzer did not run to its time limit) fails as well.
  [ $code -ne 0 ] && [ -z "$found" ] && found="exit-status-$code"
  [ -z "$runs" ] && [ -z "$found" ] && found="no-statistics"
  [ -n "$found" ] && status=1
  printf '%-12s %12s %10s  %s\n' "$t" "${runs:-?}" "${rate:-?}" "${found:-none}"
done
[ $status -ne 0 ] && echo "findings in $build/fuzz-artifacts; logs in $build/fuzz-logs"
exit $status
