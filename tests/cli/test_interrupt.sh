# fovea CLI: SIGINT and SIGTERM (issue 25, item 9), and SIGHUP, SIGPIPE, SIGQUIT, SIGUSR1, SIGUSR2 and
# SIGALRM handled alike (issue 42, item 3; 128 + the signal's number). An interrupted command prints one line
# ("fovea render: interrupted (SIGINT)"), exits 130 (SIGINT) or 143 (SIGTERM), leaves no
# temporary file of the atomic writer (*.tmp.*) and no partial output, and no child process (a
# mesh import's sandbox child dies with it). tools/fovea/cli.h describes the two ways a command
# stops: at its next cancellation point (a render), or at once (loading, bench).
. "$(dirname "$0")/lib.sh"
# Job control: background jobs keep SIGINT (a shell without it starts them with SIGINT ignored,
# which fovea respects) and each leads its own process group.
set -m

D="$TMP/outdir"
mkdir -p "$D"

no_temps() {
  local left
  left=$(find "$1" -name '*.tmp.*' | head -5)
  [ -z "$left" ] || fail "$2: temporary files left: $left"
}

# started COMMAND...: runs it in the background, stderr to $TMP/err; PID is its process id.
started() {
  "$@" >/dev/null 2>"$TMP/err" &
  PID=$!
}

# ended SIG WHAT: waits for PID, which was sent SIG (INT, TERM, HUP, ...); checks the exit status
# (128 + the signal's number) and the one line on stderr.
ended() {
  local sig=$1 what=$2 want got
  want=$((128 + $(kill -l "$sig")))
  wait "$PID"
  got=$?
  [ "$got" = "$want" ] || fail "$what: exit status $got after SIG$sig, expected $want; stderr: $(head -c 400 "$TMP/err")"
  local lines
  lines=$(grep -c '' "$TMP/err")
  [ "$lines" = 1 ] || fail "$what: $lines lines on stderr, expected one: $(head -c 600 "$TMP/err")"
  grep -q "^fovea [a-z ]*: interrupted (SIG$sig)\$" "$TMP/err" || fail "$what: stderr lacks the interruption line: $(head -c 400 "$TMP/err")"
}

# wait_for SECONDS TEST...: polls (every 20 ms) until the test holds; false when it never did.
wait_for() {
  local n=$(($1 * 50))
  shift
  for ((k = 0; k < n; k++)); do
    "$@" && return 0
    sleep 0.02
  done
  return 1
}
temp_of() { compgen -G "$1.tmp.*" >/dev/null; }
has_child() { pgrep -P "$PID" >/dev/null; }

# ---- a render of several seconds, interrupted after one: no image, no temporary ----
for sig in INT TERM; do
  rm -rf "${D:?}"/*
  started $FOVEA render cornell --method pt --spp 64 --size 640x360 --threads 2 --out "$D/o.png"
  sleep 1
  kill -$sig $PID
  ended $sig "render, SIG$sig after 1 s"
  [ ! -e "$D/o.png" ] || fail "render, SIG$sig after 1 s: wrote o.png"
  no_temps "$D" "render, SIG$sig after 1 s"
done

# ---- a signal while a large image is written ----
# A scene whose rays all miss renders a 2048x2048 EXR (with its auxiliary layers) in a fraction of
# the second its writing takes. One signal lets the write finish (the frame is whole) and stops
# after it; a second stops at once and removes the temporary file.
printf 'v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nf 1 2 3\n' >"$TMP/tiny.obj"
W="$FOVEA render $TMP/tiny.obj --quiet --no-default-light --method pt --spp 1 --size 2048x2048 --threads 2 --camera-pos 0,5,0 --camera-look 0,10,0 --camera-up 1,0,0"
rm -rf "${D:?}"/*
started $W --out "$D/o.exr"
if wait_for 10 temp_of "$D/o.exr"; then
  kill -INT $PID
  ended INT "one SIGINT during a write"
  no_temps "$D" "one SIGINT during a write"
  [ -f "$D/o.exr" ] || fail "one SIGINT during a write: the frame being written was not finished"
  expect 0 "" -- $FOVEA compare "$D/o.exr" "$D/o.exr"
else
  kill -KILL $PID
  wait $PID
  fail "the EXR's temporary file never appeared"
fi
rm -rf "${D:?}"/*
started $W --out "$D/o.exr"
if wait_for 10 temp_of "$D/o.exr"; then
  kill -INT $PID
  sleep 0.05
  kill -INT $PID 2>/dev/null
  ended INT "two SIGINTs during a write"
  no_temps "$D" "two SIGINTs during a write"
  # Unless the write was done before the second signal came, there is no file.
  [ ! -e "$D/o.exr" ] || expect 0 "" -- $FOVEA compare "$D/o.exr" "$D/o.exr"
else
  kill -KILL $PID
  wait $PID
  fail "the EXR's temporary file never appeared"
fi

# ---- the other signals that ask a process to stop, during a write ----
# Each handled as SIGTERM is: sent twice while the EXR is written (the second stops at once), one
# line, 128 + the signal, no temporary. Before issue 42 each killed fovea by its default action,
# silently, leaving o.exr.tmp.XXXXXX.
W1="${W/2048x2048/1024x1024}"
for sig in HUP PIPE QUIT USR1 USR2 ALRM; do
  rm -rf "${D:?}"/*
  started $W1 --out "$D/o.exr"
  if wait_for 10 temp_of "$D/o.exr"; then
    kill -$sig $PID
    sleep 0.02
    kill -$sig $PID 2>/dev/null
    ended $sig "SIG$sig during a write"
    no_temps "$D" "SIG$sig during a write"
  else
    kill -KILL $PID
    wait $PID
    fail "SIG$sig: the EXR's temporary file never appeared"
  fi
done

# ---- a write to a closed pipe ----
# fovea's output goes to a reader that has already left: SIGPIPE ends it as above (the line on a
# stderr that is still open). env restores SIGPIPE's default where the test runs with it ignored
# (which fovea would respect: the write then fails instead).
dflt=()
env --default-signal=PIPE true 2>/dev/null && dflt=(env --default-signal=PIPE)
{
  sleep 0.5
  exec "${dflt[@]}" $FOVEA methods 2>"$TMP/err"
} | true
got=${PIPESTATUS[0]}
[ "$got" = 141 ] || fail "methods into a closed pipe: exit status $got, expected 141: $(head -c 400 "$TMP/err")"
[ "$(cat "$TMP/err")" = "fovea methods: interrupted (SIGPIPE)" ] || fail "methods into a closed pipe: stderr is not the one line: $(head -c 400 "$TMP/err")"
# The per-frame lines of a sequence, on a stderr whose reader has left: the render stops after the
# frame (as a deferred signal does), 141, no temporary.
rm -rf "${D:?}"/*
{
  sleep 0.5
  exec "${dflt[@]}" $FOVEA render cornell --method pt --spp 1 --size 32x32 --frames 4 --threads 2 --out "$D/s.png" 2>&1 >/dev/null
} | true
got=${PIPESTATUS[0]}
[ "$got" = 141 ] || fail "a render's progress into a closed pipe: exit status $got, expected 141"
no_temps "$D" "a render's progress into a closed pipe"

# ---- SIGTERM during a mesh import: the importer's child ends with fovea ----
# About a million triangles: assimp parses them for a second or more in its sandbox child.
awk 'BEGIN { n = 720
  for (i = 0; i < n; i++) for (j = 0; j < n; j++) printf "v %d %d %.1f\n", i, j, (i * j % 7) * 0.1
  for (i = 0; i < n - 1; i++) for (j = 0; j < n - 1; j++) { a = i * n + j + 1; printf "f %d %d %d\nf %d %d %d\n", a, a + 1, a + n, a + 1, a + n + 1, a + n } }' >"$TMP/big.obj"
rm -rf "${D:?}"/*
started $FOVEA render "$TMP/big.obj" --quiet --spp 1 --size 64x64 --out "$D/o.png"
if wait_for 10 has_child; then
  kids=$(pgrep -P $PID)
  kill -TERM $PID
  ended TERM "SIGTERM during a mesh import"
  # Gone or a zombie (dead; this container's init may not reap it) within a second.
  alive() {
    local k s
    for k in $kids; do
      s=$(ps -o stat= -p "$k" 2>/dev/null) || continue
      case "$s" in Z*) ;; *) return 0 ;; esac
    done
    return 1
  }
  wait_for 1 eval '! alive' || fail "SIGTERM during a mesh import: the importer's child ($kids) still runs: $(ps -o pid,stat,etime,args -p "$kids" 2>&1)"
  [ ! -e "$D/o.png" ] || fail "SIGTERM during a mesh import: wrote o.png"
else
  wait $PID
  fail "the mesh import started no child (or was done within 20 ms)"
fi

# ---- bench: stopped while it renders the reference, and while it measures ----
cat >"$TMP/slow.json" <<'EOF'
{"name": "slow", "scene": "cornell", "size": [256, 256], "frames": 1, "repeats": 1,
 "gaze": {"fixed": [0.5, 0.5]}, "reference": {"method": "pt", "params": {"spp": 512}},
 "methods": [{"label": "pt-4", "method": "pt", "params": {"spp": 4}}, {"label": "pt-256", "method": "pt", "params": {"spp": 256}}]}
EOF
for sig in INT TERM HUP; do
  rm -rf "${D:?}"/*
  started $FOVEA bench "$TMP/slow.json" --quiet --threads 2 --out "$D"
  sleep 1
  kill -$sig $PID
  ended $sig "bench, SIG$sig after 1 s"
  no_temps "$D" "bench, SIG$sig after 1 s"
  [ ! -e "$D/slow.json" ] && [ ! -e "$D/slow.md" ] || fail "bench, SIG$sig after 1 s: wrote a report"
done

finish
