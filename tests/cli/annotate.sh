#!/usr/bin/env bash
# c3po annotate end to end: units conversion, in-place --edit, imports from the
# shared YCB keypoints (when present), bad input => exit 2 and nothing written.
# Usage: annotate.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -uo pipefail
C3PO=$(realpath "$1"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
fail() { echo "FAIL: $*"; exit 1; }
source "$(dirname "$0")/lib.sh"

# A 200 x 100 x 50 mm box, in millimetres.
cat > box_mm.obj <<'OBJ'
v 0 0 0
v 200 0 0
v 200 100 0
v 0 100 0
v 0 0 50
v 200 0 50
v 200 100 50
v 0 100 50
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
OBJ

# Units: the mesh is converted to metres; keypoints are given in metres.
"$C3PO" annotate box_mm.obj --units mm -o box.json --keypoint 0.1,0.05,0.053 --name lid > out.log 2>&1 \
  || { cat out.log; fail "annotate with --units mm"; }
grep -q "diameter d = 0.229129 m" out.log || { cat out.log; fail "diameter not converted to metres"; }
grep -q 'keypoint 0 "lid" .*snapped 0.003 to the surface' out.log || { cat out.log; fail "snap distance not reported"; }
grep -q '"units": "mm"' box.json || fail "units not written"

# --edit in place: add an --auto keypoint, remove keypoint 0.
"$C3PO" annotate --edit box.json -o box.json --auto 2 --seed 4 --remove 0 > edit.log 2>&1 \
  || { cat edit.log; fail "--edit in place"; }
grep -q "wrote box.json: 2 keypoints" edit.log || { cat edit.log; fail "edit result"; }
grep -q '"auto0"' box.json || fail "auto keypoint names"

# Bad input: exit 2, one line on stderr, no output file.
expect_error() {
  local what=$1; shift
  rm -f bad.json bad.html
  expect_bad_input bad.json "" "$C3PO" "$@" || return 1
  [ ! -e bad.html ] || fail "$what: wrote bad.html"
  echo "ok: $what -> $(head -1 bad_input.err)"
}
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n' > no_faces.obj
expect_error "non-numeric coordinate" annotate box_mm.obj --units mm -o bad.json --keypoint 0.1,x,0
expect_error "empty mesh" annotate no_faces.obj -o bad.json --keypoint 0,0,0
expect_error "missing mesh" annotate nowhere.obj -o bad.json --keypoint 0,0,0
expect_error "point far from the surface" annotate box_mm.obj --units mm -o bad.json --html bad.html --keypoint 0.1,0.05,0.2
expect_error "unknown units" annotate box_mm.obj --units inch -o bad.json --keypoint 0,0,0
expect_error "no keypoints" annotate box_mm.obj -o bad.json --html bad.html
expect_error "remove out of range" annotate --edit box.json --remove 7 -o bad.json
expect_error "missing --from-json file" annotate box_mm.obj --units mm -o bad.json --from-json none.json --key k
echo '[{"class_id": "1", "model_id": "m1", "keypoints": [{"xyz": [0, 0, 0], "semantic_id": 1}]}]' > kpnet.json
expect_error "unknown KeypointNet model id" annotate box_mm.obj --units mm -o bad.json --from-keypointnet kpnet.json --model-id m2
grep -q "model id 'm2' not found" bad_input.err || fail "unknown model id message"

# Import from the shared YCB keypoints (skipped without the shared data).
YCB=$(realpath -m "$2/../shared/data/ycb/025_mug")
if [ -f "$YCB/keypoints.json" ]; then
  "$C3PO" annotate "$YCB/textured.obj" -o mug.json --from-json "$YCB/keypoints.json" --key farthest8 \
      --max-snap 1mm > mug.log 2>&1 || { cat mug.log; fail "YCB import"; }
  [ "$(grep -c 'snapped' mug.log)" -eq 8 ] || { cat mug.log; fail "8 snapped keypoints expected"; }
  echo "ok: YCB mug farthest8 imported"
else
  echo "note: $YCB absent, YCB import not tested"
fi
echo "all annotate CLI checks passed"
