#!/usr/bin/env bash
# c3po synth --format bop end to end: a BOP split folder read back by an
# independent reader (tests/cli/bop_check.py: Python json + zlib, when python3
# is there), same seed => same bytes, artefacts reported, a YCB mesh when the
# shared data is there, bad input => exit 2, one line, nothing left behind.
# Usage: synth_bop.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -uo pipefail
C3PO=$(realpath "$1"); SOURCE=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
fail() { echo "FAIL: $*"; exit 1; }
source "$(dirname "$0")/lib.sh"
MUG="$SOURCE/annotations/mug.json"
SMALL=(--intrinsics 400,400,159.5,119.5,320,240)
check() {   # check DIR IMAGES_PER_SCENE COUNT DIAMETER_MM BLEED
  if command -v python3 > /dev/null; then
    python3 "$SOURCE/tests/cli/bop_check.py" "$@" || fail "bop_check on $1"
  else
    echo "note: python3 not found, independent BOP check of $1 skipped"
  fi
}

# Clean scenes with distractors (copies of the mug and the box), twice with one seed.
for run in a b; do
  "$C3PO" synth "$MUG" -o "clean_$run" --format bop --count 5 --images-per-scene 3 --obj-id 4 \
    --distractors 2 --distractor "$SOURCE/annotations/box.json:11" "${SMALL[@]}" --seed 9 \
    > "clean_$run.log" 2>&1 || { cat "clean_$run.log"; fail "synth --format bop run $run"; }
done
grep -q "wrote clean_a: 5 images in 2 scene(s) of mug (obj_id 4" clean_a.log || { cat clean_a.log; fail "summary line"; }
diff -r clean_a clean_b > /dev/null || fail "same seed gave different bytes"
[ -f clean_a/000001/depth/000001.png ] || fail "missing 000001/depth/000001.png"
[ -f clean_a/000000/mask_visib/000002_000002.png ] || fail "missing mask_visib/000002_000002.png"
grep -q '"obj_id":11' clean_a/000000/scene_gt.json || fail "distractor obj_id 11 not in scene_gt.json"
check clean_a 3 5 "$(sed -n 's/.*d = \([0-9.e-]*\) m.*/\1/p' clean_a.log | awk '{print $1 * 1000}')" 0

# Realistic artefacts: reported, and a different depth image than the clean one.
"$C3PO" synth "$MUG" -o real --format bop --count 3 --obj-id 4 --artefacts realistic --bleed 3 \
  "${SMALL[@]}" --seed 9 > real.log 2>&1 || { cat real.log; fail "synth --artefacts realistic"; }
grep -q "artefacts: flying pixels [1-9]" real.log || { cat real.log; fail "artefact counts not reported"; }
cmp -s real/000000/depth/000000.png clean_a/000000/depth/000000.png && fail "artefacts changed nothing"
check real 1000 3 200 3

# An object in millimetres (the mug scaled by 1000): cam_t_m2c agrees with the metre object's.
sed 's/"units": *"m"/"units": "mm"/' "$MUG" > mug_mm.json
MESH=$(sed -n 's/.*"mesh": *"\([^"]*\)".*/\1/p' "$MUG")
awk '/^v /{printf "v %.9g %.9g %.9g\n", $2*1000, $3*1000, $4*1000; next} {print}' \
  "$SOURCE/annotations/$MESH" > "$MESH"
grep -q '"units": "mm"' mug_mm.json || fail "could not build the mm fixture"
"$C3PO" synth mug_mm.json -o mm --format bop --count 2 "${SMALL[@]}" --seed 9 > mm.log 2>&1 \
  || { cat mm.log; fail "synth on a mm object"; }
"$C3PO" synth "$MUG" -o m --format bop --count 2 "${SMALL[@]}" --seed 9 > m.log 2>&1 \
  || { cat m.log; fail "synth on the m object"; }
if command -v python3 > /dev/null; then
  python3 - m/000000/scene_gt.json mm/000000/scene_gt.json <<'PY' || fail "m and mm objects disagree"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
for key in a:
    for x, y in zip(a[key][0]["cam_t_m2c"], b[key][0]["cam_t_m2c"]):
        assert abs(x - y) <= 1e-6 * max(1.0, abs(x)), (x, y)
PY
fi

# A YCB mesh (when the shared data is there).
YCB="$SOURCE/../shared/data/ycb/035_power_drill"
if [ -f "$YCB/textured.obj" ]; then
  "$C3PO" annotate "$YCB/textured.obj" -o ycb_drill.json --from-json "$YCB/keypoints.json" \
    --key farthest8 > out_ycb.log 2>&1 || { cat out_ycb.log; fail "annotate the YCB drill"; }
  "$C3PO" synth ycb_drill.json -o ycb --format bop --count 2 --artefacts realistic --obj-id 15 \
    > ycb.log 2>&1 || { cat ycb.log; fail "synth --format bop on the YCB drill"; }
  check ycb 1000 2 300 2
else
  echo "note: $YCB not found, YCB part skipped"
fi

# Bad inputs: exit 2, one line naming the problem, no folder left.
expect_error() {   # expect_error OUTPUT_DIR PATTERN ARGS...
  local out=$1 pattern=$2; shift 2
  expect_bad_input "$out" "$pattern" "$C3PO" synth "$@" -o "$out"
}
expect_error bad1 "--kind" "$MUG" --format bop --count 2 --kind depth
expect_error bad2 "--bleed" "$MUG" --kind depth --count 2 --bleed 2
expect_error bad3 "--depth-scale" "$MUG" --format bop --count 2 --depth-scale 0
expect_error bad4 "--depth-scale" "$MUG" --format bop --count 2 --depth-scale 0.001
expect_error bad5 "--artefacts" "$MUG" --format bop --count 2 --artefacts lots
expect_error bad6 "--pose" "$MUG" --format bop --count 2 --pose paper
expect_error bad7 "--format" "$MUG" --format coco --count 2
expect_error bad8 "--depth-noise" "$MUG" --format bop --count 2 --depth-noise 0.001
expect_error bad9 "--distractors" "$MUG" --format bop --count 2 --distractor "$SOURCE/annotations/box.json"
expect_error bad10 "no-such.json" "$MUG" --format bop --count 2 --distractors 1 --distractor no-such.json
# The 1.5 m chair at synth's default range does not fit YCB-V's 0.1 mm units:
# --depth-scale auto (the default) takes the finest of 0.1, 0.2, 0.5, 1, ...
# mm that holds the deepest surface (oracle: the printed range and diameter).
"$C3PO" synth "$SOURCE/annotations/chair.json" -o chair --format bop --count 1 "${SMALL[@]}" --seed 3 \
  > chair.log 2>&1 || { cat chair.log; fail "synth chair with the default depth scale"; }
far_mm=$(sed -n 's/.*depth in \[[0-9.e-]*, \([0-9.e-]*\)\] m.*/\1/p' chair.log)
chair_mm=$(sed -n 's/.*d = \([0-9.e-]*\) m.*/\1/p' chair.log | awk '{print $1 * 1000}')
expected=$(awk -v z="$far_mm" -v d="$chair_mm" 'BEGIN { far = z * 1000 + d;
  n = split("0.1 0.2 0.5 1 2 5 10", s, " "); for (i = 1; i <= n; ++i) if (far / s[i] <= 65535) { print s[i]; exit } }')
[ -n "$expected" ] && [ "$expected" != 0.1 ] || { cat chair.log; fail "chair: expected a scale above 0.1 (far $far_mm m)"; }
grep -q "depth_scale $expected mm" chair.log || { cat chair.log; fail "chair: depth scale should be $expected"; }
check chair 1000 1 "$chair_mm" 0
# An existing folder that is not ours is refused and left alone.
mkdir precious; echo keep > precious/notes.txt
"$C3PO" synth "$MUG" -o precious --format bop --count 1 > err.log 2>&1
[ $? -eq 2 ] && grep -q "refusing to overwrite" err.log || { cat err.log; fail "overwrote a foreign folder"; }
[ "$(cat precious/notes.txt)" = keep ] || fail "the foreign folder changed"
# An earlier output is replaced.
"$C3PO" synth "$MUG" -o clean_b --format bop --count 1 "${SMALL[@]}" > /dev/null 2>&1 || fail "could not replace an earlier output"
[ ! -d clean_b/000001 ] || fail "the replaced output kept old scenes"
echo "synth --format bop CLI: all checks passed"
