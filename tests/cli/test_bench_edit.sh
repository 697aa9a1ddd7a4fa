# `fovea bench` scenario fields that edit the scene and the sweep array (docs/bench.md):
# "diffuse" and "animate" change the rendered frames and the reference's cache name; an animated
# light makes two frames differ where a still one does not; a "sweep" array writes one CSV per
# sweep (NAME-sweep-PARAM.csv) while the single object keeps NAME-sweep.csv; bad "animate"
# entries exit 2 with one line naming the scenario file and field, and write nothing.
. "$(dirname "$0")/lib.sh"
B="$FOVEA bench"
SHOW="$(cd "$SRC" && pwd)/scenes/showroom.json"

# showroom, all diffuse, static camera, the mirror box held still; LIGHT is the "animate" entry
# of its spot light (or nothing), SWEEP the "sweep" value.
scenario() { # FILE DIFFUSE LIGHT SWEEP
  cat > "$1" <<JSON
{"scene": "$SHOW", "size": [32, 32], "frames": 2, "fps": 1, "repeats": 1,
 "camera_path": [{"time": 0, "pos": [0, 1.8, 7], "look": [0, 0.8, 0], "fov": 45}],
 "diffuse": $2,
 "animate": [$3 {"object": "slider", "animation": [{"time": 0, "translate": [1.5, 0, -1.5]}]}],
 "reference": {"method": "pt", "params": {"spp": 16, "max_depth": 1}},
 "sweep": $4}
JSON
}
MOVE='{"light": 0, "animation": [{"time": 0}, {"time": 1, "translate": [-3, 0, 0]}]},'
ARRAY='[{"label": "pt", "method": "pt", "params": {"spp": 1}, "param": "max_depth", "values": [1, 2]},
        {"label": "pts", "method": "pt", "param": "spp", "values": [1, 2]}]'
ONE='{"label": "pt", "method": "pt", "param": "spp", "values": [1, 2]}'

scenario "$TMP/moving.json" true "$MOVE" "$ARRAY"
expect 0 "" -- $B "$TMP/moving.json" --out "$TMP/m" --threads 2 --quiet
for f in moving-sweep-max_depth.csv moving-sweep-spp.csv moving.md moving/reference.png; do
  [ -s "$TMP/m/$f" ] || fail "missing $f"
done
[ -e "$TMP/m/moving-sweep.csv" ] && fail "a sweep array also wrote moving-sweep.csv"
grep -q "^1," "$TMP/m/moving-sweep-spp.csv" && grep -q "^2," "$TMP/m/moving-sweep-max_depth.csv" || fail "sweep CSVs lack their rows"
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["diffuse"] is True and len(d["animate"]) == 2, d
assert sorted(r.get("sweep_param") for r in d["results"]) == ["max_depth", "max_depth", "spp", "spp"]' "$TMP/m/moving.json" \
  || fail "moving.json lacks diffuse, animate or the rows' sweep_param"

scenario "$TMP/still.json" true "" "$ONE"
expect 0 "" -- $B "$TMP/still.json" --out "$TMP/s" --threads 2 --quiet
[ -s "$TMP/s/still-sweep.csv" ] || fail "the single sweep object did not write still-sweep.csv"

# The two reference frames of each run: a light that crossed the room changes the image far more
# than the noise between two frames of a still scene does.
python3 - "$TMP/m/cache" "$TMP/s/cache" <<'PY' || fail "the animated light did not make the frames differ"
import glob, struct, sys
def pfm(p):
    f = open(p, 'rb'); f.readline(); w, h = map(int, f.readline().split()); sc = float(f.readline())
    return struct.unpack(('<' if sc < 0 else '>') + '%df' % (w * h * 3), f.read(w * h * 12))
def tilt(img):  # mean of the left half minus mean of the right half: where the light falls
    w = 32
    left = [v for i, v in enumerate(img) if (i // 3) % w < w // 2]
    right = [v for i, v in enumerate(img) if (i // 3) % w >= w // 2]
    return sum(left) / len(left) - sum(right) / len(right)
def change(d):
    a, b = [tilt(pfm(p)) for p in sorted(glob.glob(d + '/ref-*.pfm'))]
    return abs(a - b)
moving, still = change(sys.argv[1]), change(sys.argv[2])
assert moving > 5 * still and moving > 0.02, (moving, still)
PY

# "diffuse" and "animate" are part of the reference's cache name: the same cache gets new files.
scenario "$TMP/glossy.json" false "" "$ONE"
expect 0 "" -- $B "$TMP/glossy.json" --out "$TMP/s" --threads 2 --quiet
[ "$(ls "$TMP"/s/cache/ref-*.pfm | wc -l)" = 4 ] || fail "diffuse false reused diffuse true's references"
expect 0 "" -- $B "$TMP/moving.json" --out "$TMP/s" --threads 2
grep -q "0 cached" "$TMP/err" || fail "an animated light reused a still scene's references"

# Bad entries: exit 2, one line naming the file and the field, no output folder.
bad() { # NAME NEEDLE ANIMATE
  printf '{"scene": "%s", "size": [8, 8], "reference": {"method": "pt"}, "methods": [{"method": "pt"}], "animate": %s}' "$SHOW" "$3" > "$TMP/$1.json"
  expect 2 "$2" -- $B "$TMP/$1.json" --out "$TMP/bad-$1" --quiet
  grep -qF "$1.json" "$TMP/err" || fail "$1: the message does not name the scenario file"
  [ -e "$TMP/bad-$1" ] && fail "$1: wrote $TMP/bad-$1"
}
bad noobj "animate[0].object: scene" '[{"object": "nope", "animation": [{"time": 0}]}]'
bad nolight "animate[1].light: scene" '[{"object": "slider", "animation": [{"time": 0}]}, {"light": 1, "animation": [{"time": 0}]}]'
bad neglight "animate[0].light" '[{"light": -1, "animation": [{"time": 0}]}]'
bad notime "animate[0].animation[1]" '[{"light": 0, "animation": [{"time": 0}, {"translate": [1, 0, 0]}]}]'
bad shortvec "animate[0].animation[0].translate" '[{"light": 0, "animation": [{"time": 0, "translate": [1, 0]}]}]'
bad order "animate[0]" '[{"light": 0, "animation": [{"time": 1}, {"time": 0}]}]'
bad badkey "animate[0].animation[0]" '[{"light": 0, "animation": [{"time": 0, "move": [1, 0, 0]}]}]'
bad both "exactly one of 'light'" '[{"light": 0, "object": "slider", "animation": [{"time": 0}]}]'
bad emissive "animate[0].object" '[{"object": "panel", "animation": [{"time": 0}]}]'
bad noanim "animation" '[{"light": 0}]'
# Two sweeps of one parameter would write the same file.
printf '{"scene": "cornell", "size": [8, 8], "reference": {"method": "pt"}, "sweep": [%s, %s]}' "$ONE" "$ONE" > "$TMP/twosweeps.json"
expect 2 "sweep[1].param" -- $B "$TMP/twosweeps.json" --out "$TMP/bad-sweeps"
printf '{"scene": "cornell", "size": [8, 8], "reference": {"method": "pt"}, "methods": [{"method": "pt"}], "diffuse": 1}' > "$TMP/baddiffuse.json"
expect 2 "diffuse" -- $B "$TMP/baddiffuse.json" --out "$TMP/bad-diffuse"
finish
