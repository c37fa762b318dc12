#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, -DC3PO_FUZZ=ON) and runs each for
# SECONDS, as many at once as there are cores (C3PO_FUZZ_JOBS to choose):
#   scripts/fuzz.sh SECONDS [TARGET...]
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
cmake --build "$build" --target $(printf 'fuzz_%s ' "${targets[@]}") -j"$(nproc)" >/dev/null || exit 2

seeds_for() {
  case $1 in
    ply|pcd|xyz) echo "$src/tests/fixtures/clouds" ;;
    object_json) echo "$src/tests/fixtures/objects" ;;
    *) echo "" ;;
  esac
}

# One target: fuzz it, then write its table row to $build/fuzz-logs/<target>.row
# (executions, rate, findings; "none" when clean).
fuzz_one() {
  local t=$1
  local exe=$build/tests/fuzz/fuzz_$t
  local work=$build/fuzz-corpus/$t
  local artifacts=$build/fuzz-artifacts/$t
  local log=$build/fuzz-logs/$t.log
  rm -rf "$artifacts"   # findings of earlier runs are not this run's
  mkdir -p "$work" "$artifacts" "$(dirname "$log")"
  # Seed folders that exist (git keeps no empty folder in a clean clone).
  local seeds=() dir
  for dir in "$src/tests/fuzz/corpus/$t" $(seeds_for "$t"); do [ -d "$dir" ] && seeds+=("$dir"); done
  "$exe" "$work" "${seeds[@]}" \
    -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    -artifact_prefix="$artifacts/" >"$log" 2>&1
  local code=$?
  local runs rate found
  runs=$(grep -m1 '^stat::number_of_executed_units' "$log" | awk '{print $2}')
  rate=$(grep -m1 '^stat::average_exec_per_sec' "$log" | awk '{print $2}')
  found=$(ls "$artifacts" 2>/dev/null | tr '\n' ' ')
  # A finding is an artifact file; a non-zero exit or no statistics (the
  # fuzzer did not run to its time limit) fails as well.
  [ $code -ne 0 ] && [ -z "$found" ] && found="exit-status-$code"
  [ -z "$runs" ] && [ -z "$found" ] && found="no-statistics"
  printf '%-12s %12s %10s  %s\n' "$t" "${runs:-?}" "${rate:-?}" "${found:-none}" >"$build/fuzz-logs/$t.row"
}

jobs_max=${C3PO_FUZZ_JOBS:-$(nproc)}
mkdir -p "$build/fuzz-logs"
for t in "${targets[@]}"; do
  rm -f "$build/fuzz-logs/$t.row"
  while [ "$(jobs -rp | wc -l)" -ge "$jobs_max" ]; do wait -n; done
  fuzz_one "$t" &
done
wait

# The table in the targets' order, whatever order they finished in.
status=0
printf '%-12s %12s %10s  %s\n' target executions exec/s findings
for t in "${targets[@]}"; do
  row=$build/fuzz-logs/$t.row
  if [ -f "$row" ]; then cat "$row"; else printf '%-12s %12s %10s  %s\n' "$t" '?' '?' 'no-result'; fi
  [ -f "$row" ] && [[ "$(awk '{print $4}' "$row")" == none ]] || status=1
done
[ $status -ne 0 ] && echo "findings in $build/fuzz-artifacts; logs in $build/fuzz-logs"
exit $status
