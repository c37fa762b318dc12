# Shared checks of the CLI tests (sourced; the sourcing script defines
# fail MESSAGE, which may exit or only count the failure).

# expect_bad_input OUTPUT PATTERN COMMAND [ARG...]
# Runs COMMAND and checks the bad-input contract: exit status 2, one line on
# stderr ("c3po COMMAND: ...", command-line errors included) that mentions PATTERN (""
# for any), and nothing lost or left: OUTPUT (a file or folder; "-" when the
# command writes none) does not exist afterwards, nor a temporary sibling
# (".NAME.tmp.PID.N" of a file, ".NAME.partial.PID" of a folder). stdout and stderr stay in bad_input.out and
# bad_input.err for further checks.
expect_bad_input() {
  local out=$1 pattern=$2; shift 2
  local status=0
  "$@" > bad_input.out 2> bad_input.err || status=$?   # (callers may run under set -e)
  [ "$status" -eq 2 ] || { cat bad_input.out bad_input.err; fail "exit $status (expected 2) for: $*"; return 1; }
  [ "$(wc -l < bad_input.err)" -eq 1 ] && grep -q '^c3po' bad_input.err ||
    { cat bad_input.err; fail "expected one line on stderr for: $*"; return 1; }
  grep -q -- "$pattern" bad_input.err ||
    { cat bad_input.err; fail "message should mention '$pattern' for: $*"; return 1; }
  if [ "$out" != - ]; then
    [ ! -e "$out" ] || { fail "$out left behind for: $*"; return 1; }
    if ls -a "$(dirname "$out")" | grep -qE "^\.$(basename "$out")\.(tmp|partial)\."; then
      fail "temporary output left behind for: $*"; return 1
    fi
  fi
  return 0
}
