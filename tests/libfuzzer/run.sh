#!/usr/bin/env bash
# Runs one libFuzzer target (docs/fuzzing.md): its starting corpus is the mutation fuzzer's seeds
# for the kind (`fovea-fuzz --kind KIND --seeds-out`), what libFuzzer adds goes to OUT/corpus-KIND
# (kept between runs), a finding to OUT/KIND-crash-... (libFuzzer's artifact names).
#   bash tests/libfuzzer/run.sh FOVEA_FUZZ TARGET KIND OUT [libFuzzer flags, e.g. -runs=3000]
# Exit status: libFuzzer's (0: no finding), or 1 when no input at all was accepted.
set -u
FUZZ=${1:?usage: run.sh FOVEA_FUZZ TARGET KIND OUT [flags]}
TARGET=${2:?} KIND=${3:?} OUT=${4:?}
shift 4
mkdir -p "$OUT/corpus-$KIND"
rm -rf "$OUT/seeds-$KIND"
"$FUZZ" --kind "$KIND" --seeds-out "$OUT/seeds-$KIND" >/dev/null || exit 2
# -malloc_limit_mb above the 3 GiB at which the target's allocator returns NULL (target.c), so a
# huge allocation is the library's to refuse; -timeout charges a hang to its input.
# The target's work folder goes in a folder of ours, removed however the target ends.
tmp=$(mktemp -d "$( [ -w /dev/shm ] && echo /dev/shm || echo /tmp )/fovea-lf-XXXXXX")
FOVEA_FUZZ_TMPDIR=$tmp "$TARGET" -artifact_prefix="$OUT/$KIND-" -timeout=60 -rss_limit_mb=4096 -malloc_limit_mb=4096 \
  -print_final_stats=1 "$@" "$OUT/corpus-$KIND" "$OUT/seeds-$KIND" 2>"$OUT/$KIND.log"
rc=$?
rm -rf "$tmp"
# The summary a reader wants: executions, time, speed, and the verdict.
runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$OUT/$KIND.log" | tail -1)
speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$OUT/$KIND.log" | tail -1)
cov=$(grep -o 'cov: [0-9]*' "$OUT/$KIND.log" | tail -1)
verdicts=$(sed -n 's/^fovea libfuzzer: [a-z]*: //p' "$OUT/$KIND.log" | tail -1)
echo "$KIND: ${runs:-?} executions, ${speed:-?} exec/s, ${cov:-cov: ?}, ${verdicts:-?}, exit $rc (log $OUT/$KIND.log)"
# 72: libFuzzer's status when stopped by SIGINT (a long run cut short by hand): no finding.
if [ "$rc" = 72 ]; then echo "$KIND: interrupted after ${runs:-?} executions, no finding"; exit 0; fi
if [ "$rc" != 0 ]; then tail -40 "$OUT/$KIND.log"; exit $rc; fi
# The seeds hold valid files of every kind: a target that accepts nothing fuzzes only its refusals.
case "$verdicts" in
  "0 inputs accepted"*) echo "$KIND: no input was accepted (the seeds' valid files were refused)"; exit 1 ;;
esac
exit 0
