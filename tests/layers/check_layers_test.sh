#!/usr/bin/env bash
# The layer check (cmake/CheckLayers.cmake) can fail: on a copy of libc3po it
# passes, then fails on each planted violation (an upward include in a source,
# in a public header, of a sibling, of the plugins, a relative include into another folder, sources in a
# folder that is not a layer), naming the file.
# Usage: check_layers_test.sh SOURCE_DIR RULES_FILE WORK_DIR   (ctest: layer_check_detects_violations)
set -u
SRC=$(realpath "$1"); RULES=$(realpath "$2"); WORK=$(realpath -m "$3")
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

scan() { cmake -DROOT="$WORK/libc3po" -DRULES_FILE="$RULES" -P "$SRC/cmake/CheckLayers.cmake" > "$WORK/scan.log" 2>&1; }
fresh() { rm -rf "$WORK"; mkdir -p "$WORK"; cp -r "$SRC/libc3po" "$WORK/libc3po"; }

fresh
scan || fail "the unmodified copy does not pass: $(cat "$WORK/scan.log")"

# expect_violation NAME FILE(relative to libc3po) LINE PATTERN
expect_violation() {
  local name=$1 file=$2 line=$3 pattern=$4
  fresh
  mkdir -p "$(dirname "$WORK/libc3po/$file")"
  printf '%s\n' "$line" >> "$WORK/libc3po/$file"
  if scan; then fail "$name: the scan passed"; return; fi
  grep -q "$pattern" "$WORK/scan.log" || fail "$name: the message lacks '$pattern': $(head -3 "$WORK/scan.log")"
  echo "ok: $name: $(grep -m1 "$pattern" "$WORK/scan.log")"
}

expect_violation geometry_includes_web geometry/src/mesh.cpp '#include "c3po/web/report.hpp"' 'geometry/src/mesh.cpp: layer geometry includes "c3po/web/'
expect_violation base_includes_geometry base/include/c3po/base/types.hpp '#  include "c3po/geometry/mesh.hpp"' 'base/types.hpp: layer base includes "c3po/geometry/'
expect_violation method_includes_eval method/src/pipeline.cpp '#include "c3po/eval/metrics.hpp"' 'layer method includes "c3po/eval/'
expect_violation synth_includes_sibling_authoring synth/src/synth.cpp '#include "c3po/authoring/annotate.hpp"' 'layer synth includes "c3po/authoring/'
expect_violation method_includes_plugins method/src/detector.cpp '#include "c3po/plugins/registry.hpp"' 'layer method includes "c3po/plugins/'
expect_violation relative_include io/src/dataset.cpp '#include "../../web/src/report_svg.hpp"' 'io/src/dataset.cpp: relative include'
expect_violation stray_folder stray/src/x.cpp '// a source outside every layer' 'stray: C++ sources in a folder that is not a layer'

# Allowed includes stay allowed: a higher layer including a lower one.
fresh
printf '%s\n' '#include "c3po/base/types.hpp"' >> "$WORK/libc3po/web/src/report.cpp"
scan || fail "an allowed downward include was reported: $(cat "$WORK/scan.log")"

rm -rf "$WORK"
echo "failures: $failures"
[ $failures -eq 0 ]
