#!/usr/bin/env bash
# ctest-labels: heavy
# The options certify, eval, selftrain and bench corrector share (cli/options.*)
# are declared once: the same flags in every --help, help text free of code,
# repeatable --detector/--model/--plugin taking one value each (so the object
# may follow them), selftrain accepting --loss, and the same one-line errors
# for bad threshold, solver and loss values in every command.
# Usage: shared_options.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -u
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
OBJ="$SRC/tests/fixtures/objects/cube.json"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
pointnet=1; [ "${C3PO_WITH_POINTNET:-ON}" == OFF ] && pointnet=0

commands=("certify" "eval" "bench corrector")
[ $pointnet -eq 1 ] && commands+=("selftrain")
for c in "${commands[@]}"; do
  # shellcheck disable=SC2086
  "$C3PO" $c --help > "help.txt" 2>&1 || fail "$c --help exited $?"
  for flag in --eps-oc --delta-nd --loss --max-outliers --robust-loss --nd-min-eigenvalue --no-global-check \
      --global-steps --no-free-space --free-space-fraction --free-space-accept --outside-mask-fraction \
      --uncovered-mask-fraction --rival-distance --tolerance --indicator-sets --no-centre; do
    grep -q -- "$flag" help.txt || fail "$c --help lacks $flag"
  done
  grep -q "allow_extra_args\|->" help.txt && fail "$c --help shows code: $(grep 'allow_extra_args\|->' help.txt)"
done
for c in certify eval selftrain; do
  [ $c == selftrain ] && [ $pointnet -eq 0 ] && continue
  "$C3PO" $c --help | grep -q -- "--solver" || fail "$c --help lacks --solver"
done
# The HTML reports (cli/options.* AddReportOptions): the same flags and the same error.
for c in certify eval; do
  "$C3PO" $c --help > help.txt 2>&1
  grep -q -- "--report" help.txt && grep -q -- "--views" help.txt || fail "$c --help lacks --report/--views"
  "$C3PO" $c "$OBJ" --detector svd --data nowhere --report r.html --views -2 > /dev/null 2> views.err
  status=$?
  [ $status -eq 2 ] && grep -q "views must be >= 0" views.err || fail "$c --views -2: exit $status, $(cat views.err)"
done
"$C3PO" certify --help | grep -q "auto" || fail "certify --eps-oc does not offer auto"
"$C3PO" eval --help | grep -- "--eps-oc" | grep -q "auto" && fail "eval --eps-oc offers auto, which eval does not do"

"$C3PO" synth "$OBJ" -o data --kind depth --count 4 --points 300 --seed 1 --perturb-sigma 0.1 >/dev/null 2>&1 \
  || { echo "synth failed"; exit 1; }

# --detector / --plugin take one value: the object may come after them (it was
# swallowed into the detector list when the option took extra arguments).
"$C3PO" eval --detector manifest "$OBJ" --data data --no-icp > eval.out 2>&1 \
  || fail "eval --detector manifest OBJECT: exited $?: $(tail -2 eval.out)"
grep -q "KeyPo (manifest) + corrector" eval.out || fail "eval table lacks the manifest rows"
"$C3PO" eval --detector manifest --detector svd "$OBJ" --data data --no-icp > eval2.out 2>&1 \
  || fail "eval with two --detector and the object last: exited $?: $(tail -2 eval2.out)"
grep -q "KeyPo (svd) + corrector" eval2.out || fail "eval table lacks the svd rows"
"$C3PO" certify --detector manifest "$OBJ" --data data --json > certify.out 2>&1; status=$?
[ $status -le 1 ] || fail "certify --detector manifest OBJECT: exited $status: $(tail -2 certify.out)"
"$C3PO" certify "$OBJ" --detector svd --detector manifest --data data > two.out 2>&1
[ $? -eq 2 ] && grep -q "exactly one of --model" two.out || fail "certify with two detectors: $(cat two.out)"

# bad_value NAME CMD...: exit 2 and one stderr line naming the option.
bad_value() {
  local option=$1; shift
  "$@" > bad.out 2> bad.err; local status=$?
  [ $status -eq 2 ] || fail "$* exited $status, expected 2"
  [ "$(wc -l < bad.err)" -eq 1 ] && grep -q -- "$option" bad.err || fail "$*: stderr: $(cat bad.err)"
}
for c in certify eval; do
  det=(--detector manifest)
  bad_value --eps-oc "$C3PO" $c "$OBJ" "${det[@]}" --data data --eps-oc nonsense
  bad_value --delta-nd "$C3PO" $c "$OBJ" "${det[@]}" --data data --delta-nd 0
  bad_value --solver "$C3PO" $c "$OBJ" "${det[@]}" --data data --solver slow
  bad_value --loss "$C3PO" $c "$OBJ" "${det[@]}" --data data --loss median
  bad_value --max-outliers "$C3PO" $c "$OBJ" "${det[@]}" --data data --max-outliers 3x
  bad_value --robust-loss "$C3PO" $c "$OBJ" "${det[@]}" --data data --robust-loss huber
  bad_value --nd-min-eigenvalue "$C3PO" $c "$OBJ" "${det[@]}" --data data --nd-min-eigenvalue -1
  bad_value --reestimate-steps "$C3PO" $c "$OBJ" "${det[@]}" --data data --reestimate --reestimate-steps 5
  bad_value --rival-distance "$C3PO" $c "$OBJ" "${det[@]}" --data data --rival-distance 0
  bad_value --rival-distance "$C3PO" $c "$OBJ" "${det[@]}" --data data --rival-distance 3x
  bad_value --indicator-sets "$C3PO" $c "$OBJ" "${det[@]}" --data data --indicator-sets maybe
done
bad_value --max-outliers "$C3PO" bench corrector "$OBJ" --data data --max-outliers -2
bad_value --eps-oc "$C3PO" eval "$OBJ" --detector manifest --data data --eps-oc auto
bad_value --loss "$C3PO" bench corrector "$OBJ" --data data --loss median
if [ $pointnet -eq 1 ]; then
  "$C3PO" train "$OBJ" --data data -o cube.model --epochs 1 --point-mlp 8 8 --head 8 --points 32 --seed 1 >/dev/null 2>&1 \
    || fail "train failed"
  bad_value --loss "$C3PO" selftrain "$OBJ" --model cube.model --data data -o self.model --loss median
  [ ! -e self.model ] || fail "selftrain wrote a model after a bad --loss"
  bad_value --robust-loss "$C3PO" selftrain "$OBJ" --model cube.model --data data -o self.model --robust-loss huber
  [ ! -e self.model ] || fail "selftrain wrote a model after a bad --robust-loss"
fi

# One input, one set of defaults (options.hpp InputKind): depth frames
# certified with their frame (certify, eval and selftrain with --bop) of an
# object get m = 2%, the TLS kernel and the indicator sets off (an object with
# sets is judged as one without), m = 0 and the sets on when the free-space
# test is off or --indicator-sets on is given; segments certified without
# their frame (selftrain with --data as well) get TLS and m = 0; ready-made
# clouds keep the paper (m = 0, no kernel); a flag wins. eval --bop certifies
# what certify --bop certifies (the frame's free space included).
python3 - "$SRC/tests/fixtures/objects" <<'EOF' || fail "could not write cube_nosets.json"
import json, os, sys
spec = json.load(open(os.path.join(sys.argv[1], "cube.json")))
spec["mesh"] = os.path.join(sys.argv[1], spec["mesh"])
spec["indicator_sets"] = []
json.dump(spec, open("cube_nosets.json", "w"))
EOF
"$C3PO" synth "$OBJ" -o bop --format bop --count 2 --obj-id 3 --seed 2 --depth-scale 1 >/dev/null 2>&1 || fail "synth --format bop failed"
NOSETS="$WORK/cube_nosets.json"
summary() {   # the certify summary's budget and kernel
  grep -o "m = [^,]*, robust loss = [a-z]*" "$1" | head -1
}
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd -o c.jsonl > c.out 2>&1 || true
[ "$(summary c.out)" == "m = 2%, robust loss = tls" ] || fail "certify --bop defaults: '$(summary c.out)'"
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --robust-loss none --max-outliers 5 -o c.jsonl > c.out 2>&1 || true
[ "$(summary c.out)" == "m = 5, robust loss = none" ] || fail "certify --bop with flags: '$(summary c.out)'"
"$C3PO" certify "$OBJ" --bop bop --obj-id 3 --detector svd -o c.jsonl > c.out 2>&1 || true
[ "$(summary c.out)" == "m = 2%, robust loss = tls" ] || fail "certify --bop, object with sets: '$(summary c.out)'"
grep -q "indicator sets off" c.out || fail "certify --bop, object with sets: summary does not say the sets are off"
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd -o c_nosets.jsonl > /dev/null 2>&1 || true
"$C3PO" certify "$OBJ" --bop bop --obj-id 3 --detector svd --indicator-sets on -o c_on.jsonl > c.out 2>&1 || true
[ "$(summary c.out)" == "m = 0, robust loss = tls" ] || fail "certify --bop --indicator-sets on: '$(summary c.out)'"
"$C3PO" certify "$OBJ" --data data --detector svd -o c_clouds.jsonl > /dev/null 2>&1 || true
python3 - <<'PY' || fail "--indicator-sets: the sets are not off on frames / on for clouds"
import json
def lines(path): return [json.loads(l) for l in open(path)]
off, nosets, on, clouds = lines("c.jsonl"), lines("c_nosets.jsonl"), lines("c_on.jsonl"), lines("c_clouds.jsonl")
assert off and on and clouds and len(off) == len(nosets)
assert all(not l["nd_sets_used"] for l in off + nosets), off
assert all(l["nd_sets_used"] and l["max_outliers"] == 0 for l in on + clouds), on + clouds
# Sets off = the same object without sets: the same decisions and poses.
for a, b in zip(off, nosets):
    assert (a["certified"], a["refused_by"], a["R"], a["t"]) == (b["certified"], b["refused_by"], b["R"], b["t"]), (a, b)
PY
"$C3PO" certify "$OBJ" --bop bop --obj-id 3 --detector svd --indicator-sets off --no-free-space -o c.jsonl > c.out 2>&1 || true
[ "$(summary c.out)" == "m = 0, robust loss = tls" ] || fail "certify --bop --indicator-sets off --no-free-space: '$(summary c.out)'"
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --no-free-space -o c.jsonl > c.out 2>&1 || true
[ "$(summary c.out)" == "m = 0, robust loss = tls" ] || fail "certify --bop --no-free-space: '$(summary c.out)'"
"$C3PO" certify "$NOSETS" --data data --detector svd -o c.jsonl > c.out 2>&1 || true
[ "$(summary c.out)" == "m = 0, robust loss = none" ] || fail "certify --data defaults: '$(summary c.out)'"
# Re-estimation: on for certify's and eval's frames, off for clouds and
# selftrain; a flag wins, and the two flags exclude each other.
grep -q "re-estimation on" c.out && fail "certify --data re-estimates by default: $(grep 're-estimation' c.out)"
"$C3PO" certify "$NOSETS" --data data --detector svd --reestimate -o c.jsonl > c.out 2>&1 || true
grep -q "re-estimation on" c.out || fail "certify --data --reestimate: $(head -3 c.out)"
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd -o c.jsonl > c.out 2>&1 || true
grep -q "re-estimation on" c.out || fail "certify --bop does not re-estimate by default: $(head -3 c.out)"
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --no-reestimate -o c.jsonl > c.out 2>&1 || true
grep -q "re-estimation on" c.out && fail "certify --bop --no-reestimate re-estimates"
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --no-global-check -o c.jsonl > c.out 2>&1 || true
grep -q "global check off, re-estimation on" c.out || fail "certify --bop --no-global-check: $(head -3 c.out)"
bad_value "--reestimate" "$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --reestimate --no-reestimate
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --no-centre -o nc.jsonl > nc.out 2>&1 || true
grep -q "re-estimation on, centring off" nc.out || fail "certify --no-centre: $(head -3 nc.out)"
grep -q "centring" c.out && fail "certify without --no-centre mentions centring: $(head -3 c.out)"
# --rival-distance: a second fit counts as a rival only beyond it (default
# 2*eps_oc). The cube's second frame is refused by nd_global for a rival at
# Hausdorff h from its estimate; given a distance D > h that rival no longer
# counts, and what is certified lies within D + eps_oc of the truth (the
# loosened bound, docs/method.md). The JSON lines carry D, the summary names it.
# (-o writes the JSON lines; stdout keeps the summary.)
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --erode-mask 4 -o rd0.jsonl > rd0.out 2>&1 || true
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --erode-mask 4 --rival-distance 15%d -o rd.jsonl > rd.out 2>&1 || true
grep -q "global rivals [0-9]* beyond 0.2598" rd.out || fail "certify --rival-distance: summary $(grep -o 'global rivals[^,]*' rd.out)"
python3 - "$NOSETS" <<'PY' || fail "--rival-distance does not act on the rival search"
import json, re, sys
eps = json.load(open(sys.argv[1]))["eps_oc"]
d = float(re.search(r"d = ([0-9.e+-]+)\)", open("rd0.out").read()).group(1))
default = [json.loads(l) for l in open("rd0.jsonl")]
given = {l["cloud"]: l for l in map(json.loads, open("rd.jsonl"))}
# The default tolerance max(10 % of d, 3 eps_oc): rho = tolerance - eps_oc, the bound of a certified pose.
rho = max(0.1 * d, 3 * eps) - eps
assert all(abs(l["rival_distance"] - rho) < 1e-5 for l in default if l["nd_global"] is not None), (rho, default)
assert all(abs(l["certified_bound"] - (rho + eps)) < 1e-5 for l in default if l["certified"]), default
assert all(l["certified_bound"] is None for l in default if not l["certified"]), default
rivalled = [l for l in default if l["refused_by"] == ["nd_global"]]
assert rivalled, "no frame refused by nd_global alone: the test lost its case"
for l in rivalled:
    g = given[l["cloud"]]
    D = g["rival_distance"]
    assert D > l["rival_hausdorff"], (D, l["rival_hausdorff"])
    assert "nd_global" not in g["refused_by"], g["refused_by"]
    if g["certified"]:
        assert g["gt_hausdorff"] <= D + eps, (g["gt_hausdorff"], D, eps)
PY
# --tolerance T: the same search as --rival-distance T - eps_oc, every certified
# pose's certified_bound is T and lies within it of the truth; not with
# --rival-distance; at or below eps_oc it is refused.
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --erode-mask 4 --tolerance 18%d -o tol.jsonl > tol.out 2>&1 || true
grep -q "tolerance 0.31" tol.out || fail "certify --tolerance: summary $(grep -o 'global rivals[^;]*' tol.out)"
python3 - "$NOSETS" <<'PY' || fail "--tolerance is not the rival distance + eps_oc, or a certified pose lies beyond it"
import json, re, sys
eps = json.load(open(sys.argv[1]))["eps_oc"]
d = float(re.search(r"d = ([0-9.e+-]+)\)", open("tol.out").read()).group(1))
given = {l["cloud"]: l for l in map(json.loads, open("rd.jsonl"))}
for l in map(json.loads, open("tol.jsonl")):
    assert abs(l["rival_distance"] - (0.18 * d - eps)) < 1e-5, l["rival_distance"]
    if l["certified"]:
        assert abs(l["certified_bound"] - 0.18 * d) < 1e-5
        assert l["gt_hausdorff"] <= 0.18 * d + 1e-5, (l["gt_hausdorff"], d)
PY
bad_value --tolerance "$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --tolerance 2cm --rival-distance 2cm
bad_value --tolerance "$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --tolerance 0.1%d
bad_value --tolerance "$C3PO" eval "$NOSETS" --bop bop --obj-id 3 --detector svd --tolerance 3x
"$C3PO" eval "$NOSETS" --bop bop --obj-id 3 --detector svd --no-icp > e.out 2>&1 || fail "eval --bop exited $?"
grep -q "re-estimation on" e.out || fail "eval --bop does not re-estimate by default: $(grep 'outlier budget' e.out)"
"$C3PO" eval "$NOSETS" --data data --detector svd --no-icp > e.out 2>&1 || fail "eval --data exited $?"
grep -q "re-estimation off" e.out || fail "eval --data re-estimates by default: $(grep 'outlier budget' e.out)"
"$C3PO" eval "$NOSETS" --bop bop --obj-id 3 --detector svd --no-icp > e.out 2>&1 || fail "eval --bop exited $?: $(tail -1 e.out)"
grep -q "outlier budget m = 2%,.*robust kernel tls" e.out || fail "eval --bop defaults: $(grep 'outlier budget' e.out)"
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd -o c.jsonl > c.out 2>&1 || true
"$C3PO" eval "$NOSETS" --bop bop --obj-id 3 --detector svd --no-icp --json e.json > e.out 2>&1 || fail "eval --bop --json exited $?"
python3 - <<'PY' || fail "eval --bop and certify --bop disagree"
import json
certify = [json.loads(line) for line in open('c.jsonl')]
rows = json.load(open('e.json'))['rows']
corrector = [r for r in rows if r['label'].endswith('+ corrector')][0]
assert len(corrector['samples']) == len(certify) > 0, (len(corrector['samples']), len(certify))
# Same segments, same defaults, same frame: the same decisions, instance by instance.
by_name = {c['cloud'].replace('/', '_') + '.ply': c for c in certify}
for s in corrector['samples']:
    c = by_name[s['cloud']]
    assert s['certified'] == c['certified'], (s['cloud'], s['certified'], c['certified'])
    assert s['free_space'] == c['free_space'], (s['cloud'], s['free_space'], c['free_space'])
PY
"$C3PO" eval "$NOSETS" --bop bop --obj-id 3 --detector svd --no-icp --no-free-space > e.out 2>&1 || fail "eval --bop --no-free-space exited $?"
grep -q "outlier budget m = 0,.*robust kernel tls" e.out || fail "eval --bop --no-free-space: $(grep 'outlier budget' e.out)"
"$C3PO" eval "$NOSETS" --data data --detector svd --no-icp > e.out 2>&1 || fail "eval --data exited $?: $(tail -1 e.out)"
grep -q "outlier budget m = 0,.*robust kernel none" e.out || fail "eval --data defaults: $(grep 'outlier budget' e.out)"
# Two free-space limits: the estimate's (--free-space-accept, default 0.015)
# and the rivals' (--free-space-fraction, 0.02); the JSON carries the one
# applied to the estimate; --free-space-fraction alone lowers the estimate's
# to it; an estimate's limit above the rivals' is an error.
limit() { python3 -c "import json,sys; print(sorted({json.loads(l)['free_space_limit'] for l in open(sys.argv[1])}))" "$1"; }
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd -o c.jsonl > c.out 2>&1 || true
[ "$(limit c.jsonl)" == "[0.015]" ] || fail "certify --bop free-space limit: $(limit c.jsonl)"
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --free-space-fraction 0.01 -o c.jsonl > c.out 2>&1 || true
[ "$(limit c.jsonl)" == "[0.01]" ] || fail "--free-space-fraction 0.01 leaves the estimate's limit at $(limit c.jsonl)"
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --free-space-accept 0.018 -o c.jsonl > c.out 2>&1 || true
[ "$(limit c.jsonl)" == "[0.018]" ] || fail "--free-space-accept 0.018: limit $(limit c.jsonl)"
bad_value --free-space-accept "$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --free-space-accept 0.05
bad_value --free-space-accept "$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --free-space-fraction 0.01 \
  --free-space-accept 0.02
bad_value --free-space-accept "$C3PO" eval "$NOSETS" --bop bop --obj-id 3 --detector svd --free-space-accept abc
# The mask tests: mask_option FLAG LIMIT_KEY DEFAULT PART COUNT TOTAL: the
# JSON carries the limit applied and the counts (0 <= COUNT <= TOTAL), PART
# refuses exactly when COUNT > DEFAULT * TOTAL; 1 switches it off; beyond
# [0, 1] is an error.
mask_option() {
  local flag=$1 key=$2 default=$3 part=$4 count=$5 total=$6 limit
  limit_of() { python3 -c "import json,sys; print(sorted({json.loads(l)[sys.argv[2]] for l in open(sys.argv[1])}))" "$1" "$key"; }
  "$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd -o c.jsonl > c.out 2>&1 || true
  limit=$(limit_of c.jsonl)
  [ "$limit" == "[$default]" ] || fail "certify --bop $key: $limit"
  python3 -c "
import json,sys
count, total, part, default = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
for l in open('c.jsonl'):
    j = json.loads(l)
    assert 0 <= j[count] <= j[total], j['cloud']
    assert (part in j['refused_by']) == (j[count] > default * j[total]), j['cloud']
" "$count" "$total" "$part" "$default" || fail "certify --bop: $count or '$part' refusals inconsistent"
  "$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd "$flag" 1 -o c.jsonl > c.out 2>&1 || true
  limit=$(limit_of c.jsonl)
  [ "$limit" == "[1.0]" ] || fail "$flag 1: limit $limit"
  grep -q "\"$part\"" c.jsonl && fail "$flag 1 still refuses by '$part'"
  bad_value "$flag" "$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd "$flag" 1.5
  bad_value "$flag" "$C3PO" eval "$NOSETS" --bop bop --obj-id 3 --detector svd "$flag" x
}
mask_option --outside-mask-fraction outside_mask_limit 0.05 mask seen_outside_mask free_space_measured
mask_option --uncovered-mask-fraction uncovered_mask_limit 0.035 uncovered mask_uncovered mask_at_depth
# --erode-mask: a width at the segment's depth or pixels (default 4). Every
# frame's k (erode_pixels) is round(f * w / median depth) lowered by the
# half-segment floor, so it never exceeds the width's pixels; pixels are taken
# as given (or lowered by the floor); 0 = off; malformed widths are one-line errors.
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd -o e_default.jsonl > /dev/null 2>&1 || true
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --erode-mask 3mm -o e_3mm.jsonl > /dev/null 2>&1 || true
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --erode-mask 6px -o e_6px.jsonl > /dev/null 2>&1 || true
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --erode-mask 4px -o e_4px.jsonl > /dev/null 2>&1 || true
"$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --erode-mask 0 -o e_0.jsonl > /dev/null 2>&1 || true
python3 - "$SRC" <<'PY' || fail "--erode-mask: erode_pixels not as the width, pixels or 0 give"
import json
rows = lambda f: [json.loads(l) for l in open(f)]
default, mm3, px6, off = rows('e_default.jsonl'), rows('e_3mm.jsonl'), rows('e_6px.jsonl'), rows('e_0.jsonl')
px4 = rows('e_4px.jsonl')
assert len(default) == 2 and [r['erode_pixels'] for r in default] == [r['erode_pixels'] for r in px4]
for r in mm3:
    assert 0 <= r['erode_pixels'] <= 1000
for r in px6:
    assert 0 < r['erode_pixels'] <= 6
    assert r['removed_erosion'] >= max(o['removed_erosion'] for o in off)
for r in off:
    assert r['erode_pixels'] == 0 and r['removed_erosion'] == 0
PY
for w in 3.5 abc -2 5km 2000 0.5px; do
  bad_value --erode-mask "$C3PO" certify "$NOSETS" --bop bop --obj-id 3 --detector svd --erode-mask "$w"
done
bad_value --erode-mask "$C3PO" eval "$NOSETS" --bop bop --obj-id 3 --detector svd --erode-mask 2m
# Ground truth that is not a rotation (here |R^T R - I| = 0.21) never stops a
# certify run: the instance's gt_ fields are null and one warning names the file.
cp -r bop bop_badgt
python3 - <<'PY'
import json
p = 'bop_badgt/000000/scene_gt.json'
gt = json.load(open(p))
first = sorted(gt, key=int)[0]
gt[first][0]['cam_R_m2c'] = [1, 0, 0, 0, 1, 0, 0, 0, 1.1]
json.dump(gt, open(p, 'w'))
PY
"$C3PO" certify "$NOSETS" --bop bop_badgt --obj-id 3 --detector svd -o g.jsonl > g.out 2> g.err
status=$?
[ $status -le 1 ] || fail "certify with an unusable ground-truth pose exited $status: $(cat g.err)"
grep -q "c3po certify: warning: .*bop_badgt/000000/scene_gt.json: .*cam_R_m2c: not orthonormal.*reported as null" g.err \
  || fail "no ground-truth warning: $(cat g.err)"
python3 - <<'PY' || fail "certify with an unusable ground-truth pose: gt fields not null / others missing"
import json
rows = [json.loads(l) for l in open('g.jsonl')]
assert len(rows) == 2
assert rows[0].get('gt_hausdorff') is None and 'R' in rows[0]
assert rows[1].get('gt_hausdorff') is not None
PY
if [ $pointnet -eq 1 ]; then
  "$C3PO" selftrain "$NOSETS" --model cube.model --bop bop --obj-id 3 --copies 2 --epochs 1 -o self_bop.model     > s.out 2>&1 || fail "selftrain --bop exited $?: $(tail -1 s.out)"
  [ "$(summary s.out)" == "m = 2%, robust loss = tls" ] || fail "selftrain --bop defaults: '$(summary s.out)'"
  grep -q "re-estimation on" s.out && fail "selftrain --bop re-estimates by default"
  "$C3PO" selftrain "$NOSETS" --model cube.model --bop bop --obj-id 3 --data data --copies 2 --epochs 1 \
    -o self_mixed.model > s.out 2>&1 || fail "selftrain --bop --data exited $?: $(tail -1 s.out)"
  [ "$(summary s.out)" == "m = 0, robust loss = tls" ] || fail "selftrain --bop --data defaults: '$(summary s.out)'"
fi

echo "failures: $failures"
[ $failures -eq 0 ]
