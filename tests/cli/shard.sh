#!/usr/bin/env bash
# --shard K/N with GNU parallel (issue 15), no shared data needed: synth parts
# merged with `c3po merge` are byte-identical to the unsharded dataset;
# certify --data parts merged equal the unsharded JSON lines (up to "ms");
# bad shard specs exit 2. Skips (77) without GNU parallel.
# Usage: shard.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
command -v parallel >/dev/null || { echo "skipped: GNU parallel is not installed"; exit 77; }
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
OBJ="$SRC/annotations/mug.json"
fail() { echo "FAIL: $*"; exit 1; }

"$C3PO" synth "$OBJ" -o full --kind depth --count 9 --points 300 --seed 5 >/dev/null
parallel --halt now,fail=1 "'$C3PO' synth '$OBJ' -o part{} --kind depth --count 9 --points 300 --seed 5 --shard {}/4 >/dev/null" ::: 1 2 3 4
"$C3PO" merge -o merged part1 part2 part3 part4 >/dev/null
diff -r full merged >/dev/null || fail "merged synth parts differ from the unsharded dataset"

set +e
"$C3PO" certify "$OBJ" --detector svd --data full -o full.jsonl --eps-oc 3%d >/dev/null 2>&1
[ $? -le 1 ] || fail "unsharded certify failed"
parallel "'$C3PO' certify '$OBJ' --detector svd --data full --eps-oc 3%d --shard {}/3 -o c{}.jsonl >/dev/null 2>&1; [ \$? -le 1 ]" ::: 1 2 3
[ $? -eq 0 ] || fail "a certify part failed"
"$C3PO" certify "$OBJ" --detector svd --data full --shard 4/3 > bad.txt 2>&1
[ $? -eq 2 ] || fail "--shard 4/3 did not exit 2"
"$C3PO" certify "$OBJ" --detector svd --data full --shard 1/2 --eps-oc auto > auto.txt 2>&1
[ $? -eq 2 ] || fail "--shard with --eps-oc auto did not exit 2"
set -e
"$C3PO" merge -o merged.jsonl c1.jsonl c2.jsonl c3.jsonl
python3 - <<'PY' || fail "merged certify parts differ from the unsharded run"
import json
def lines(path):
    out = [json.loads(l) for l in open(path)]
    for d in out:
        d.pop('ms', None)
        d.pop('ms_stages', None)
    return out
assert len(lines('full.jsonl')) == 9
assert lines('merged.jsonl') == lines('full.jsonl')
PY
echo "shard: ok"
