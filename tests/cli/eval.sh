#!/usr/bin/env bash
# ctest-labels: heavy
# c3po eval end to end on a small synthetic depth dataset whose manifest holds
# perturbed keypoints (--detector manifest): table, JSON (summaries agree with
# the per-sample results recomputed here), ADD-S variants, thresholds, the
# HTML report (atomic, self-contained, training curves) and bad inputs (exit 2).
# Usage: eval.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
OBJECT="$SRC/annotations/mug.json"
fail() { echo "FAIL: $*"; exit 1; }
source "$(dirname "$0")/lib.sh"

"$C3PO" synth "$OBJECT" -o data --kind depth --count 10 --points 400 --seed 5 --perturb-sigma 0.3 >/dev/null 2>&1 \
  || fail "c3po synth could not make the dataset"

# ---- the table, JSON and report ----
cat > train.log.jsonl <<'LOG'
{"epoch": 1, "train_loss": 0.5, "val_loss": 0.6, "oc_val": 0.1}
{"epoch": 2, "train_loss": 0.2, "val_loss": 0.3, "oc_val": 0.5}
{"epoch": 3, "train_loss": 0.1, "val_loss": 0.2, "oc_val": 0.9}
LOG
"$C3PO" eval "$OBJECT" --data data --detector manifest --json out.json --report report.html \
  --training-log train.log.jsonl > table.txt 2> err.txt || { cat table.txt err.txt; fail "eval exited with $?"; }
for text in "KeyPo (manifest)  " "KeyPo (manifest) + ICP" "KeyPo (manifest) + RANSAC + ICP" "KeyPo (manifest) + corrector" \
            "ADD-S variant: symmetric" "Soundness:" "eps_oc ="; do
  grep -qF "$text" table.txt || { cat table.txt; fail "table lacks '$text'"; }
done
grep -q "wrote report.html (.* 3D examples, 1 training logs)" err.txt || { cat err.txt; fail "no report line"; }
[ -s out.json ] || fail "out.json not written"
head -c 15 report.html | grep -qi "<!doctype html>" || fail "report.html is not HTML"
grep -q "<table id=\"results\">" report.html || fail "report has no results table"
grep -q "train: loss per epoch" report.html || fail "report has no training curve"
tail -c 20 report.html | grep -q "</html>" || fail "report.html is truncated"
ls -a | grep -q '\.tmp' && fail "temporary files left behind: $(ls -a)"

if command -v python3 >/dev/null; then
python3 - "$WORK/out.json" <<'PY' || fail "JSON check"
import json, math, sys
e = json.load(open(sys.argv[1]))
assert e["adds_variant"] == "symmetric", e["adds_variant"]
assert abs(e["adds_threshold"] - 0.05 * e["diameter"]) < 1e-12
assert abs(e["auc_max"] - 0.10 * e["diameter"]) < 1e-12
assert [r["label"] for r in e["rows"]] == ["KeyPo (manifest)", "KeyPo (manifest) + ICP", "KeyPo (manifest) + RANSAC + ICP", "KeyPo (manifest) + corrector"]
for r in e["rows"]:
    s, samples = r["summary"], r["samples"]
    assert s["n"] == len(samples) == e["clouds"] == 10
    adds = [x["adds"] if x["adds"] is not None else math.inf for x in samples]
    score = 100.0 * sum(a < e["adds_threshold"] for a in adds) / len(adds)
    assert abs(s["adds_score"] - score) < 1e-9, (r["label"], s["adds_score"], score)
    m = e["auc_max"]
    auc = 100.0 * sum(max(0.0, m - a) for a in adds) / (m * len(adds))
    assert abs(s["adds_auc"] - auc) < 1e-9, (s["adds_auc"], auc)
    cert = sum(x["certified"] for x in samples)
    assert s["certified"] == cert and abs(s["percent_certified"] - 100.0 * cert / len(samples)) < 1e-9
    false = sum(x["certified"] and not (a < e["adds_threshold"]) for x, a in zip(samples, adds))
    assert s["false_certificates"] == false
    assert all(x["certified"] == (x["oc"] and x["nd"]) for x in samples)
print("ok: JSON summaries agree with the per-sample results")
PY
  # One-sided ADD-S is the first term of the symmetric sum: never larger.
  "$C3PO" eval "$OBJECT" --data data --detector manifest --no-icp --adds one-sided --json one.json > one.txt 2>&1 \
    || fail "eval --adds one-sided"
  grep -q "ADD-S variant: one-sided" one.txt || fail "variant not named in the table"
  python3 - out.json one.json <<'PY' || fail "one-sided vs symmetric"
import json, sys
sym, one = (json.load(open(p)) for p in sys.argv[1:3])
assert one["adds_variant"] == "one-sided"
a = {r["label"]: r for r in sym["rows"]}
for r in one["rows"]:
    for x, y in zip(r["samples"], a[r["label"]]["samples"]):
        assert x["cloud"] == y["cloud"]
        if x["adds"] is not None:
            assert x["adds"] <= y["adds"] + 1e-12 and x["adds"] > 0.3 * y["adds"], (x["adds"], y["adds"])
print("ok: one-sided ADD-S <= symmetric ADD-S for every sample")
PY
else
  echo "note: python3 not found, JSON cross-checks skipped"
fi

# Absolute thresholds are reported as given.
"$C3PO" eval "$OBJECT" --data data --detector manifest --no-icp --adds-threshold 2cm --auc-max 5cm \
  --eps-oc 1cm --delta-nd 8mm --json - > stdout.json 2> table2.txt || fail "eval with absolute thresholds"
grep -q "ADD-S < 0.02 " table2.txt || { cat table2.txt; fail "absolute ADD-S threshold not stated"; }
grep -q "eps_oc = 0.01 " table2.txt || fail "eps_oc not stated"
grep -q "delta_nd = 0.008 " table2.txt || fail "delta_nd not stated"
grep -q '"adds_threshold": 0.02' stdout.json || fail "--json - did not print the JSON on stdout"

# A corrupt cloud is a per-sample failure, reported, not a crash.
mkdir -p corrupt && cp data/* corrupt/
head -c 200 data/000003.ply > corrupt/000003.ply
"$C3PO" eval "$OBJECT" --data corrupt --detector manifest --no-icp > corrupt.txt 2>&1 || { cat corrupt.txt; fail "eval on a corrupt cloud"; }
grep -q "Failures: KeyPo (manifest): 1 of 10 samples without a pose.*000003.ply" corrupt.txt \
  || { cat corrupt.txt; fail "corrupt cloud not reported"; }

# ---- bad inputs: exit 2, one line naming the problem, outputs untouched ----
cp report.html report.before
expect_error() {   # expect_error PATTERN ARGS...
  local pattern=$1; shift
  expect_bad_input - "$pattern" "$C3PO" eval "$@"
}
expect_error "data" "$OBJECT" --detector manifest --report report.html
expect_error "at least one" "$OBJECT" --data data --report report.html
expect_error "one-sided or symmetric" "$OBJECT" --data data --detector manifest --adds both --report report.html
expect_error "adds-threshold" "$OBJECT" --data data --detector manifest --adds-threshold -1 --report report.html
expect_error "nosuch" "$OBJECT" --data data --detector nosuch --report report.html
mkdir -p nogt && cp data/*.ply nogt/
sed 's/"R":\[\[[^]]*\],\[[^]]*\],\[[^]]*\]\],//; s/"t":\[[^]]*\],//' data/manifest.jsonl > nogt/manifest.jsonl
expect_error "manifest.jsonl: line 1.*ground-truth" "$OBJECT" --data nogt --detector manifest --report report.html
expect_error "missing.jsonl" "$OBJECT" --data data --detector manifest --training-log missing.jsonl --report report.html
cmp -s report.html report.before || fail "a failed run changed report.html"
echo "ok: c3po eval table, JSON, report and errors"
