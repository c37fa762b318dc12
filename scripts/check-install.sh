#!/usr/bin/env bash
# Checks c3po as users get it (issue 19), from an existing Release build
# (default build/; nothing of the project is rebuilt):
#   1. the README's "Use c3po from C++" and "Write a detector plugin" commands,
#      run exactly as written (they install into c3po-prefix/ and build the
#      examples in build-examples/, both removed afterwards);
#   2. the installed tree: GNU layout, only public headers, no absolute path
#      of the build machine in any installed file, still usable once moved;
#   3. one version: c3po --version, the CMake package version (and its
#      SameMinorVersion rule), c3po.pc, the plugin ABI of plugin_api.h;
#   4. the examples against oracles: certify_cloud agrees with
#      `c3po certify --detector svd`; the centroid plugin's keypoints are
#      centred on the cloud's centroid; a pkg-config build links;
#   5. the ABI check: the example plugin built against a plugin_api.h with
#      another ABI version is refused by the installed c3po (one line, exit 2);
#   6. the Debian package (cpack): name, version, Depends; extracted with
#      dpkg -x and run (c3po --version, annotate, synth, certify --detector svd
#      on a bundled object); with C3PO_CHECK_DPKG_INSTALL=1 (CI, as root) also
#      installed with dpkg -i and removed again, unless that would overwrite
#      a file on the system.
#
#   bash scripts/check-install.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
BUILD=${1:-build}
[[ -x $BUILD/bin/c3po ]] || { echo "check-install: $BUILD/bin/c3po is missing: build first (bash scripts/build.sh)" >&2; exit 2; }
for tool in cmake cpack pkg-config dpkg-deb python3; do
  command -v "$tool" > /dev/null || { echo "check-install: $tool is missing" >&2; exit 2; }
done

WORK=$(mktemp -d "${TMPDIR:-/tmp}/c3po-check-install.XXXXXX")
cleanup() { rm -rf "$WORK" "$ROOT/c3po-prefix" "$ROOT/build-examples" "$ROOT/centroid.jsonl"; }
trap cleanup EXIT
fail() { echo "check-install: FAIL: $*" >&2; exit 1; }
section() { echo "=== check-install: $*"; }

VERSION=$(sed -n 's/^project(c3po VERSION \([0-9]*\.[0-9]*\.[0-9]*\).*/\1/p' CMakeLists.txt)
ABI=$(sed -n 's/^#define C3PO_PLUGIN_ABI_VERSION \([0-9]*\)$/\1/p' plugins/include/c3po/plugins/plugin_api.h)
[[ -n $VERSION && -n $ABI ]] || fail "cannot read the project VERSION or C3PO_PLUGIN_ABI_VERSION"
echo "c3po $VERSION, plugin ABI $ABI"

# --- 1. The README's commands, verbatim ------------------------------------
section "README commands"
[[ ! -e c3po-prefix && ! -e build-examples ]] || fail "c3po-prefix/ or build-examples/ exists already; remove it"
readme_block() {   # the first ```sh block after the heading $1
  awk -v heading="$1" '
    $0 == heading { found = 1; next }
    found && /^```sh$/ { inside = 1; next }
    inside && /^```$/ { exit }
    inside { print }' README.md
}
for heading in "### Use c3po from C++" "### Write a detector plugin"; do
  block=$(readme_block "$heading")
  [[ -n $block ]] || fail "README.md: no sh block after '$heading'"
  echo "--- $heading"
  printf '%s\n' "$block"
  bash -euo pipefail -c "$block" > "$WORK/readme.log" 2>&1 || { cat "$WORK/readme.log"; fail "README block '$heading'"; }
done
tail -n 8 "$WORK/readme.log"

# --- 2. The installed tree -------------------------------------------------
section "installed tree"
PREFIX=$ROOT/c3po-prefix
for file in bin/c3po lib/libc3po_base.a lib/libc3po_web.a lib/libc3po_plugins.a lib/libc3po_detector_svd.a \
            include/c3po/base/version.hpp include/c3po/plugins/plugin_api.h include/c3po/method/pipeline.hpp \
            lib/cmake/c3po/c3poConfig.cmake lib/cmake/c3po/c3poConfigVersion.cmake lib/cmake/c3po/c3poTargets.cmake \
            lib/pkgconfig/c3po.pc share/c3po/annotations/mug.json share/c3po/annotations/mug.obj \
            share/doc/c3po/README.md share/doc/c3po/CHANGELOG.md share/doc/c3po/plugins.md \
            share/doc/c3po/help/c3po.txt share/doc/c3po/help/c3po-certify.txt; do
  [[ -e $PREFIX/$file ]] || fail "not installed: $file"
done
grep -q -- "--plugin" "$PREFIX/share/doc/c3po/help/c3po-certify.txt" || fail "help/c3po-certify.txt lacks --plugin"
# Exactly the public headers: every include/ folder of a layer or plugin, nothing from src/.
expected=$( (cd libc3po && for d in */include; do (cd "$d" && find . -name '*.hpp' -o -name '*.h'); done)
            for d in plugins/include plugins/*/include; do (cd "$d" && find . -name '*.hpp' -o -name '*.h'); done
            echo ./c3po/base/version.hpp) 
diff <(printf '%s\n' "$expected" | sed 's|^\./||' | sort) \
     <(cd "$PREFIX/include" && find . -type f | sed 's|^\./||' | sort) || fail "installed headers differ from the public ones (above)"
# Relocatable: no file holds the path of the prefix, the sources or the build.
if grep -rlF -e "$PREFIX" -e "$ROOT/libc3po" -e "$ROOT/plugins" -e "$ROOT/cli" -e "$ROOT/$BUILD" "$PREFIX"; then
  fail "the files above contain an absolute path of this machine"
fi
mv "$PREFIX" "$WORK/moved"
PREFIX=$WORK/moved

# --- 3. One version --------------------------------------------------------
section "versions"
[[ $("$PREFIX/bin/c3po" --version) == "c3po $VERSION (plugin ABI $ABI)" ]] ||
  fail "c3po --version says '$("$PREFIX/bin/c3po" --version)', expected 'c3po $VERSION (plugin ABI $ABI)'"
[[ $(PKG_CONFIG_PATH=$PREFIX/lib/pkgconfig pkg-config --modversion c3po) == "$VERSION" ]] || fail "c3po.pc version"
grep -q "^#define C3PO_PLUGIN_ABI_VERSION $ABI\$" "$PREFIX/include/c3po/plugins/plugin_api.h" || fail "installed plugin_api.h ABI"
mkdir -p "$WORK/find"
cat > "$WORK/find/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.25)
project(find_c3po LANGUAGES CXX)
find_package(c3po ${WANT} QUIET)
if(c3po_FOUND)
  get_target_property(type c3po::plugin_api TYPE)
  message(STATUS "FOUND c3po ${c3po_VERSION} ABI ${c3po_PLUGIN_ABI_VERSION} data ${c3po_DATA_DIR} plugin_api ${type}")
  foreach(target c3po::core c3po::base c3po::geometry c3po::io c3po::object c3po::method c3po::authoring
                 c3po::synth c3po::eval c3po::web c3po::plugins)
    if(NOT TARGET ${target})
      message(FATAL_ERROR "no target ${target}")
    endif()
  endforeach()
else()
  message(STATUS "NOT FOUND")
endif()
EOF
find_c3po() { cmake -S "$WORK/find" -B "$WORK/find/build-$1" -DWANT="$1" -DCMAKE_PREFIX_PATH="$PREFIX" 2>&1 | grep -E "FOUND|Error" || true; }
major_minor=${VERSION%.*}
found=$(find_c3po "$major_minor")
[[ $found == "-- FOUND c3po $VERSION ABI $ABI data $PREFIX/share/c3po plugin_api INTERFACE_LIBRARY" ]] ||
  fail "find_package(c3po $major_minor) from the moved prefix: '$found'"
next_minor="${VERSION%%.*}.$(( $(echo "$VERSION" | cut -d. -f2) + 1 ))"
[[ $(find_c3po "$next_minor") == "-- NOT FOUND" ]] || fail "find_package(c3po $next_minor) accepted $VERSION"
echo "$found; find_package(c3po $next_minor) refused"

# --- 4. The examples against oracles ---------------------------------------
# (They are compiled with default flags, the libraries with -march=native:
# they agree on Eigen's layout only through the exported EIGEN_MAX_ALIGN_BYTES;
# without it certify_cloud crashed with "double free or corruption".)
section "examples"
OBJECT=$PREFIX/share/c3po/annotations/drill.json
CLOUDS=$ROOT/build-examples/drill-clouds
cloud=$CLOUDS/000000.ply
status=0
"$ROOT/build-examples/certify_cloud/certify_cloud" "$OBJECT" "$cloud" > "$WORK/example.txt" || status=$?
[[ $status -le 1 ]] || fail "certify_cloud exit $status"
status=0
"$PREFIX/bin/c3po" certify "$OBJECT" "$cloud" --detector svd --json > "$WORK/cli.jsonl" || status=$?
[[ $status -le 1 ]] || fail "c3po certify exit $status"
python3 - "$WORK/example.txt" "$WORK/cli.jsonl" <<'EOF'
import json, re, sys
text = open(sys.argv[1]).read()
cli = json.loads(open(sys.argv[2]).readline())
certified = "CERTIFIED" in text.splitlines()[0]
t = [float(v) for v in re.search(r"t = \[([^\]]*)\]", text).group(1).split()]
assert certified == cli["certified"], (text, cli["certified"])
assert all(abs(a - b) < 1e-4 for a, b in zip(t, cli["t"])), (t, cli["t"])
print(f"certify_cloud agrees with c3po certify --detector svd: certified={certified}, t={t}")
EOF
# The centroid plugin (README block): without the corrector its keypoints are
# the model keypoints centred on the cloud's centroid (ASCII or binary PLY read here).
status=0
"$PREFIX/bin/c3po" certify "$OBJECT" "$cloud" --plugin "$ROOT/build-examples/detector_plugin/libcentroid_detector.so" \
  --detector centroid --no-correct --json > "$WORK/plugin.jsonl" || status=$?
[[ $status -le 1 ]] || fail "c3po certify --plugin exit $status"
[[ $(wc -l < "$ROOT/centroid.jsonl") -eq 3 ]] || fail "README plugin command: expected 3 JSON lines in centroid.jsonl"
python3 - "$cloud" "$WORK/plugin.jsonl" "$OBJECT" <<'EOF'
import json, struct, sys
data = open(sys.argv[1], "rb").read()
end = data.index(b"end_header\n") + len(b"end_header\n")
header = data[:end].decode().splitlines()
count = next(int(l.split()[2]) for l in header if l.startswith("element vertex"))
props = [l.split() for l in header if l.startswith("property")]
fmt = next(l.split()[1] for l in header if l.startswith("format"))
assert all(p[1] in ("float", "double", "float32", "float64") for p in props), props
if fmt == "ascii":
    rows = [list(map(float, l.split()[:3])) for l in data[end:].decode().splitlines()[:count]]
else:
    assert fmt == "binary_little_endian", fmt
    codes = "".join("f" if p[1] in ("float", "float32") else "d" for p in props)
    size = struct.calcsize("<" + codes)
    rows = [struct.unpack_from("<" + codes, data, end + i * size)[:3] for i in range(count)]
centroid = [sum(r[a] for r in rows) / count for a in range(3)]
line = json.loads(open(sys.argv[2]).readline())
keypoints = line["keypoints"]
mean = [sum(k[a] for k in keypoints) / len(keypoints) for a in range(3)]
assert all(abs(m - c) < 1e-6 for m, c in zip(mean, centroid)), (mean, centroid)
model = json.load(open(sys.argv[3]))["keypoints"]
model_mean = [sum(k[a] for k in model) / len(model) for a in range(3)]
for k, b in zip(keypoints, model):   # translated, not rotated
    assert all(abs((k[a] - mean[a]) - (b[a] - model_mean[a])) < 1e-6 for a in range(3)), (k, b)
print(f"centroid plugin: keypoint centroid {mean} = cloud centroid over {count} points")
EOF
# A non-CMake build through c3po.pc, linking every layer.
cat > "$WORK/pc.cpp" <<'EOF'
#include <cstdio>
#include "c3po/base/version.hpp"
#include "c3po/io/cloud_io.hpp"
#include "c3po/object/object_io.hpp"
int main(int argc, char** argv) {
  const c3po::ObjectModel object = c3po::LoadObject(argv[1]);
  const c3po::PointSet cloud = c3po::ReadCloud(argv[2]);
  std::printf("c3po %s: %d keypoints, %d points\n", C3PO_VERSION, object.num_keypoints(), static_cast<int>(cloud.cols()));
}
EOF
# shellcheck disable=SC2046
c++ "$WORK/pc.cpp" -o "$WORK/pc" $(PKG_CONFIG_PATH=$PREFIX/lib/pkgconfig pkg-config --cflags --libs c3po) ||
  fail "building against c3po.pc"
"$WORK/pc" "$OBJECT" "$cloud"

# --- 5. The plugin ABI check -----------------------------------------------
section "plugin ABI check"
mkdir -p "$WORK/abi/include/c3po/plugins"
OTHER_ABI=$((ABI + 1))
sed "s/^#define C3PO_PLUGIN_ABI_VERSION $ABI\$/#define C3PO_PLUGIN_ABI_VERSION $OTHER_ABI/" \
  "$PREFIX/include/c3po/plugins/plugin_api.h" > "$WORK/abi/include/c3po/plugins/plugin_api.h"
grep -q "C3PO_PLUGIN_ABI_VERSION $OTHER_ABI" "$WORK/abi/include/c3po/plugins/plugin_api.h" || fail "ABI edit"
c++ -std=c++17 -shared -fPIC -fvisibility=hidden -I"$WORK/abi/include" examples/detector_plugin/centroid_detector.cpp \
  -o "$WORK/libcentroid_other_abi.so"
status=0
"$PREFIX/bin/c3po" certify "$OBJECT" "$cloud" --plugin "$WORK/libcentroid_other_abi.so" --detector centroid \
  > "$WORK/abi.out" 2> "$WORK/abi.err" || status=$?
cat "$WORK/abi.err"
[[ $status -eq 2 ]] || fail "a plugin for ABI $OTHER_ABI: exit $status, expected 2"
[[ $(wc -l < "$WORK/abi.err") -eq 1 && ! -s $WORK/abi.out ]] || fail "a plugin for ABI $OTHER_ABI: not one line"
grep -q "libcentroid_other_abi.so: plugin built for c3po plugin ABI version $OTHER_ABI, this c3po $VERSION loads ABI version $ABI" \
  "$WORK/abi.err" || fail "a plugin for ABI $OTHER_ABI: message"

# --- 6. The Debian package -------------------------------------------------
section "Debian package"
(cd "$BUILD" && cpack -G DEB -B "$WORK/deb" > "$WORK/cpack.log" 2>&1) || { cat "$WORK/cpack.log"; fail "cpack"; }
deb=$(ls "$WORK"/deb/c3po_*.deb)
[[ $(basename "$deb") == "c3po_${VERSION}_$(dpkg --print-architecture).deb" ]] || fail "package file name $(basename "$deb")"
[[ $(dpkg-deb -f "$deb" Package) == c3po && $(dpkg-deb -f "$deb" Version) == "$VERSION" ]] || fail "package name/version"
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
for library in libassimp libspng libstdc++6 libc6; do
  [[ $depends == *"$library"* ]] || fail "Depends lacks $library"
done
# Every dependency is installed here (the package's executable runs below).
for package in $(echo "$depends" | tr ',' '\n' | sed 's/(.*)//; s/|.*//' | tr -d ' '); do
  dpkg-query -W -f='${Status}\n' "$package" 2> /dev/null | grep -q "install ok installed" ||
    fail "Depends names $package, which is not installed"
done
if dpkg-deb -c "$deb" | awk '{print $6}' | grep -E "build|$ROOT" | grep -v "^./usr/share/doc/c3po/"; then
  fail "the package holds build paths (above)"
fi
dpkg -x "$deb" "$WORK/root"
run_package() {   # the package's first steps, with the c3po executable $1 and its data folder $2
  local c3po=$1 data=$2 out=$3
  mkdir -p "$out"
  [[ $("$c3po" --version) == "c3po $VERSION (plugin ABI $ABI)" ]] || fail "$c3po --version"
  "$c3po" annotate "$data/annotations/box.obj" --auto 8 --seed 1 -o "$out/box.json" > /dev/null
  "$c3po" synth "$out/box.json" -o "$out/clouds" --kind depth --count 4 --pose easy --seed 2 > /dev/null
  local status=0
  "$c3po" certify "$out/box.json" --detector svd --data "$out/clouds" -o "$out/poses.jsonl" \
    > "$out/certify.txt" || status=$?
  [[ $status -le 1 ]] || fail "$c3po certify: exit $status"
  [[ $(wc -l < "$out/poses.jsonl") -eq 4 ]] || fail "$c3po certify: expected 4 JSON lines"
  tail -n 1 "$out/certify.txt"
}
run_package "$WORK/root/usr/bin/c3po" "$WORK/root/usr/share/c3po" "$WORK/extracted"
echo "dpkg -x: the extracted package runs"
if [[ ${C3PO_CHECK_DPKG_INSTALL:-0} == 1 ]]; then
  [[ $(id -u) -eq 0 ]] || fail "C3PO_CHECK_DPKG_INSTALL=1 needs root"
  clobbered=$(dpkg-deb -c "$deb" | awk '$1 !~ /^d/ {print substr($6, 2)}' | while read -r f; do [[ -e $f ]] && echo "$f"; done || true)
  if dpkg-query -W c3po > /dev/null 2>&1 || [[ -n $clobbered ]]; then
    echo "dpkg -i skipped: c3po is installed already or the package would overwrite: $clobbered"
  else
    dpkg -i "$deb"
    run_package /usr/bin/c3po /usr/share/c3po "$WORK/installed"
    dpkg -r c3po > /dev/null
    echo "dpkg -i: the installed package runs; removed again"
  fi
fi
section "all checks passed"
