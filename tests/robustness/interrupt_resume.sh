#!/usr/bin/env bash
# ctest-labels: heavy
# Interrupted work loses nothing (issue 7): `train` killed with SIGINT and
# `selftrain` killed with SIGTERM mid-epoch keep their checkpoint, leave no
# partial model file, and `--resume` gives the same model bytes as an
# uninterrupted run with the same seed. `synth` killed mid-run (SIGINT into a
# new folder, SIGTERM over an existing dataset) leaves no dataset or the old
# complete one, and no temporary folder next to it.
# Usage: interrupt_resume.sh C3PO_BIN SOURCE_DIR WORK_DIR   (ctest: robustness_interrupt_resume)
set -u
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
OBJ="$SRC/tests/fixtures/objects/cube.json"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# The runs hold inside epoch 2 until signalled (C3PO_TEST_HOLD_AT), so epoch
# lengths no longer matter for correctness; they only set the run time. Sanitizer builds train ~35x slower: C3PO_ROBUSTNESS_LIGHT=1 (set by
# scripts/sanitize.sh) uses a smaller run whose epochs take ~2 s there.
if [ "${C3PO_ROBUSTNESS_LIGHT:-0}" = 1 ]; then
  SIM=(--count 300 --points 400); UNLABELLED=(--count 160 --points 400); NET=(--point-mlp 64 128 --head 128 --points 512)
else
  SIM=(--count 1500 --points 400); UNLABELLED=(--count 200 --points 400); NET=(--point-mlp 128 256 --head 256 --points 1024)
fi
"$C3PO" synth "$OBJ" -o sim --kind sim "${SIM[@]}" --seed 1 >/dev/null 2>&1 || { echo "synth failed"; exit 2; }
"$C3PO" synth "$OBJ" -o unlabelled --kind sim "${UNLABELLED[@]}" --noise 1%d --seed 2 >/dev/null 2>&1 || exit 2
TRAIN=(--data sim --epochs 4 "${NET[@]}" --seed 7)
SELF=(--model ref_train.model --data unlabelled --epochs 4 --seed 9)

# interrupt NAME SIGNAL CMD...: starts CMD, sends SIGNAL once the first epoch
# line is on stderr, waits, prints the status. C3PO_TEST_HOLD_AT=2:1 makes the
# run wait before batch 1 of epoch 2 until the signal has arrived, so the
# interruption lands inside epoch 2 however fast or loaded the machine is.
interrupt() {
  local name=$1 signal=$2; shift 2
  C3PO_TEST_HOLD_AT=2:1 "$@" > "$name.out" 2> "$name.err" &
  local pid=$! waited=0
  until grep -q '^epoch *1 ' "$name.err" 2>/dev/null; do
    sleep 0.1; waited=$((waited + 1))
    if ! kill -0 $pid 2>/dev/null || [ $waited -gt 3000 ]; then break; fi
  done
  kill -s "$signal" $pid 2>/dev/null || echo "($name finished before the signal)"
  wait $pid; local status=$?
  echo "$name: killed with SIG$signal after: $(grep -c '^epoch' "$name.err") epoch line(s); status $status; stderr tail: $(tail -1 "$name.err")"
  grep -q "interrupted" "$name.err" && echo "  (c3po reported the interruption; status $status)"
  [ "$(grep -c '^epoch' "$name.err")" -eq 1 ] || fail "$name: not interrupted inside epoch 2 (the hold did not take effect)"
}

# check_resume NAME MODEL REFERENCE RESUME_CMD...
check_resume() {
  local name=$1 model=$2 reference=$3; shift 3
  [ -f "$model.ckpt" ] && echo "  checkpoint kept: $model.ckpt ($(stat -c %s "$model.ckpt") bytes)" \
    || fail "$name: no checkpoint $model.ckpt after the interruption"
  [ ! -e "$model" ] || fail "$name: a model file $model exists after the interruption"
  ls -A | grep -E "^\.$model|\.tmp" && fail "$name: temporary files left"
  "$@" > "$name.resume.out" 2> "$name.resume.err"; local status=$?
  echo "  resume: status $status; $(tail -1 "$name.resume.err")"
  [ $status -eq 0 ] || fail "$name: --resume exited $status"
  if cmp "$model" "$reference"; then echo "  $name: resumed model == uninterrupted model (cmp)"
  else fail "$name: resumed model differs from the uninterrupted run"; fi
}

# train and selftrain need the pointnet detector (not in a C3PO_WITH_POINTNET=OFF build).
if [ "${C3PO_WITH_POINTNET:-ON}" != OFF ]; then
"$C3PO" train "$OBJ" "${TRAIN[@]}" -o ref_train.model > ref_train.out 2> ref_train.err || { echo "reference train failed"; exit 2; }
echo "reference train: $(grep -c '^epoch' ref_train.err) epochs"
interrupt train INT "$C3PO" train "$OBJ" "${TRAIN[@]}" -o cut_train.model
check_resume train cut_train.model ref_train.model "$C3PO" train "$OBJ" "${TRAIN[@]}" -o cut_train.model --resume

"$C3PO" selftrain "$OBJ" "${SELF[@]}" -o ref_self.model > ref_self.out 2> ref_self.err || { echo "reference selftrain failed: $(tail -1 ref_self.err)"; exit 2; }
echo "reference selftrain: $(grep -c '^epoch' ref_self.err) epochs"
interrupt selftrain TERM "$C3PO" selftrain "$OBJ" "${SELF[@]}" -o cut_self.model
check_resume selftrain cut_self.model ref_self.model "$C3PO" selftrain "$OBJ" "${SELF[@]}" -o cut_self.model --resume
fi

# --- synth ------------------------------------------------------------------
# interrupt_synth NAME SIGNAL DIR: synth into DIR, signalled once its hidden
# temporary folder holds 20 clouds (mid-run; 4000 are asked for).
interrupt_synth() {
  local name=$1 signal=$2 dir=$3 waited=0
  "$C3PO" synth "$OBJ" -o "$dir" --kind sim --count 4000 --points 400 --seed 5 > "$name.out" 2> "$name.err" &
  local pid=$!
  until [ "$(find . -maxdepth 2 -path "./.$dir.partial.*/*.ply" 2>/dev/null | wc -l)" -ge 20 ]; do
    sleep 0.05; waited=$((waited + 1))
    if ! kill -0 $pid 2>/dev/null || [ $waited -gt 2000 ]; then break; fi
  done
  kill -s "$signal" $pid 2>/dev/null || echo "($name finished before the signal)"
  wait $pid; local status=$?
  echo "$name: killed with SIG$signal; status $status; stderr tail: $(tail -1 "$name.err")"
  # 130 with the message = c3po's cooperative stop; 128 + n alone = killed.
  [ $status -eq 130 ] && grep -q interrupted "$name.err" \
    || fail "$name: status $status, not c3po's interrupt status 130 with its message"
  if ls -A | grep -E "^\.$dir|\.partial|\.tmp"; then fail "$name: temporary files left next to $dir"; fi
}
# A dataset is complete when every manifest line names an existing cloud and
# every cloud is named: prints "complete N" or "incomplete ...".
dataset_state() {
  [ -e "$1" ] || { echo "absent"; return; }
  python3 - "$1" <<'PY'
import json, os, sys
d = sys.argv[1]
try:
    clouds = [json.loads(l)['cloud'] for l in open(os.path.join(d, 'manifest.jsonl')) if l.strip()]
except Exception as e:
    print('incomplete (manifest: %s)' % e); sys.exit()
files = sorted(f for f in os.listdir(d) if f != 'manifest.jsonl')
missing = [c for c in clouds if not os.path.isfile(os.path.join(d, c))]
print('complete %d' % len(clouds) if not missing and sorted(clouds) == files
      else 'incomplete (%d listed, %d files, %d missing)' % (len(clouds), len(files), len(missing)))
PY
}
interrupt_synth synth_new INT fresh
state=$(dataset_state fresh); echo "  fresh: $state"
[ "$state" = absent ] || fail "synth_new: an interrupted synth into a new folder left: $state"

before=$(cd sim && sha256sum -- * | sha256sum)
interrupt_synth synth_over TERM sim
state=$(dataset_state sim); echo "  sim: $state"
[ "$state" = "complete ${SIM[1]}" ] || fail "synth_over: the existing dataset is now: $state"
[ "$(cd sim && sha256sum -- * | sha256sum)" = "$before" ] || fail "synth_over: the existing dataset changed"

# --- synth --format bop ---------------------------------------------------------
# Signalled once the hidden folder holds 20 depth images of 4000 asked for:
# nothing is left for a new folder, and an earlier BOP output stays intact.
interrupt_synth_bop() {
  local name=$1 signal=$2 dir=$3 waited=0
  "$C3PO" synth "$OBJ" -o "$dir" --format bop --count 4000 --artefacts realistic --depth-scale 1 \
    --intrinsics 400,400,159.5,119.5,320,240 --seed 5 > "$name.out" 2> "$name.err" &
  local pid=$!
  until [ "$(find . -maxdepth 4 -path "./.$dir.partial.*/*/depth/*.png" 2>/dev/null | wc -l)" -ge 20 ]; do
    sleep 0.05; waited=$((waited + 1))
    if ! kill -0 $pid 2>/dev/null || [ $waited -gt 2000 ]; then break; fi
  done
  kill -s "$signal" $pid 2>/dev/null || echo "($name finished before the signal)"
  wait $pid; local status=$?
  echo "$name: killed with SIG$signal; status $status; stderr tail: $(tail -1 "$name.err")"
  [ $status -eq 130 ] && grep -q interrupted "$name.err" \
    || fail "$name: status $status, not c3po's interrupt status 130 with its message"
  if ls -A | grep -E "^\.$dir|\.partial|\.tmp"; then fail "$name: temporary files left next to $dir"; fi
}
interrupt_synth_bop synth_bop_new INT bop_fresh
[ ! -e bop_fresh ] || fail "synth_bop_new: an interrupted synth --format bop left bop_fresh"
"$C3PO" synth "$OBJ" -o bop_old --format bop --count 3 --depth-scale 1 --intrinsics 400,400,159.5,119.5,320,240 \
  > /dev/null 2>&1 || fail "synth --format bop reference run"
before=$(cd bop_old && find . -type f | sort | xargs sha256sum | sha256sum)
interrupt_synth_bop synth_bop_over TERM bop_old
[ "$(cd bop_old && find . -type f | sort | xargs sha256sum | sha256sum)" = "$before" ] \
  || fail "synth_bop_over: the earlier BOP output changed"

echo "failures: $failures"
[ $failures -eq 0 ]
