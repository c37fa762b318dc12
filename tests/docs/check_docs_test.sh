#!/usr/bin/env bash
# The docs check (check_docs.py) can fail: a planted doc with one missing item
# of each kind (a path, a link, a C++ name, an option of a command, of a bench
# subcommand, an option named alone, a JSON key, a doc section) fails with a line naming each, and the
# existing items beside them are not reported.
# Usage: check_docs_test.sh C3PO_EXE SOURCE_DIR WORK_DIR   (ctest: docs_check_detects_drift)
set -u
EXE=$1; SRC=$(realpath "$2"); WORK=$(realpath -m "$3")
rm -rf "$WORK" && mkdir -p "$WORK"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

cat > "$WORK/planted.md" <<'DOC'
See `libc3po/method/src/no_such_step.cpp` and [the notes](docs/nowhere.md); `method/free_space.cpp` exists.
`NoSuchFunction` computes it; `CheckWeakMotion` exists.
c3po certify drill.json --data d --no-such-option --max-outliers 2%
c3po bench corrector drill.json --data d --bogus-flag
The option `--not-an-option 3` and `--reestimate` (exists).
The key `KEY`; `free_space_shift_px` exists, and `my_out_dir` is made below.
See docs/method.md "SECTION" and docs/method.md "Weak motion" (exists).

```sh
c3po synth drill.json -o my_out_dir --count 3
```
DOC
# A key and a section that no source has: not written whole here (this script is a source).
KEY="never_written$((6 * 7))_key"
SECTION="Never written $((6 * 7))"
sed -i "s/\`KEY\`/\`$KEY\`/; s/\"SECTION\"/\"$SECTION\"/" "$WORK/planted.md"
python3 "$SRC/tests/docs/check_docs.py" "$EXE" "$SRC" "$WORK/planted.md" > "$WORK/out.txt" 2> "$WORK/err.txt"
status=$?
[ "$status" = 1 ] || fail "exit status $status, expected 1: $(cat "$WORK/err.txt")"
for expected in 'planted.md:1: names `libc3po/method/src/no_such_step.cpp`' \
                'planted.md:1: names docs/nowhere.md, which is not a doc' \
                'planted.md:2: names `NoSuchFunction`' \
                'planted.md:3: gives `c3po certify` the option --no-such-option' \
                'planted.md:4: gives `c3po bench corrector` the option --bogus-flag' \
                'planted.md:5: names the option --not-an-option' \
                "planted.md:6: names \`$KEY\`" \
                "planted.md:7: refers to docs/method.md \"$SECTION\""; do
  grep -qF -- "$expected" "$WORK/out.txt" || fail "no line '$expected' in: $(cat "$WORK/out.txt")"
done
lines=$(wc -l < "$WORK/out.txt")
[ "$lines" = 8 ] || fail "$lines lines, expected 8 (an existing item was reported): $(cat "$WORK/out.txt")"
[ "$failures" = 0 ] && echo "ok: the planted doc's eight missing items are named, nothing else"
exit $((failures > 0))
