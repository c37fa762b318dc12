#!/usr/bin/env bash
# Builds c3po and runs the whole test suite (unit + CLI + browser tests).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 600
