#!/usr/bin/env bash
# ctest-labels: heavy
# The evaluation and certify reports in headless Chromium (Debian package `chromium`,
# driven by npm playwright-core, like annotate_browser.sh): loads without
# console errors or network requests, shows the table and a WebGL 3D view that
# draws, orbits on drag and switches examples. Skips (77) without chromium,
# node or playwright-core.
# Usage: report_browser.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
source "$SRC/tests/browser/playwright_setup.sh"

cd "$WORK"
OBJECT="$SRC/annotations/mug.json"
"$C3PO" synth "$OBJECT" -o data --kind depth --count 8 --points 400 --seed 9 --perturb-sigma 0.4 >/dev/null 2>&1 \
  || { echo "FAIL: c3po synth"; exit 1; }
"$C3PO" eval "$OBJECT" --data data --detector manifest --report report.html --views 2 > table.txt 2>&1 \
  || { cat table.txt; echo "FAIL: c3po eval"; exit 1; }
[ -s report.html ] || { echo "FAIL: report.html not written"; exit 1; }

# KeyPo, + ICP, + RANSAC + ICP, + corrector for the one detector.
node "$SRC/tests/browser/report_page.mjs" "$PW_DIR" report.html 4 "$WORK/chromium-profile"

# The certify report (no ground truth): the refusal table and the same 3D view.
status=0
"$C3PO" certify "$OBJECT" --data data --detector manifest --report certify.html --views 2 > certify.txt 2>&1 || status=$?
[ $status -le 1 ] && [ -s certify.html ] || { cat certify.txt; echo "FAIL: c3po certify --report"; exit 1; }
node "$SRC/tests/browser/report_page.mjs" "$PW_DIR" certify.html certify "$WORK/chromium-profile-certify"
