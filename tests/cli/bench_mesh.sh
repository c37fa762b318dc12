#!/usr/bin/env bash
# c3po bench mesh: loads bundled meshes in several formats and reports the
# vertex and triangle counts the files hold (counted here with grep/awk), and
# a clear exit-2 error for a missing or unreadable mesh.
# Usage: bench_mesh.sh C3PO_BIN SOURCE_DIR WORK_DIR
set -euo pipefail
C3PO=$(realpath "$1"); SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK"; mkdir -p "$WORK"; cd "$WORK"
fail() { echo "FAIL: $*"; exit 1; }

MUG="$SRC/annotations/mug.obj"
vertices=$(grep -c '^v ' "$MUG"); faces=$(grep -c '^f ' "$MUG")
# The same mesh as an OFF file (indices from 0), written here with awk.
awk -v nv="$vertices" -v nf="$faces" 'BEGIN { print "OFF"; print nv, nf, 0 }
  /^v / { print $2, $3, $4 } /^f / { f[++n] = "3 " ($2 - 1) " " ($3 - 1) " " ($4 - 1) }
  END { for (i = 1; i <= n; ++i) print f[i] }' "$MUG" > mug.off

"$C3PO" bench mesh "$MUG" mug.off --seconds 0.05 > out.txt 2> err.txt || { cat out.txt err.txt; fail "bench mesh exited with $?"; }
[ "$(wc -l < out.txt)" -eq 2 ] || { cat out.txt; fail "expected one line per mesh"; }
for file in "$MUG" mug.off; do
  line=$(grep -F "mesh $file:" out.txt) || { cat out.txt; fail "no line for $file"; }
  grep -q ": $vertices vertices, $faces triangles, .* ms per load = .* MB/s" <<< "$line" \
    || fail "$file: expected $vertices vertices and $faces triangles: $line"
done

# Bad input: exit 2, one line naming the file.
status=0; "$C3PO" bench mesh missing.obj > out.txt 2> err.txt || status=$?
[ "$status" -eq 2 ] || fail "missing mesh: exit $status, expected 2"
[ "$(wc -l < err.txt)" -eq 1 ] && grep -q "missing.obj: mesh file not found" err.txt || { cat err.txt; fail "unclear error"; }
printf 'OFF\n3 99999999999 0\n0 0 0\n1 0 0\n0 1 0\n' > lying.off
status=0; "$C3PO" bench mesh lying.off > out.txt 2> err.txt || status=$?
[ "$status" -eq 2 ] && grep -q "lying.off: truncated: header says 99999999999 faces" err.txt || { cat err.txt; fail "lying OFF: exit $status"; }
echo "bench_mesh: ok"
