# Sourced by tests/cli/*.sh: strict mode, a scratch directory, and assertions.
set -euo pipefail
: "${AMGSPLAT:?AMGSPLAT must name the amgsplat binary}"
name=$(basename "${BASH_SOURCE[1]}" .sh)
T="${ASP_TEST_TMP:-/tmp/amgsplat-test}/$name"
rm -rf "$T"
mkdir -p "$T"

fail() { echo "FAIL: $*" >&2; exit 1; }

# Models from ../shared/data that a test could not find. A script that needed one ends with status
# 77, which ctest lists as "Skipped" (SKIP_RETURN_CODE in CMakeLists.txt), never as passed without
# the checks it could not make; a failure still wins. EXIT trap, so a script needs no epilogue.
asp_skipped=()
trap 'asp_st=$?; if ((asp_st == 0 && ${#asp_skipped[@]} > 0)); then
  echo "SKIPPED: test models not found: ${asp_skipped[*]}" >&2; exit 77; fi' EXIT

# have_data NAME...: true when every NAME is readable in $ASP_TEST_DATA; otherwise records the
# missing ones (the script then ends as SKIPPED) and returns 1, so: if have_data x.obj; then ...; fi
have_data() {
  local n ok=0
  for n in "$@"; do
    if [[ ! -r "${ASP_TEST_DATA:-/nonexistent}/$n" ]]; then
      asp_skipped+=("${ASP_TEST_DATA:-(ASP_TEST_DATA unset)}/$n")
      ok=1
    fi
  done
  return $ok
}
# Pipes into grep use `grep PATTERN >/dev/null`, never `grep -q`: -q exits at the first match, the
# writer may then die of SIGPIPE, and pipefail turns that into a failure (it did, once the render
# usage text grew).

# expect_fail STATUS SUBSTRING cmd...: the command must exit with STATUS and print SUBSTRING on stderr.
expect_fail() {
  local want=$1 text=$2; shift 2
  local st=0
  "$@" >"$T/out" 2>"$T/err" || st=$?
  [[ $st -eq $want ]] || fail "'$*' exited $st, expected $want; stderr: $(cat "$T/err")"
  grep -qF -- "$text" "$T/err" || fail "'$*' stderr lacks '$text': $(cat "$T/err")"
}

# expect_exit STATUS cmd...: the command must exit with STATUS; its stdout and stderr are left in
# $T/out and $T/err for further checks.
expect_exit() {
  local want=$1; shift
  local st=0
  "$@" >"$T/out" 2>"$T/err" || st=$?
  [[ $st -eq $want ]] || { cat "$T/err" >&2; fail "'$*' exited $st, expected $want"; }
}

# check FILE EXPR: asserts a Python expression over a PNG's pixels (see png_check.py).
check() { python3 "$(dirname "${BASH_SOURCE[0]}")/png_check.py" "$1" "$2" || fail "$1: $2"; }
