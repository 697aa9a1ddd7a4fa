# Shared helpers of the CLI tests: each test script is run as `bash test_x.sh FOVEA SRCDIR BUILDDIR`.
set -u
FOVEA=$1
SRC=$2
TMP=$(mktemp -d /tmp/fovea-cli-XXXXXX)
trap 'rm -rf "$TMP"' EXIT
FAILS=0

fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }

# expect CODE NEEDLE -- command...: the exit status must be CODE and, for a failure, stderr must be
# exactly one line containing NEEDLE.
expect() {
  local code=$1 needle=$2
  shift 3
  "$@" >"$TMP/out" 2>"$TMP/err"
  local got=$?
  if [ "$got" != "$code" ]; then
    fail "'$*' exited $got, expected $code; stderr: $(head -c 400 "$TMP/err")"
    return
  fi
  if [ "$code" != 0 ]; then
    local lines
    lines=$(grep -c '' "$TMP/err")
    [ "$lines" = 1 ] || fail "'$*' printed $lines lines on stderr, expected one: $(cat "$TMP/err")"
    grep -qF -- "$needle" "$TMP/err" || fail "'$*' stderr lacks '$needle': $(cat "$TMP/err")"
  fi
}

finish() {
  if [ "$FAILS" -gt 0 ]; then
    echo "$FAILS check(s) failed"
    exit 1
  fi
  echo "all checks passed"
}
