#!/usr/bin/env bash
# Installs everything c3po needs to build and test on Debian 12 (bookworm).
# Run as root (or with sudo). Chromium, Node.js and npm are only for the
# browser tests of the HTML pages; pass --no-browser to skip them.
set -euo pipefail
packages=(build-essential cmake ninja-build ccache
          libeigen3-dev libnanoflann-dev libcli11-dev nlohmann-json3-dev doctest-dev
          libassimp-dev tiny-dnn libcereal-dev libjs-three libspng-dev libpng-dev pkg-config parallel
          dpkg-dev file python3)
# dpkg-dev (dpkg-shlibdeps) and file: the Depends of the Debian package
# (cpack -G DEB, scripts/check-install.sh); python3: test oracles.
if [[ "${1:-}" != "--no-browser" ]]; then
  packages+=(chromium)
  # Node.js + npm run the browser tests (playwright-core from the npm registry);
  # keep a Node.js that is already installed.
  if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
    packages+=(nodejs npm)
  fi
fi
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${packages[@]}"
