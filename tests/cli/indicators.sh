#!/usr/bin/env bash
# ctest-labels: heavy
# c3po indicators end to end: listing, editing with validation (bad input =>
# exit 2 and the file untouched), in-place writes with a backup, --coverage on
# a rendered dataset (handle sets fail on handle-less views), --auto with
# --write carrying its evidence.
# Usage: indicators.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -uo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
fail() { echo "FAIL: $*"; exit 1; }
source "$(dirname "$0")/lib.sh"

cp "$SRC/annotations/mug.json" "$SRC/annotations/mug.obj" .

# Listing names the keypoints of every set.
out=$("$C3PO" indicators mug.json) || fail "list exit $?"
grep -q "3 indicator sets" <<< "$out" || fail "list: $out"
grep -q "set 1: {9 handle_middle}" <<< "$out" || fail "list names: $out"

# Invalid edits: exit 2, one line naming the problem, file unchanged.
cp mug.json original.json
for args in "--set 1,99" "--set 2,2" "--set 9" "--remove 3" "--set x"; do
  expect_bad_input mug.json.bak "" "$C3PO" indicators mug.json $args
  cmp -s mug.json original.json || fail "'$args' changed the file"
done
# --auto's options are checked before any work or output.
expect_bad_input mug.json.bak "--views" "$C3PO" indicators mug.json --auto --views 0 --write
expect_bad_input mug.json.bak "--test-views" "$C3PO" indicators mug.json --auto --test-views 0 --write
expect_bad_input mug.json.bak "--max-set-size" "$C3PO" indicators mug.json --auto --max-set-size 7 --write
[ -s bad_input.out ] && fail "--auto printed before refusing: $(cat bad_input.out)"
cmp -s mug.json original.json || fail "a refused --auto changed the file"

# Edit to -o: the input stays, the output has the new sets.
"$C3PO" indicators mug.json --remove 0 --set 0,4 -o edited.json > /dev/null || fail "edit -o"
cmp -s mug.json original.json || fail "-o changed the input"
grep -q '"indicator_sets"' edited.json || fail "edited.json"
out=$("$C3PO" indicators edited.json)
grep -q "set 2: {0 rim_handle_side, 4 base_handle_side}" <<< "$out" || fail "edited sets: $out"
grep -q "set 0: {9 handle_middle}" <<< "$out" || fail "remove 0: $out"

# In place: a backup of the original, then --clear.
cp edited.json before_clear.json
"$C3PO" indicators edited.json --clear > /dev/null || fail "clear"
cmp -s edited.json.bak before_clear.json || fail "the backup is not the file before the edit"
out=$("$C3PO" indicators edited.json)
grep -q "0 indicator sets (nd = 1 always)" <<< "$out" || fail "cleared: $out"

# --write without --auto is refused.
"$C3PO" indicators mug.json --write > /dev/null 2>&1
[ $? -eq 2 ] || fail "--write without --auto"

# Coverage on rendered views: every view passes with no sets; with the handle
# sets, the views in which no handle keypoint is seen fail.
"$C3PO" synth mug.json -o depth --kind depth --count 24 --points 600 --seed 4 > /dev/null 2>&1 || fail "synth"
out=$("$C3PO" indicators mug.json --coverage depth) || fail "coverage exit $?"
grep -q "24 views" <<< "$out" || fail "coverage: $out"
nd=$(echo "$out" | sed -n 's/.*nd = 1 in \([0-9]*\) of 24 views.*/\1/p')
[ -n "$nd" ] && [ "$nd" -lt 24 ] && [ "$nd" -gt 0 ] || fail "handle sets should pass some views, not all: $out"
out=$("$C3PO" indicators edited.json --coverage depth) || fail "coverage (no sets)"
grep -q "nd = 1 in 24 of 24 views" <<< "$out" || fail "no sets => always: $out"

# --auto prints without writing; --write -o writes the sets and the evidence.
cp mug.json before_auto.json
out=$("$C3PO" indicators mug.json --auto --views 10 --test-views 6 --points 400 2>/dev/null) || fail "auto exit $?"
grep -q "precision" <<< "$out" || fail "auto output: $out"
cmp -s mug.json before_auto.json || fail "--auto without --write changed the file"
"$C3PO" indicators mug.json --auto --views 10 --test-views 6 --points 400 --write -o auto.json > /dev/null 2>&1 || fail "auto --write"
grep -q '"indicator_sets_auto"' auto.json || fail "no evidence in auto.json"
grep -q '"precision"' auto.json || fail "no precision in auto.json"
"$C3PO" indicators auto.json > /dev/null || fail "auto.json does not read back"
echo "ok"
