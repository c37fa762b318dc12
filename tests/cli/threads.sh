#!/usr/bin/env bash
# ctest-labels: heavy
# Same seed, same output on any machine: every command that runs on several
# threads (C3PO_THREADS, default: the cores) writes the same bytes with 1 and
# with 3 threads -- synth (depth clouds; a BOP dataset with a distractor and
# the realistic artefacts), certify (--data, --bop with free space and the
# rival search), eval --json, indicators --auto, and train + selftrain where
# pointnet is built -- up to the timing keys ("ms", "seconds").
# Usage: threads.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -u
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
MUG="$SRC/annotations/mug.json"; DRILL="$SRC/annotations/drill.json"; BOX="$SRC/annotations/box.json"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# untimed FILE: FILE's JSON (lines or one document) without the timing keys, keys sorted.
untimed() {
  python3 - "$1" <<'PY'
import json, sys
def strip(value):
    if isinstance(value, dict):
        return {k: strip(v) for k, v in value.items() if k not in ("ms", "ms_stages", "seconds")}
    if isinstance(value, list):
        return [strip(v) for v in value]
    return value
text = open(sys.argv[1]).read()
try:
    docs = [json.loads(text)]
except json.JSONDecodeError:
    docs = [json.loads(line) for line in text.splitlines() if line.strip()]
for doc in docs:
    print(json.dumps(strip(doc), sort_keys=True))
PY
}

run_all() {   # run_all THREADS: every output under t$THREADS/
  local t=$1 out="t$1"
  mkdir -p "$out"
  export C3PO_THREADS=$t
  "$C3PO" synth "$MUG" -o "$out/depth" --kind depth --count 16 --points 400 --noise 1mm --seed 4 \
    > /dev/null 2>&1 || fail "synth depth ($t threads)"
  "$C3PO" synth "$DRILL" -o "$out/bop" --format bop --count 4 --obj-id 1 --distractors 1 --distractor "$BOX:2" \
    --artefacts realistic --intrinsics 400,400,159.5,119.5,320,240 --seed 4 > /dev/null 2>&1 ||
    fail "synth bop ($t threads)"
  "$C3PO" certify "$MUG" --data "$out/depth" --detector svd -o "$out/certify.jsonl" > /dev/null 2>&1
  [ $? -le 1 ] || fail "certify --data ($t threads)"
  "$C3PO" certify "$DRILL" --bop "$out/bop" --obj-id 1 --detector svd -o "$out/certify_bop.jsonl" > /dev/null 2>&1
  [ $? -le 1 ] || fail "certify --bop ($t threads)"
  "$C3PO" eval "$MUG" --data "$out/depth" --detector svd --json "$out/eval.json" > /dev/null 2>&1 ||
    fail "eval ($t threads)"
  "$C3PO" indicators "$BOX" --auto --views 12 --seed 2 > "$out/indicators.txt" 2>&1 ||
    fail "indicators --auto ($t threads)"
  sed -i 's/[0-9.]* s\b//g' "$out/indicators.txt"
  if [ "${C3PO_WITH_POINTNET:-ON}" != OFF ]; then
    "$C3PO" train "$MUG" --data "$out/depth" -o "$out/mug.model" --epochs 4 --point-mlp 16 16 --head 16 --points 64 \
      --seed 1 > /dev/null 2>&1 || fail "train ($t threads)"
    "$C3PO" selftrain "$MUG" --model "$out/mug.model" --data "$out/depth" -o "$out/self.model" --epochs 2 --seed 3 \
      --patience 0 --eps-oc 5%d > /dev/null 2>&1 || fail "selftrain ($t threads)"
  fi
  unset C3PO_THREADS
}

run_all 1
run_all 3
diff -r t1/depth t3/depth > /dev/null || fail "synth depth clouds differ between 1 and 3 threads"
diff -r t1/bop t3/bop > /dev/null || fail "synth BOP datasets differ between 1 and 3 threads"
for f in certify.jsonl certify_bop.jsonl eval.json; do
  [ -s "t1/$f" ] || { fail "t1/$f is empty"; continue; }
  diff <(untimed "t1/$f" | sed 's#t1/#T/#g') <(untimed "t3/$f" | sed 's#t3/#T/#g') > /dev/null ||
    fail "$f differs between 1 and 3 threads"
done
diff t1/indicators.txt t3/indicators.txt > /dev/null || fail "indicators --auto prints differently with 1 and 3 threads"
if [ "${C3PO_WITH_POINTNET:-ON}" != OFF ]; then
  cmp -s t1/mug.model t3/mug.model || fail "train: the models differ between 1 and 3 threads"
  cmp -s t1/self.model t3/self.model || fail "selftrain: the models differ between 1 and 3 threads"
  diff <(untimed t1/self.model.log.jsonl) <(untimed t3/self.model.log.jsonl) > /dev/null ||
    fail "selftrain: the logs differ between 1 and 3 threads"
fi
certified=$(grep -c '"certified":true' t1/certify.jsonl)
echo "certify --data: $(wc -l < t1/certify.jsonl) lines ($certified certified)," \
     "--bop: $(wc -l < t1/certify_bop.jsonl) lines"
[ "$failures" -eq 0 ] && echo "ok: the same outputs with 1 and 3 threads"
exit $((failures > 0))
