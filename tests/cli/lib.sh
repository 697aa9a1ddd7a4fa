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

# For the MPI tests (test_mpi.sh, test_mpi_interrupt.sh): skips (exit 77) where fovea was built
# without MPI or mpirun is missing; lets OpenMPI run as root (CI does: it refuses unless told
# twice); sets MPIENV, the command prefix of the ranks: under the sanitizers (scripts/test),
# OpenMPI's own allocations, made by components it unloads at MPI_Finalize, are reported as leaks
# LeakSanitizer cannot attribute or suppress by library, so the ranks run with leak detection off
# (AddressSanitizer and UBSan stay on); one-process renders keep it.
fv_mpi_setup() {
  if [ "${FV_HAVE_MPI:-OFF}" != ON ] || ! command -v mpirun >/dev/null; then
    echo "skipped: fovea built without MPI (FOVEA_MPI) or no mpirun"
    exit 77
  fi
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  MPIENV=()
  if [ "${FOVEA_SANITIZED:-0}" = 1 ]; then
    MPIENV=(env "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0")
  fi
}
