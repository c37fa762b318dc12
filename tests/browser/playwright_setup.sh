# Sourced by the browser tests (tests/cli/*_browser.sh) after they set WORK:
# skips (exit 77) without Chromium or Node.js, installs playwright-core once
# per build tree next to the work folders, and sets PW_DIR to it.
PLAYWRIGHT_VERSION=1.56.1

[ -x /usr/bin/chromium ] || { echo "SKIP: /usr/bin/chromium not found (apt-get install chromium)"; exit 77; }
command -v node >/dev/null || { echo "SKIP: node not found (apt-get install nodejs npm)"; exit 77; }

rm -rf "$WORK"; mkdir -p "$WORK"
PW_DIR=$(dirname "$WORK")/playwright-core-$PLAYWRIGHT_VERSION
if [ ! -f "$PW_DIR/node_modules/playwright-core/index.mjs" ]; then
  command -v npm >/dev/null || { echo "SKIP: npm not found to install playwright-core"; exit 77; }
  if ! npm install --silent --no-audit --no-fund --prefix "$PW_DIR" "playwright-core@$PLAYWRIGHT_VERSION" >"$WORK/npm.log" 2>&1; then
    echo "SKIP: cannot install playwright-core@$PLAYWRIGHT_VERSION (offline?):"; tail -3 "$WORK/npm.log"; exit 77
  fi
fi
