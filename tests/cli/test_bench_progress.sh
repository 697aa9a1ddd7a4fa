# `fovea bench`'s progress within its steps (docs/bench.md): off a terminal, plain lines no more
# often than --progress-every (0 here: every change), each naming its step, its percentage and the
# frame; none for a step shorter than the default 20 s; none at all with --quiet; on a terminal
# one line redrawn in place and cleared before the next step's line. The reports are the same with
# or without it, timings apart.
. "$(dirname "$0")/lib.sh"
B="$FOVEA bench"
# two frames, so that each step has a frame to come after another; one thread, because within a
# frame only the pool's thread 0 reports its tiles (core/parallel.c): with two, a loaded machine
# may give the other thread every tile, and the lines within a frame would depend on scheduling
RUN="--scene cornell --methods pt:spp=1,pt:spp=2 --reference pt:spp=16 --frames 2 --size 32x32 --repeats 1 --threads 1"

expect 0 "" -- $B $RUN --out "$TMP/p" --progress-every 0
cp "$TMP/err" "$TMP/progress.err"
python3 - "$TMP/progress.err" <<'PY' || fail "the progress lines off a terminal are wrong: $(head -c 3000 "$TMP/progress.err")"
import re, sys
text = open(sys.argv[1]).read()
assert "\r" not in text, "a carriage return in a log"
lines = text.splitlines()
prog = re.compile(r"^fovea bench: (.*): (\d+)%, frame (\d+)/(\d+), \d+(?:s|m\d\ds|h\d\dm) elapsed(?:, ETA \S+)?$")
steps = {}    # step -> the percentages said, in order
status = []   # the status lines, in order
for l in lines:
    m = prog.match(l)
    if m:
        step, pc, k, n = m.group(1), int(m.group(2)), int(m.group(3)), int(m.group(4))
        # every progress line belongs to the status line just before it (its step)
        assert status and status[-1] == step, (l, status[-1:])
        assert 1 <= k <= n, l
        steps.setdefault(step, []).append((pc, k, n))
    elif not l.startswith("fovea: warning: "):
        assert l.startswith("fovea bench: "), l
        status.append(l[len("fovea bench: "):])
ref = "reference: rendering 2 frame(s) with pt (0 cached)"
probe = "reference noise: probing with spp=4 on its own stream"
reps = ["[1/2] pt: repeat 1/1, 2 frame(s)", "[2/2] pt-2: repeat 1/1, 2 frame(s)"]
for s in [ref, probe] + reps:
    assert s in status, (s, status)
    said = steps.get(s)
    assert said, ("no progress for", s)
    pcs = [p for p, _, _ in said]
    assert pcs == sorted(pcs) and len(set(pcs)) == len(pcs), (s, pcs)  # news only, never back
    assert pcs[-1] == 100 and said[-1][1:] == (said[-1][2], said[-1][2]), (s, said[-1])
# within a frame: the reference's and the probe's tiles, so more than their frames' worth of lines
assert len(steps[ref]) > 3 and len(steps[probe]) > 2, (steps[ref], steps[probe])
assert any(k == 1 and 0 < p < 50 for p, k, _ in steps[ref]), steps[ref]
# a method's repeat: frame k of n between its frames only, 0%, 50%, 100% of 2 frames
for s in reps:
    assert steps[s] == [(0, 1, 2), (50, 2, 2), (100, 2, 2)], (s, steps[s])
# the scenario line and the final one carry none
assert not any(s.startswith("scenario ") or s.startswith("wrote ") for s in steps), steps.keys()
PY

# By default a line only after 20 s of a step: this run adds nothing to the status lines.
expect 0 "" -- $B $RUN --out "$TMP/d"
grep -q "elapsed" "$TMP/err" && fail "a short step printed progress lines by default: $(cat "$TMP/err")"
grep -q "^fovea bench: \[2/2\] pt-2: repeat 1/1, 2 frame(s)$" "$TMP/err" || fail "the status lines are gone: $(cat "$TMP/err")"

# --quiet: nothing on stderr, whatever --progress-every says.
expect 0 "" -- $B $RUN --out "$TMP/q" --progress-every 0 --quiet
[ -s "$TMP/err" ] && fail "--quiet printed on stderr: $(head -c 400 "$TMP/err")"

# The reports are the same with the progress lines and without them, timings apart (the reference
# rendered afresh in each: its frames report progress within them).
python3 - "$TMP/p" "$TMP/q" <<'PY' || fail "the progress changed the report"
import json, sys
VOLATILE = {"date", "command", "ms_per_frame", "frame_ms", "stages_ms", "stages_ms_range", "stages_serial_share", "speedup",
            "mrays_per_s"}
def strip(x):
    if isinstance(x, dict): return {k: strip(v) for k, v in x.items() if k not in VOLATILE}
    if isinstance(x, list): return [strip(v) for v in x]
    return x
name = "cornell-pt-pt-2.json"
a, b = (json.load(open(f"{d}/{name}")) for d in sys.argv[1:3])
assert strip(a) == strip(b)
PY
for f in "$TMP"/p/cache/*.pfm; do
  cmp -s "$f" "$TMP/q/cache/$(basename "$f")" || fail "the cached reference $(basename "$f") differs with progress on"
done

# A bad interval is refused before anything runs.
expect 2 "--progress-every -1: expected seconds in [0, 86400]" -- $B $RUN --out "$TMP/bad" --progress-every -1
expect 2 "--progress-every soon" -- $B $RUN --out "$TMP/bad" --progress-every soon
[ -e "$TMP/bad" ] && fail "a refused run wrote $TMP/bad"

# On a terminal (script(1) gives the command one): the bar redrawn in place, and cleared (spaces,
# then \r) before the next status line; nothing of it once --quiet.
if command -v script >/dev/null 2>&1; then
  script -qec "$FOVEA bench $RUN --out $TMP/t >/dev/null" /dev/null > "$TMP/tty" 2>&1 </dev/null
  python3 - "$TMP/tty" <<'PY' || fail "the terminal's progress line is wrong: $(head -c 2000 "$TMP/tty" | od -c | head -40)"
import re, sys
t = open(sys.argv[1], "rb").read().decode().replace("\r\n", "\n")
assert re.search(r"\r\[[#.]{30}\] +\d+%  frame \d+/\d+  \d+s elapsed", t), "no bar"
assert re.search(r"\r\[#{30}\] 100%  frame 2/2", t), "no full bar"
# every status line after the first starts on a clean line: a drawn bar was wiped first
for m in re.finditer(r"fovea bench: ", t):
    before = t[:m.start()]
    assert before == "" or before.endswith("\n") or re.search(r"\r {20,}\r$", before), repr(before[-80:])
# nothing of the bar stays behind: every line ends without one
assert not re.search(r"\] +\d+%[^\r\n]*\n", t), "a bar left in the output"
PY
  script -qec "$FOVEA bench $RUN --out $TMP/t --quiet >/dev/null" /dev/null > "$TMP/ttyq" 2>&1 </dev/null
  [ -s "$TMP/ttyq" ] && fail "--quiet drew on a terminal: $(od -c "$TMP/ttyq" | head -5)"
fi
finish
