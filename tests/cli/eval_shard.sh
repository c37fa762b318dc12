#!/usr/bin/env bash
# ctest-labels: heavy
# eval --shard K/N + c3po merge --eval (issue 15): the parts' per-sample rows
# (--samples), run by GNU parallel and merged, give the unsharded eval table
# byte for byte and its --json document up to the timings "ms"; on --data (a
# synthetic depth dataset, several detectors) and, when present, on the real
# YCB-Video frames with --bop (sharded by image). Merging parts out of order,
# a missing part, parts of another run or samples given to plain merge exit 2.
# Skips (77) without GNU parallel.
# Usage: eval_shard.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
command -v parallel >/dev/null || { echo "skipped: GNU parallel is not installed"; exit 77; }
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
OBJ="$SRC/annotations/mug.json"
fail() { echo "FAIL: $*"; exit 1; }

"$C3PO" synth "$OBJ" -o data --kind depth --count 10 --points 300 --seed 5 --perturb-sigma 0.3 >/dev/null 2>&1 \
  || fail "synth failed"
ARGS=(--data data --detector manifest --detector svd --eps-oc 3%d --worst 2)
"$C3PO" eval "$OBJ" "${ARGS[@]}" --json full.json --samples full.samples.jsonl > full.txt 2>/dev/null || fail "unsharded eval failed"
parallel --halt now,fail=1 "'$C3PO' eval '$OBJ' ${ARGS[*]} --shard {}/3 --samples s{}.jsonl > part{}.txt 2>/dev/null" ::: 1 2 3 \
  || fail "a sharded eval failed"
"$C3PO" merge --eval s1.jsonl s2.jsonl s3.jsonl -o merged.json > merged.txt || fail "merge --eval failed"
cmp full.txt merged.txt || { diff full.txt merged.txt; fail "merged table differs from the unsharded one"; }
"$C3PO" merge --eval full.samples.jsonl > single.txt || fail "merge --eval of a 1/1 part failed"
cmp full.txt single.txt || fail "a 1/1 samples file does not reproduce its table"
grep -q "(10 clouds)" merged.txt || fail "merged table does not count 10 clouds"
grep -q "(3 clouds)\|(4 clouds)" part1.txt || fail "part 1 is not a third of the clouds"
python3 - <<'PY' || fail "merged JSON differs from the unsharded --json"
import json
def load(path):
    d = json.load(open(path))
    for row in d['rows']:
        for s in row.get('samples', []):
            s.pop('ms')
    return d
full, merged = load('full.json'), load('merged.json')
assert full == merged
assert [s['index'] for s in merged['rows'][0]['samples']] == list(range(10))
# The parts are disjoint and cover the dataset in order.
clouds = []
for k in (1, 2, 3):
    lines = [json.loads(l) for l in open('s%d.jsonl' % k)]
    assert lines[0]['shard'] == '%d/3' % k
    clouds += [l['cloud'] for l in lines[1:] if l['row'] == 0]
assert clouds == [s['cloud'] for s in full['rows'][0]['samples']], clouds
PY

# Refusals: exit 2, one line naming the file, nothing written.
expect2() {
  local name=$1; shift
  set +e; "$@" > "$name.out" 2> "$name.err"; local status=$?; set -e
  [ $status -eq 2 ] || { cat "$name.err"; fail "$name: exit $status, not 2"; }
  [ "$(wc -l < "$name.err")" -eq 1 ] || { cat "$name.err"; fail "$name: not one line"; }
  [ ! -e "$name.json" ] || fail "$name: wrote output"
}
expect2 order "$C3PO" merge --eval s2.jsonl s1.jsonl s3.jsonl -o order.json
grep -q "s2.jsonl: shard 2/3 given as part 1" order.err || fail "order: $(cat order.err)"
expect2 missing "$C3PO" merge --eval s1.jsonl s2.jsonl -o missing.json
"$C3PO" eval "$OBJ" "${ARGS[@]}" --adds-threshold 4%d --shard 3/3 --samples other3.jsonl > /dev/null 2>&1 || true
expect2 other "$C3PO" merge --eval s1.jsonl s2.jsonl other3.jsonl -o other.json
grep -q "other3.jsonl: object, dataset or settings differ" other.err || fail "other: $(cat other.err)"
expect2 plain "$C3PO" merge -o plain.json s1.jsonl s2.jsonl s3.jsonl
grep -q "s1.jsonl: eval samples" plain.err || fail "plain: $(cat plain.err)"
expect2 empty_part "$C3PO" eval "$OBJ" "${ARGS[@]}" --shard 1/20 --samples empty_part.json
expect2 bad_shard "$C3PO" eval "$OBJ" "${ARGS[@]}" --shard 0/3 --samples bad_shard.json

# The real frames, sharded by image (skipped when absent).
DATA="$SRC/../shared/data/real/ycbv-bop"
if [ -d "$DATA/test" ]; then
  "$C3PO" annotate "$DATA/models/obj_000005.ply" --units mm --auto 12 --seed 1 -o obj5.json >/dev/null
  BOP=(--bop "$DATA/test" --obj-id 5 --detector svd --eps-oc 3%d --no-ransac)
  "$C3PO" eval obj5.json "${BOP[@]}" --samples bop_full.jsonl > bop_full.txt 2>/dev/null || fail "unsharded eval --bop failed"
  parallel --halt now,fail=1 "'$C3PO' eval obj5.json ${BOP[*]} --shard {}/3 --samples b{}.jsonl > /dev/null 2>&1" ::: 1 2 3 \
    || fail "a sharded eval --bop failed"
  "$C3PO" merge --eval b1.jsonl b2.jsonl b3.jsonl > bop_merged.txt || fail "merge --eval (bop) failed"
  cmp bop_full.txt bop_merged.txt || { diff bop_full.txt bop_merged.txt; fail "merged BOP table differs"; }
  grep -qF "on $DATA/test (40 clouds)" bop_merged.txt || { head -1 bop_merged.txt; fail "BOP table does not name the BOP folder"; }
  echo "eval_shard: BOP frames: sharded == unsharded"
else
  echo "note: $DATA absent, BOP part skipped"
fi
echo "eval_shard: ok"
