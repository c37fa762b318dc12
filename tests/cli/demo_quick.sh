#!/usr/bin/env bash
# ctest-labels: heavy
# The README's demo in its --quick form: every step runs and writes its outputs
# (sim data, models, depth data, table, JSON, HTML report).
# Usage: demo_quick.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$SRC"
[ "${C3PO_WITH_POINTNET:-ON}" != OFF ] || { echo "SKIP: the demo trains the pointnet detector (C3PO_WITH_POINTNET=OFF)"; exit 77; }
"$C3PO" demo --quick --out "$WORK/out" > "$WORK/demo.log" 2>&1 || { tail -20 "$WORK/demo.log"; exit 1; }
for f in sim/manifest.jsonl sim.model self.model supervised.model depth_test/manifest.jsonl report.html eval.json \
         sim.model.log.jsonl self.model.log.jsonl; do
  [ -s "$WORK/out/$f" ] || { echo "FAIL: demo did not write $f"; exit 1; }
done
grep -q "Soundness:" "$WORK/demo.log" || { echo "FAIL: no soundness line"; exit 1; }
grep -q "C-3PO (self)" "$WORK/demo.log" || { echo "FAIL: no C-3PO row"; exit 1; }
echo "demo --quick: OK"
