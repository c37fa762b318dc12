#!/usr/bin/env bash
# ctest-labels: heavy
# c3po certify --poses: the poses c3po itself wrote (certify -o JSON lines)
# certified again as given poses with --no-correct give the same verdicts;
# a wrong extra hypothesis per cloud is rejected and never chosen; the
# correction's change is reported; unmatched lines are reported (exit 2).
# Usage: certify_poses.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
OBJ="$SRC/annotations/drill.json"
fail() { echo "FAIL: $*"; exit 1; }

"$C3PO" synth "$OBJ" -o depth --kind depth --count 6 --pose easy --noise 0.0005 --seed 5 >/dev/null
set +e
"$C3PO" certify "$OBJ" --detector svd --data depth -o first.jsonl > first.txt 2>&1
set -e
[ "$(wc -l < first.jsonl)" -eq 6 ] || fail "expected 6 lines from the svd run"

# The certify output is itself a valid poses file (cloud, R, t).
set +e
"$C3PO" certify "$OBJ" --data depth --poses first.jsonl --no-correct --json > again.jsonl 2> again.err
status=$?
set -e
[ $status -le 1 ] || fail "re-certifying c3po's own poses: exit $status ($(cat again.err))"
python3 - first.jsonl again.jsonl <<'PY' || fail "verdicts differ"
import json, sys
first = [json.loads(l) for l in open(sys.argv[1])]
again = [json.loads(l) for l in open(sys.argv[2])]
assert len(first) == len(again), (len(first), len(again))
for a, b in zip(first, again):
    assert b["cloud"].startswith(a["cloud"] + " (line "), (a["cloud"], b["cloud"])
    assert a["certified"] == b["certified"], (a["cloud"], a["certified"], b["certified"])
    assert b["rotation_change_deg"] < 1e-4 and b["translation_change"] < 1e-12, b
    assert b["chosen"] == b["certified"], b
PY

# A wrong second hypothesis per cloud (rotated by 90 degrees about z, higher score).
python3 - first.jsonl > two.jsonl <<'PY'
import json, sys
for line in open(sys.argv[1]):
    a = json.loads(line)
    R = a["R"]
    wrong = [[-R[0][1], R[0][0], R[0][2]], [-R[1][1], R[1][0], R[1][2]], [-R[2][1], R[2][0], R[2][2]]]
    print(json.dumps({"cloud": a["cloud"], "R": wrong, "t": a["t"], "score": 1.0}))
    print(json.dumps({"cloud": a["cloud"], "R": R, "t": a["t"], "score": 0.5}))
PY
set +e
"$C3PO" certify "$OBJ" --data depth --poses two.jsonl --no-correct --json > two_out.jsonl 2> two.err
set -e
python3 - first.jsonl two_out.jsonl <<'PY' || fail "multiple hypotheses"
import json, sys
first = {json.loads(l)["cloud"]: json.loads(l)["certified"] for l in open(sys.argv[1])}
out = [json.loads(l) for l in open(sys.argv[2])]
assert len(out) == 12, len(out)
for o in out:
    wrong = o["pose_line"] % 2 == 1
    if wrong:
        assert not o["certified"] and not o["chosen"], o["cloud"]
chosen = [o for o in out if o["chosen"]]
assert len(chosen) == sum(first.values()), (len(chosen), first)
for o in chosen:
    assert o["pose_line"] % 2 == 0
PY

# Default mode: the given pose starts the corrector; the change is reported.
"$C3PO" certify "$OBJ" --data depth --poses two.jsonl > corrected.txt 2>&1 || true
grep -q "change .* deg" corrected.txt || fail "the correction's change is not reported"
grep -q "instances with a certified pose" corrected.txt || fail "no instance summary"

# Unmatched lines are reported, not dropped: exit 2, the file and line named.
printf '{"cloud": "nowhere.ply", "R": [[1,0,0],[0,1,0],[0,0,1]], "t": [0,0,0.5]}\n' >> two.jsonl
set +e; "$C3PO" certify "$OBJ" --data depth --poses two.jsonl > unmatched.txt 2> unmatched.err; status=$?; set -e
[ $status -eq 2 ] || fail "unmatched line: expected exit 2, got $status"
grep -q "two.jsonl: line 13: no cloud named 'nowhere.ply'" unmatched.err || fail "unmatched line not named: $(cat unmatched.err)"

# --poses with a detector is refused.
set +e; "$C3PO" certify "$OBJ" --data depth --poses first.jsonl --detector svd > both.txt 2>&1; status=$?; set -e
[ $status -eq 2 ] || fail "--poses with --detector: expected exit 2, got $status"
echo "certify_poses: ok"
