#!/usr/bin/env bash
# The annotation page in headless Chromium (Debian package `chromium`, driven
# by npm playwright-core): loads without console errors or network requests,
# shows the keypoints, a real click adds one, a click on a keypoint removes it
# (indicator sets remapped), and the downloaded JSON is accepted by
# `c3po annotate --edit`. Skips (77) without chromium, node or npm.
# Usage: annotate_browser.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
source "$SRC/tests/browser/playwright_setup.sh"

cd "$WORK"
cat > box.obj <<'OBJ'
v 0 0 0
v 0.2 0 0
v 0.2 0.1 0
v 0 0.1 0
v 0 0 0.05
v 0.2 0 0.05
v 0.2 0.1 0.05
v 0 0.1 0.05
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
"$C3PO" annotate box.obj -o box.json --auto 6 --seed 3 >/dev/null
# Give the object indicator sets, then write the page through --edit.
node -e '
const fs = require("fs"); const o = JSON.parse(fs.readFileSync("box.json"));
o.indicator_sets = [[0, 1], [2, 3, 4], [5]]; fs.writeFileSync("box.json", JSON.stringify(o));'
"$C3PO" annotate --edit box.json -o box.json --html view.html >/dev/null
[ -s view.html ] || { echo "FAIL: view.html not written"; exit 1; }

node "$SRC/tests/browser/annotate_page.mjs" "$PW_DIR" view.html 6 0.2,0.1,0.05 "$WORK/downloaded.json"

# The downloaded object (saved next to box.json) is accepted by --edit.
"$C3PO" annotate --edit downloaded.json -o reedited.json --keypoint 0.1,0.05,0.05 > reedit.log \
  || { echo "FAIL: c3po annotate --edit rejected the downloaded JSON"; cat reedit.log; exit 1; }
grep -q "wrote reedited.json: 7 keypoints" reedit.log \
  || { echo "FAIL: unexpected re-edit result"; cat reedit.log; exit 1; }
echo "ok: c3po annotate --edit accepts the downloaded JSON"
