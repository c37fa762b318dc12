#!/usr/bin/env bash
# ctest-labels: heavy
# c3po certify --poses on BOP sources: the BOP CSV that `certify --bop
# --bop-csv` wrote, certified again with --no-correct, gives every instance
# the verdict of the first run, on a synth --format bop scene set with two
# instances of the object per image (a CSV row has no gt_id: it is tried on
# both, and each instance keeps its best certified row). Rows of another
# obj_id are skipped with a note; rows of an image that is not there are
# unmatched (exit 2). Each line carries its instance's ids, segment counts and
# ground truth (gt_hausdorff of the certified pose) as certify --bop lines do;
# --bop-csv writes each instance's chosen hypothesis, the first run's rows again.
# Usage: certify_poses_bop.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
OBJ="$SRC/annotations/drill.json"
fail() { echo "FAIL: $*"; exit 1; }

# 6 images, each with the drill (obj 5) and a second drill (the default distractor).
"$C3PO" synth "$OBJ" -o bop --format bop --count 6 --obj-id 5 --distractors 1 --seed 4 >/dev/null
set +e
"$C3PO" certify "$OBJ" --bop bop --obj-id 5 --detector svd --bop-csv first.csv --json > first.jsonl 2> first.err
status=$?
set -e
[ $status -le 1 ] || fail "first run: exit $status ($(cat first.err))"
[ "$(wc -l < first.jsonl)" -eq 12 ] || fail "expected 12 instances, got $(wc -l < first.jsonl)"

set +e
"$C3PO" certify "$OBJ" --bop bop --obj-id 5 --poses first.csv --no-correct --json > again.jsonl 2> again.err
status=$?
set -e
[ $status -le 1 ] || fail "re-certifying the BOP CSV: exit $status ($(cat again.err))"
python3 - first.jsonl first.csv again.jsonl <<'PY' || fail "verdicts differ"
import csv, json, sys
first = [json.loads(l) for l in open(sys.argv[1])]
rows = list(csv.DictReader(open(sys.argv[2])))
again = [json.loads(l) for l in open(sys.argv[3])]
# Every row is a hypothesis for each instance of obj 5 in its image (2 here).
per_image = {}
for a in first:
    per_image.setdefault((a["scene_id"], a["im_id"]), []).append(a["cloud"])
assert all(len(v) == 2 for v in per_image.values()), per_image
expected = sum(len(per_image[(int(r["scene_id"]), int(r["im_id"]))]) for r in rows)
assert len(again) == expected, (len(again), expected)
certified_first = {a["cloud"]: a["certified"] for a in first}
assert any(certified_first.values()), "nothing certified in the first run: the test shows nothing"
chosen = {}
for b in again:
    instance = b["cloud"].split(" (line ")[0]
    assert instance in certified_first, b["cloud"]
    assert b["rotation_change_deg"] < 1e-4 and b["translation_change"] < 1e-9, b
    if b["chosen"]:
        assert b["certified"], b
        assert instance not in chosen, ("two chosen", instance)
        chosen[instance] = b
for name, certified in certified_first.items():
    assert (name in chosen) == certified, (name, certified)
# The chosen row is the instance's own pose of the first run (as printed in the CSV).
for a in first:
    if not a["certified"]:
        continue
    b = chosen[a["cloud"]]
    dr = max(abs(x - y) for ra, rb in zip(a["R"], b["R"]) for x, y in zip(ra, rb))
    dt = max(abs(x - y) for x, y in zip(a["t"], b["t"]))
    assert dr < 1e-7 and dt < 1e-6, (a["cloud"], dr, dt)
    # The lines carry the BOP instance's keys and ground truth as certify --bop writes them.
    for key in ("scene_id", "im_id", "gt_id", "obj_id", "points", "gt_t"):
        assert b[key] == a[key], (key, b[key], a[key])
    assert abs(b["gt_hausdorff"] - a["gt_hausdorff"]) < 1e-5, (b["gt_hausdorff"], a["gt_hausdorff"])
print("instances", len(first), "certified", sum(certified_first.values()), "hypotheses", len(again))
PY

# Another object's rows are skipped with a note; an absent image's row is unmatched (exit 2).
head -2 first.csv | tail -1 | awk -F, 'BEGIN{OFS=","} {$3=9; print}' > other.csv
{ head -1 first.csv; tail -n +2 first.csv; cat other.csv; } > with_other.csv
set +e
"$C3PO" certify "$OBJ" --bop bop --obj-id 5 --poses with_other.csv --no-correct > other.txt 2> other.err
status=$?
set -e
[ $status -le 1 ] || fail "a row of another obj_id: exit $status ($(cat other.err))"
grep -q "1 line(s) for other obj_ids skipped" other.err || fail "other obj_id not reported: $(cat other.err)"
grep -q "instances with a certified pose" other.txt || fail "no instance summary"
head -2 first.csv | tail -1 | awk -F, 'BEGIN{OFS=","} {$2=999; print}' >> with_other.csv
set +e
"$C3PO" certify "$OBJ" --bop bop --obj-id 5 --poses with_other.csv --no-correct > absent.txt 2> absent.err
status=$?
set -e
[ $status -eq 2 ] || fail "a row of an absent image: expected exit 2, got $status"
grep -q "no BOP instance of obj_id 5 in scene/image '0/999' (unmatched)" absent.err || fail "unmatched row not named: $(cat absent.err)"

# With --shard, the rows of the other shard's images are skipped (counted), not unmatched;
# the two shards together give the verdicts of the whole run.
for k in 1 2; do
  set +e
  "$C3PO" certify "$OBJ" --bop bop --obj-id 5 --poses first.csv --no-correct --shard $k/2 --json > shard$k.jsonl 2> shard$k.err
  status=$?
  set -e
  [ $status -le 1 ] || fail "shard $k/2: exit $status ($(cat shard$k.err))"
  grep -q "line(s) for other shards skipped" shard$k.err || fail "shard $k/2: other shards not reported: $(cat shard$k.err)"
done
python3 - again.jsonl shard1.jsonl shard2.jsonl <<'PY2' || fail "shards differ from the whole run"
import json, sys
whole = sorted((json.loads(l)["cloud"], json.loads(l)["chosen"]) for l in open(sys.argv[1]))
parts = sorted((json.loads(l)["cloud"], json.loads(l)["chosen"]) for f in sys.argv[2:] for l in open(f))
assert whole == parts, (whole, parts)
PY2

# --bop-csv with --poses: one row per instance, its chosen hypothesis (else its
# best fit), scored by its certificate; re-certifying the first run's CSV as it
# is gives back the first run's rows (the two instances of an image cannot be
# told apart by a row's ids: compared per image as sorted lists).
set +e
"$C3PO" certify "$OBJ" --bop bop --obj-id 5 --poses first.csv --no-correct --bop-csv again.csv > /dev/null 2> again_csv.err
status=$?
set -e
[ $status -le 1 ] || fail "--poses with --bop-csv: exit $status ($(cat again_csv.err))"
python3 - first.csv again.csv <<'PY3' || fail "--bop-csv of --poses differs from the first run's rows"
import csv, sys
def rows(path):
    per_image = {}
    for r in csv.DictReader(open(path)):
        key = (int(r["scene_id"]), int(r["im_id"]), int(r["obj_id"]))
        pose = [float(x) for x in r["R"].split()] + [float(x) for x in r["t"].split()]
        per_image.setdefault(key, []).append((float(r["score"]), pose))
    return {k: sorted(v) for k, v in per_image.items()}
first, again = rows(sys.argv[1]), rows(sys.argv[2])
assert first.keys() == again.keys(), (first.keys(), again.keys())
certified = 0
for key in first:
    assert len(first[key]) == len(again[key]), key
    for (s1, p1), (s2, p2) in zip(first[key], again[key]):
        assert abs(s1 - s2) < 1e-5 and (s1 > 1) == (s2 > 1), (key, s1, s2)   # the CSV prints 9 digits
        assert max(abs(a - b) for a, b in zip(p1, p2)) < 1e-6, key
        certified += s1 > 1
assert certified > 0, "no certified row: the test shows nothing"
PY3
echo "certify_poses_bop: ok"
