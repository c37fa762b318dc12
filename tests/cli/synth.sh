#!/usr/bin/env bash
# c3po synth end to end: sim and depth datasets of a bundled object, same seed
# => same bytes, bad input => exit 2, one line, nothing left behind.
# Usage: synth.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -uo pipefail
C3PO=$(realpath "$1"); SOURCE=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
fail() { echo "FAIL: $*"; exit 1; }
source "$(dirname "$0")/lib.sh"
BOX="$SOURCE/annotations/box.json"

# Depth clouds with perturbed detected keypoints, twice with the same seed.
for run in a b; do
  "$C3PO" synth "$BOX" -o "depth_$run" --kind depth --count 12 --points 400 --noise 1mm \
    --dropout 0.1 --perturb-sigma 0.3 --seed 7 > "out_$run.log" 2>&1 \
    || { cat "out_$run.log"; fail "synth depth run $run"; }
done
grep -q "wrote depth_a: 12 depth clouds of box" out_a.log || { cat out_a.log; fail "summary line"; }
[ "$(wc -l < depth_a/manifest.jsonl)" -eq 12 ] || fail "manifest should have 12 lines"
[ "$(ls depth_a/*.ply | wc -l)" -eq 12 ] || fail "expected 12 clouds"
diff -r depth_a depth_b > /dev/null || fail "same seed gave different bytes"
head -1 depth_a/manifest.jsonl | grep -q '"visible":\[' || fail "depth manifest lacks visible"
head -1 depth_a/manifest.jsonl | grep -q '"detected_keypoints":\[' || fail "no detected_keypoints"
head -c 200 depth_a/000000.ply | grep -qa "format binary_little_endian" || fail "clouds are not binary PLY"

# Another seed, other data; sim clouds have exactly --points points.
"$C3PO" synth "$BOX" -o depth_c --kind depth --count 12 --points 400 --seed 8 > out_c.log 2>&1 \
  || { cat out_c.log; fail "synth seed 8"; }
cmp -s depth_a/manifest.jsonl depth_c/manifest.jsonl && fail "different seeds gave the same data"
"$C3PO" synth "$BOX" -o sim --kind sim --count 5 --points 321 --pose paper > out_sim.log 2>&1 \
  || { cat out_sim.log; fail "synth sim"; }
grep -qa "element vertex 321" sim/000004.ply || fail "sim cloud should have 321 points"
grep -q '"visible"' sim/manifest.jsonl && fail "sim manifest should not claim visibility"

# Easy poses, a custom camera and distance range.
"$C3PO" synth "$SOURCE/annotations/drill.json" -o easy --kind depth --count 4 --points 500 \
  --pose easy --intrinsics 600,600,159.5,119.5,320,240 --distance 0.8,1.0 > out_easy.log 2>&1 \
  || { cat out_easy.log; fail "synth --pose easy --intrinsics"; }
grep -q "object centre depth in \[0.8, 1\] m" out_easy.log || { cat out_easy.log; fail "distance range not reported"; }

# A YCB mesh with keypoints imported by c3po annotate (when the shared data is there).
YCB="$SOURCE/../shared/data/ycb/035_power_drill"
if [ -f "$YCB/textured.obj" ]; then
  "$C3PO" annotate "$YCB/textured.obj" -o ycb_drill.json --from-json "$YCB/keypoints.json" \
    --key farthest8 > out_ycb.log 2>&1 || { cat out_ycb.log; fail "annotate the YCB drill"; }
  "$C3PO" synth ycb_drill.json -o ycb_depth --kind depth --count 6 --noise 1mm --dropout 0.1 \
    > out_ycb.log 2>&1 || { cat out_ycb.log; fail "synth on the YCB drill"; }
  [ "$(wc -l < ycb_depth/manifest.jsonl)" -eq 6 ] || fail "YCB dataset should have 6 clouds"
else
  echo "note: $YCB not found, YCB part skipped"
fi

# Bad inputs: exit 2, one line on stderr naming the problem, no dataset.
expect_error() {   # expect_error OUTPUT_DIR PATTERN ARGS...
  local out=$1 pattern=$2; shift 2
  expect_bad_input "$out" "$pattern" "$C3PO" synth "$@" -o "$out"
}
expect_error bad1 "count" "$BOX" --kind sim --count 0
expect_error bad2 "kind" "$BOX" --kind lidar --count 3
expect_error bad3 "min-points" "$BOX" --kind depth --count 3 --points 100 --min-points 200
expect_error bad4 "intrinsics" "$BOX" --kind depth --count 3 --intrinsics 525,525,320
expect_error bad5 "distance" "$BOX" --kind depth --count 3 --distance 2,1

# An object whose indicator set points past the keypoints.
cp "$SOURCE/annotations/box.obj" box.obj
sed 's/"indicator_sets": \[/"indicator_sets": [[99],/' "$BOX" > bad_sets.json
grep -q '\[99\]' bad_sets.json || fail "could not build the bad-sets fixture"
expect_error bad6 "bad_sets.json" bad_sets.json --kind sim --count 3

# A mesh without triangles.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n' > box.obj
cp "$BOX" no_triangles.json   # its mesh path "box.obj" now names the broken mesh
expect_error bad7 "box.obj" no_triangles.json --kind sim --count 3

# An unwritable output folder (its parent is a regular file).
echo x > plain_file
expect_error plain_file/out "plain_file" "$BOX" --kind sim --count 3
echo "synth CLI: all checks passed"
