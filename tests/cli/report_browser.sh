#!/usr/bin/env bash
# The evaluation report in headless Chromium (Debian package `chromium`,
# driven by npm playwright-core, like annotate_browser.sh): loads without
# console errors or network requests, shows the table and a WebGL 3D view that
# draws, orbits on drag and switches examples. Skips (77) without chromium,
# node or playwright-core.
# Usage: report_browser.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
PLAYWRIGHT_VERSION=1.56.1

[ -x /usr/bin/chromium ] || { echo "SKIP: /usr/bin/chromium not found (apt-get install chromium)"; exit 77; }
command -v node >/dev/null || { echo "SKIP: node not found (apt-get install nodejs npm)"; exit 77; }

rm -rf "$WORK"; mkdir -p "$WORK"
# playwright-core is installed once per build tree, next to the work folders.
PW_DIR=$(dirname "$WORK")/playwright-core-$PLAYWRIGHT_VERSION
if [ ! -f "$PW_DIR/node_modules/playwright-core/index.mjs" ]; then
  command -v npm >/dev/null || { echo "SKIP: npm not found to install playwright-core"; exit 77; }
  if ! npm install --silent --no-audit --no-fund --prefix "$PW_DIR" "playwright-core@$PLAYWRIGHT_VERSION" >"$WORK/npm.log" 2>&1; then
    echo "SKIP: cannot install playwright-core@$PLAYWRIGHT_VERSION (offline?):"; tail -3 "$WORK/npm.log"; exit 77
  fi
fi

cd "$WORK"
OBJECT="$SRC/annotations/mug.json"
"$C3PO" synth "$OBJECT" -o data --kind depth --count 8 --points 400 --seed 9 --perturb-sigma 0.4 >/dev/null 2>&1 \
  || { echo "FAIL: c3po synth"; exit 1; }
"$C3PO" eval "$OBJECT" --data data --detector manifest --report report.html --views 2 > table.txt 2>&1 \
  || { cat table.txt; echo "FAIL: c3po eval"; exit 1; }
[ -s report.html ] || { echo "FAIL: report.html not written"; exit 1; }

# KeyPo, + ICP, + corrector for the one detector.
node "$SRC/tests/browser/report_page.mjs" "$PW_DIR" report.html 3 "$WORK/chromium-profile"
