#!/usr/bin/env bash
# A c3po built with C3PO_WITH_POINTNET=OFF: the commands that need the pointnet
# detector (train, selftrain, bench pointnet, demo) exit 2 with one line saying
# so and write nothing; certify with the svd detector still works. Skipped
# (77) in a build with pointnet.
# Usage: without_pointnet.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -u
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
[ "${C3PO_WITH_POINTNET:-ON}" == OFF ] || { echo "SKIP: this c3po has the pointnet detector"; exit 77; }
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
OBJ="$SRC/tests/fixtures/objects/cube.json"
"$C3PO" synth "$OBJ" -o sim --kind sim --count 3 --points 100 --seed 1 >/dev/null 2>&1 || { echo "synth failed"; exit 1; }

# refused NAME CMD...: status 2, one stderr line naming pointnet and the build option, no output file.
refused() {
  local name=$1; shift
  "$@" > "$name.out" 2> "$name.err"; local status=$?
  [ $status -eq 2 ] || fail "$name: status $status, expected 2"
  [ "$(wc -l < "$name.err")" -eq 1 ] || fail "$name: stderr is not one line: $(cat "$name.err")"
  grep -q "pointnet.*C3PO_WITH_POINTNET=OFF" "$name.err" || fail "$name: stderr does not say why: $(cat "$name.err")"
  echo "ok: $name -> $(cat "$name.err")"
}
refused train "$C3PO" train "$OBJ" --data sim -o x.model --epochs 1
refused selftrain "$C3PO" selftrain "$OBJ" --model x.model --data sim -o y.model
refused bench_pointnet "$C3PO" bench pointnet --points 64
refused demo "$C3PO" demo --quick --out demo_out
[ ! -e x.model ] && [ ! -e y.model ] && [ ! -e demo_out ] || fail "an output was written"

"$C3PO" certify "$OBJ" --detector svd --data sim > certify.out 2>&1; status=$?
[ $status -le 1 ] || fail "certify --detector svd exited $status: $(tail -2 certify.out)"
grep -q "^certified " certify.out || fail "certify printed no summary"

echo "failures: $failures"
[ $failures -eq 0 ]
