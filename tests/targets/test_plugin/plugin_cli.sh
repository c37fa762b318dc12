#!/usr/bin/env bash
# c3po --version and --plugin through the CLI: the version line agrees with
# the project VERSION and plugin_api.h (read here independently); a working
# plugin is used by certify; a plugin built for another ABI version, a library
# without the entry point and a missing file are each refused with one line
# on stderr and exit 2.
# Usage: plugin_cli.sh C3PO_BIN SOURCE_DIR WORK_DIR PLUGIN BAD_ABI_PLUGIN NOT_A_PLUGIN
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
PLUGIN=$(realpath "$4"); BAD_ABI=$(realpath "$5"); NOT_A_PLUGIN=$(realpath "$6")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
fail() { echo "FAIL: $*"; exit 1; }

version=$(sed -n 's/^project(c3po VERSION \([0-9]*\.[0-9]*\.[0-9]*\).*/\1/p' "$SRC/CMakeLists.txt")
abi=$(sed -n 's/^#define C3PO_PLUGIN_ABI_VERSION \([0-9]*\)$/\1/p' "$SRC/plugins/include/c3po/plugins/plugin_api.h")
[[ -n $version && -n $abi ]] || fail "cannot read the version sources"
[[ $("$C3PO" --version) == "c3po $version (plugin ABI $abi)" ]] || fail "c3po --version: $("$C3PO" --version)"

OBJ="$SRC/annotations/mug.json"
"$C3PO" synth "$OBJ" -o clouds --kind depth --count 2 --pose easy --seed 5 > /dev/null

# The working test plugin ("centroid") loads and certify runs it (exit 0 or 1,
# one JSON line); its keypoints are checked in tests/unit/plugin_test.cpp.
status=0
"$C3PO" certify "$OBJ" clouds/000000.ply --plugin "$PLUGIN" --detector centroid --no-correct --json \
  > good.jsonl 2> good.err || status=$?
[[ $status -le 1 ]] || fail "working plugin: exit $status: $(cat good.err)"
[[ $(wc -l < good.jsonl) -eq 1 ]] || fail "working plugin: expected one JSON line"

refused() {   # NAME EXPECTED_TEXT ARGS...: exit 2, one line on stderr naming the file, nothing on stdout
  local name=$1 expected=$2; shift 2
  local status=0
  "$C3PO" certify "$OBJ" clouds/000000.ply --detector centroid "$@" > "$name.out" 2> "$name.err" || status=$?
  [[ $status -eq 2 ]] || fail "$name: exit $status, expected 2"
  [[ $(wc -l < "$name.err") -eq 1 ]] || fail "$name: expected one line on stderr: $(cat "$name.err")"
  [[ ! -s $name.out ]] || fail "$name: wrote to stdout"
  grep -qF -- "$expected" "$name.err" || fail "$name: '$(cat "$name.err")' lacks '$expected'"
}
refused bad_abi "$BAD_ABI: plugin built for c3po plugin ABI version 99, this c3po $version loads ABI version $abi" \
  --plugin "$BAD_ABI"
refused not_a_plugin "$NOT_A_PLUGIN: not a c3po plugin: no symbol c3po_detector_plugin_v1" --plugin "$NOT_A_PLUGIN"
refused missing "$WORK/no_such_plugin.so: no such plugin file" --plugin "$WORK/no_such_plugin.so"
echo "plugin_cli: ok"
