#!/usr/bin/env bash
# The long fuzz run (docs/fuzzing.md): every input kind for COUNT inputs (the OBJ importer, the
# slowest, for a third of that), in the background-friendly way: nice, one kind after another.
#   bash tests/fuzz/run-long.sh FUZZ_BINARY [COUNT] [OUTDIR] [SEED] [KINDS]
# KINDS (e.g. "obj", to run the slow kind beside the others on a second core): default all.
# FUZZ_BINARY is build/tests/fovea-fuzz (Release is ~3x faster; build-asan's adds the sanitizers).
# Exit status 1 when any kind had a finding (listed in OUTDIR/findings.txt).
set -u
FUZZ=${1:?usage: run-long.sh FUZZ_BINARY [COUNT] [OUTDIR] [SEED]}
COUNT=${2:-100000}
OUT=${3:-fuzz-long}
SEED=${4:-1}
KINDS=${5:-}
mkdir -p "$OUT"
rc=0
kinds=${KINDS:-$("$FUZZ" --kind list 2>&1 | sed -n 's/^kinds: //p')}
for k in $kinds; do
  n=$COUNT
  [ "$k" = obj ] && n=$((COUNT / 3))
  nice -n 19 "$FUZZ" --kind "$k" --count "$n" --seed "$SEED" --timeout 120 --out "$OUT" | grep -v '^total' | tee -a "$OUT/summary.txt" || rc=1
done
awk '{n += $2} END {print "inputs in all:", n}' "$OUT/summary.txt" | tee -a "$OUT/summary.txt"
exit $rc
