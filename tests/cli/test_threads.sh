# The thread policy (docs/threads.md) as the OpenMP runtime itself reads it: libgomp prints the
# values it parsed at start-up when OMP_DISPLAY_ENV=verbose, so the last such block of a run is
# what the render ran under (the first one is the run before fovea executed itself again).
# Checks each policy's variables, that the user's own variables and FOVEA_THREAD_POLICY are
# honoured, that --thread-policy openmp changes nothing, bad names, and the --stats line.
# Run as `bash test_threads.sh FOVEA SRCDIR BUILDDIR`.
. "$(dirname "$0")/lib.sh"
R=(render --size 16x16 --spp 1 --quiet --out "$TMP/a.png")

# the value libgomp reports for variable $1 in the last block of file $2
seen() { awk -v k="$1" '/DISPLAY ENVIRONMENT BEGIN/ {delete v} $1 == k {v[k] = $3} END {print v[k]}' "$2" | tr -d "'"; }
blocks() { grep -c 'DISPLAY ENVIRONMENT BEGIN' "$1"; }
run() { env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT -u OMP_NUM_THREADS -u FOVEA_THREAD_POLICY -u FOVEA_THREAD_PLAN \
        OMP_DISPLAY_ENV=verbose "$@" >"$TMP/out" 2>"$TMP/err" || fail "'$*' exited $?: $(tail -n 3 "$TMP/err")"; }
check() { # check WHAT VAR EXPECTED
  local got; got=$(seen "$2" "$TMP/err")
  [ "$got" = "$3" ] || fail "$1: libgomp read $2=$got, expected $3"
}
CPUS=$(nproc)

run "$FOVEA" "${R[@]}" --thread-policy pace
check pace OMP_WAIT_POLICY ACTIVE
check pace GOMP_SPINCOUNT 4000000
check pace OMP_NUM_THREADS "$CPUS"
[ "$(blocks "$TMP/err")" = 2 ] || fail "pace: expected one re-execution (two start-up blocks), got $(blocks "$TMP/err")"

run "$FOVEA" "${R[@]}" --thread-policy=share
check share OMP_WAIT_POLICY PASSIVE
check share GOMP_SPINCOUNT 0
n=$(seen OMP_NUM_THREADS "$TMP/err")
[ "$n" -ge 1 ] && [ "$n" -le "$CPUS" ] || fail "share: OMP_NUM_THREADS=$n not in [1, $CPUS]"

# auto: whatever the load, a thread count within the machine and one of the two wait plans
run "$FOVEA" "${R[@]}"
w=$(seen OMP_WAIT_POLICY "$TMP/err") s=$(seen GOMP_SPINCOUNT "$TMP/err")
[ "$w/$s" = ACTIVE/4000000 ] || [ "$w/$s" = PASSIVE/0 ] || fail "auto: unexpected wait plan $w/$s"

# the environment instead of the option; the option wins over it
run env FOVEA_THREAD_POLICY=share "$FOVEA" "${R[@]}"
check FOVEA_THREAD_POLICY=share OMP_WAIT_POLICY PASSIVE
run env FOVEA_THREAD_POLICY=share "$FOVEA" "${R[@]}" --thread-policy pace
check "--thread-policy over FOVEA_THREAD_POLICY" OMP_WAIT_POLICY ACTIVE

# the user's own variables are kept: the wait pair as one, the thread count alone
run env OMP_WAIT_POLICY=passive "$FOVEA" "${R[@]}" --thread-policy pace
check "user's OMP_WAIT_POLICY" OMP_WAIT_POLICY PASSIVE
check "user's OMP_WAIT_POLICY" GOMP_SPINCOUNT 0
run env GOMP_SPINCOUNT=1234 "$FOVEA" "${R[@]}" --thread-policy pace
check "user's GOMP_SPINCOUNT" GOMP_SPINCOUNT 1234
run env OMP_NUM_THREADS=1 "$FOVEA" "${R[@]}" --thread-policy pace
check "user's OMP_NUM_THREADS" OMP_NUM_THREADS 1
check "user's OMP_NUM_THREADS" OMP_WAIT_POLICY ACTIVE

# openmp: fovea sets nothing and does not execute itself again; libgomp's defaults
run "$FOVEA" "${R[@]}" --thread-policy openmp
[ "$(blocks "$TMP/err")" = 1 ] || fail "openmp: fovea executed itself again"
check openmp GOMP_SPINCOUNT 300000

# bench takes the option too (it renders)
run "$FOVEA" bench --thread-policy share --list
check "bench --thread-policy share" OMP_WAIT_POLICY PASSIVE

# --stats says which plan the render ran under
"$FOVEA" render --size 16x16 --spp 1 --out "$TMP/a.png" --thread-policy share --stats 2>"$TMP/err" >/dev/null
grep -q '^  threads: [0-9]* (share: .* OMP_WAIT_POLICY=passive GOMP_SPINCOUNT=0' "$TMP/err" ||
  fail "--stats lacks the thread plan: $(cat "$TMP/err")"

# fovea bench scaling: a row per thread count with the regions a frame opened, the report whole
"$FOVEA" bench scaling --methods vpolar,pt --size 16x12 --frames 2 --warmup 0 --max-threads 2 --quiet \
  --report "$TMP/scaling.md" >"$TMP/out" 2>"$TMP/err" || fail "bench scaling exited $?: $(cat "$TMP/err")"
for m in pt vpolar; do
  for t in 1 2; do
    grep -Eq "^\| $m \| cornell \| $t \| [0-9.]+ \| [0-9.]+ \|.* \| [1-9][0-9]* \|$" "$TMP/out" ||
      fail "bench scaling: no row for $m at $t threads: $(cat "$TMP/out")"
  done
done
cmp -s "$TMP/out" "$TMP/scaling.md" || fail "bench scaling: the report differs from what it printed"
# the measured serial %% of every row (the column before regions/frame) and of vpolar's stages at the
# most threads, each a share in [0, 100]
awk -F'|' '/^\| (pt|vpolar) \| cornell/ {if ($11 !~ /%/) bad=1; v=$11; gsub(/[ %]/, "", v); if (v == "" || v+0 < 0 || v+0 > 100) bad=1; n++}
  END {exit !(n == 4 && !bad)}' "$TMP/out" || fail "bench scaling: a row's serial % is missing or outside [0, 100]: $(cat "$TMP/out")"
grep '^| vpolar |' "$TMP/out" | tail -n 1 | grep -oE '[a-z_]+: [0-9.-]+%, [0-9.]+%' | awk -F', ' '{v=$2; sub(/%/, "", v); if (v+0 < 0 || v+0 > 100) bad=1; n++}
  END {exit !(n >= 3 && !bad)}' || fail "bench scaling: vpolar's stages have no measured serial %: $(cat "$TMP/out")"
expect 2 "unknown method 'nope'" -- "$FOVEA" bench scaling --methods vpolar,nope
expect 2 "--frames 0: expected an integer in [1, 100000]" -- "$FOVEA" bench scaling --frames 0
expect 2 "unexpected argument 'x'" -- "$FOVEA" bench scaling x

# bad input: one line, exit 2, naming where the name came from
expect 2 "--thread-policy fast: expected auto, pace, share or openmp" -- "$FOVEA" "${R[@]}" --thread-policy fast
expect 2 "FOVEA_THREAD_POLICY spin: expected auto" -- env FOVEA_THREAD_POLICY=spin "$FOVEA" "${R[@]}"
expect 2 "--thread-policy : expected" -- "$FOVEA" "${R[@]}" --thread-policy ""
finish
