#!/usr/bin/env bash
# The quality runs of the detector/self-training issue: for each object, a
# PointNet detector trained on 6000 simulated clouds, self-trained on 2000
# unlabelled depth clouds (1 mm noise, n = 1000) and evaluated on 200 held-out
# depth clouds (`c3po demo` runs and prints every step and its time).
#
# Usage: bash scripts/quality.sh [OUT_DIR] [OBJECT ...]
# OBJECT is mug, drill (bundled), ycb_drill or ycb_mustard (needs
# ../shared/data/ycb); default: all four. Extra demo options via
# QUALITY_OPTIONS, e.g. QUALITY_OPTIONS="--pose hard".
set -euo pipefail
cd "$(dirname "$0")/.."
C3PO=${C3PO:-./build/bin/c3po}
OUT=${1:-quality_out}
shift || true
OBJECTS=("$@")
[ ${#OBJECTS[@]} -gt 0 ] || OBJECTS=(mug drill ycb_drill ycb_mustard)
for name in "${OBJECTS[@]}"; do
  case "$name" in
    mug | drill | ycb_drill | ycb_mustard) ;;
    *) echo "quality.sh: unknown object '$name' (mug, drill, ycb_drill, ycb_mustard)" >&2; exit 2 ;;
  esac
done
YCB=../shared/data/ycb
mkdir -p "$OUT"

object_file() {
  case "$1" in
    mug | drill) echo "annotations/$1.json" ;;
    ycb_drill | ycb_mustard)
      local folder=035_power_drill
      [ "$1" = ycb_mustard ] && folder=006_mustard_bottle
      if [ ! -f "$YCB/$folder/textured.obj" ]; then
        echo "skipping $1: $YCB/$folder is absent" >&2
        return 1
      fi
      "$C3PO" annotate "$YCB/$folder/textured.obj" -o "$OUT/$1.json" --object-name "$folder" \
        --from-json "$YCB/$folder/keypoints.json" --key farthest12 >&2
      echo "$OUT/$1.json" ;;
  esac
}

for name in "${OBJECTS[@]}"; do
  object=$(object_file "$name") || continue
  # shellcheck disable=SC2086
  "$C3PO" demo --object "$object" --out "$OUT/$name" --sim-count 6000 --depth-train 2000 \
    --depth-test 200 --train-epochs 15 --selftrain-epochs 20 --seed 1 ${QUALITY_OPTIONS:-} \
    | tee "$OUT/$name.log"
done
