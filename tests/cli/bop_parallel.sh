#!/usr/bin/env bash
# ctest-labels: heavy
# Sharded certification of the real YCB-Video frames (issue 15): GNU parallel
# runs --shard K/3 parts, `c3po merge` joins them, and the result equals the
# unsharded run (up to the timing fields "ms" and the CSV's time); the Slurm
# script is run as three simulated array tasks. Every line carries the BOP ids.
# Skips (77) when ../shared/data/real/ycbv-bop or GNU parallel is absent.
# Usage: bop_parallel.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
DATA="$SRC/../shared/data/real/ycbv-bop"
[ -d "$DATA/test" ] || { echo "skipped: $DATA is absent"; exit 77; }
command -v parallel >/dev/null || { echo "skipped: GNU parallel is not installed"; exit 77; }
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
fail() { echo "FAIL: $*"; exit 1; }

"$C3PO" annotate "$DATA/models/obj_000005.ply" --units mm --auto 12 --seed 1 -o obj5.json >/dev/null
ARGS=(--bop "$DATA/test" --obj-id 5 --detector svd --eps-oc 3%d)
set +e
"$C3PO" certify obj5.json "${ARGS[@]}" -o full.jsonl --bop-csv full.csv >/dev/null 2>&1
[ $? -le 1 ] || fail "unsharded certify failed"
# The documented invocation (docs/camera_inputs.md).
parallel --halt now,fail=1 "'$C3PO' certify obj5.json ${ARGS[*]} --shard {}/3 -o part{}.jsonl --bop-csv part{}.csv >/dev/null 2>&1; [ \$? -le 1 ]" ::: 1 2 3
[ $? -eq 0 ] || fail "a GNU parallel part failed"
set -e
# One frame of the scene, its camera picked from the scene's scene_camera.json
# (20 images) with --im-id: the same cloud and pose as the --bop line; without
# --im-id, or with an id the file lacks, exit 2.
S1="$DATA/test/000001"
GT=$(python3 -c "import json; print([e['obj_id'] for e in json.load(open('$S1/scene_gt.json'))['2']].index(5))")
FRAME=(--depth "$S1/depth/000002.png" --mask "$S1/mask_visib/000002_$(printf %06d "$GT").png" --camera "$S1/scene_camera.json")
set +e
"$C3PO" certify obj5.json --detector svd --eps-oc 3%d "${FRAME[@]}" --im-id 2 --json > frame.jsonl 2>/dev/null
[ $? -le 1 ] || fail "certify --camera scene_camera.json --im-id 2 failed"
"$C3PO" certify obj5.json --detector svd --eps-oc 3%d "${FRAME[@]}" --json > no_im_id.out 2> no_im_id.err
[ $? -eq 2 ] && grep -q "scene_camera.json: a scene_camera.json of 20 images; give --im-id" no_im_id.err \
  || fail "several cameras without --im-id: $(cat no_im_id.err)"
"$C3PO" certify obj5.json --detector svd --eps-oc 3%d "${FRAME[@]}" --im-id 999 --json > bad_im_id.out 2> bad_im_id.err
[ $? -eq 2 ] && grep -q "scene_camera.json: --im-id 999: no such image" bad_im_id.err || fail "absent --im-id: $(cat bad_im_id.err)"
set -e
python3 - "$GT" <<'PY' || fail "the --im-id frame differs from its --bop line"
import json, sys
gt = int(sys.argv[1])
frame = json.loads(open('frame.jsonl').readline())
bop = [json.loads(l) for l in open('full.jsonl')]
line = [d for d in bop if d['scene_id'] == 1 and d['im_id'] == 2 and d['gt_id'] == gt][0]
for key in ('points', 'pixels', 'no_depth', 'R', 't', 'certified'):
    assert frame[key] == line[key], (key, frame[key], line[key])
PY
"$C3PO" merge -o merged.jsonl part1.jsonl part2.jsonl part3.jsonl
"$C3PO" merge -o merged.csv part1.csv part2.csv part3.csv

# Slurm job array, simulated: three tasks numbered 0..2.
for task in 0 1 2; do
  SLURM_ARRAY_TASK_ID=$task SLURM_ARRAY_TASK_MIN=0 SLURM_ARRAY_TASK_COUNT=3 C3PO="$C3PO" \
    bash "$SRC/scripts/slurm_certify.sh" obj5.json slurm "${ARGS[@]}" >/dev/null 2>&1 || fail "slurm task $task failed"
done
"$C3PO" merge -o slurm.jsonl slurm/part_1.jsonl slurm/part_2.jsonl slurm/part_3.jsonl
"$C3PO" merge -o slurm.csv slurm/part_1.csv slurm/part_2.csv slurm/part_3.csv

python3 - <<'PY' || fail "merged outputs differ from the unsharded run"
import json, sys
def lines(path):
    out = []
    for line in open(path):
        d = json.loads(line)
        d.pop('ms', None)
        d.pop('ms_stages', None)
        out.append(d)
    return out
def csv(path):
    return [l.rstrip('\n').rsplit(',', 1)[0] for l in open(path)]
full = lines('full.jsonl')
assert len(full) == 40, len(full)
for d in full:
    for key in ('scene_id', 'im_id', 'gt_id', 'obj_id', 'pixels', 'no_depth', 'points'):
        assert key in d, (key, d)
for name in ('merged', 'slurm'):
    assert lines(name + '.jsonl') == full, name
    assert csv(name + '.csv') == csv('full.csv'), name
parts = [set((json.loads(l)['scene_id'], json.loads(l)['im_id']) for l in open('part%d.jsonl' % k)) for k in (1, 2, 3)]
assert not (parts[0] & parts[1]) and not (parts[1] & parts[2]) and not (parts[0] & parts[2])
print('sharded == unsharded:', len(full), 'lines,', len(csv('full.csv')) - 1, 'CSV rows')
PY
echo "bop_parallel: ok"
