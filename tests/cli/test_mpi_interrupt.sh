#!/usr/bin/env bash
# `mpirun -n 2 fovea render` interrupted (issue 42, item 4): a signal on any rank ends the job as
# it ends one process, "fovea render: interrupted (SIGTERM)" said once (not once per rank, not
# "rank 1: fovea render: render cancelled"), every rank exiting 128 + the signal, no temporary.
# Skipped (exit 77) where fovea was built without MPI or mpirun is missing.
. "$(dirname "$0")/lib.sh"
fv_mpi_setup
# Job control: the launcher and its ranks keep SIGINT (a background job of a shell without it
# starts with SIGINT ignored, which fovea respects).
set -m
cd "$TMP" || exit 1

# stopped SIG WHO ARGS...: a 2-rank render of ARGS, each rank's pid in pid.R; one second into its
# render (past the set-up) SIG goes to rank 1 (WHO=one) or to both ranks at once (both, as a terminal's Ctrl-C).
stopped() {
  local sig=$1 who=$2 what
  shift 2
  what="SIG$sig to $who rank(s), $*"
  cat >rank.sh <<EOS
echo \$\$ >"pid.\$OMPI_COMM_WORLD_RANK"
exec "$FOVEA" render cornell --size 128x128 --threads 1 --quiet $* --out "$TMP/out/k.png"
EOS
  rm -rf pid.* out
  mkdir out
  "${MPIENV[@]}" mpirun -q --oversubscribe --bind-to none -n 2 bash rank.sh >job.out 2>&1 &
  local job=$!
  for _ in $(seq 100); do [ -s pid.1 ] && [ -s pid.0 ] && break; sleep 0.1; done
  sleep 1.5
  if [ "$who" = both ]; then
    kill -"$sig" "$(cat pid.0)" "$(cat pid.1)" || fail "$what: no ranks to signal"
  else
    kill -"$sig" "$(cat pid.1)" || fail "$what: no rank 1 to signal"
  fi
  wait "$job"
  local rc=$? want=$((128 + $(kill -l "$sig")))
  [ "$rc" = "$want" ] || fail "$what: exit status $rc, expected $want: $(head -c 400 job.out)"
  [ "$(cat job.out)" = "fovea render: interrupted (SIG$sig)" ] || fail "$what: not the one line: $(head -c 600 job.out)"
  local left
  left=$(find out -name '*.tmp.*')
  [ -z "$left" ] || fail "$what: temporary files left: $left"
}

# A split still (pt's samples over both ranks): no image.
stopped TERM one --spp 20000
[ -e out/k.png ] && fail "an interrupted split still wrote its image"
stopped INT both --spp 20000
[ -e out/k.png ] && fail "an interrupted split still wrote its image"
# A split sequence (each rank its block of frames).
stopped TERM one --spp 3000 --frames 4
stopped INT both --spp 3000 --frames 4
finish
