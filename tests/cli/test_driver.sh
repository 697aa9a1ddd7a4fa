# One frame driver for every tool: `fovea render` and `fovea bench` given the same scene, size,
# times and seed render the same frames, bit for bit. The scene file carries a display and a gaze
# trace (scenes/showroom.json) and fpm uses both (its focus region follows the gaze, its regions
# the display), so a tool that built its frames with another policy would differ.
. "$(dirname "$0")/lib.sh"
SCN="$SRC/scenes/showroom.json"
expect 0 "" -- "$FOVEA" render "$SCN" --method fpm --param photons=20000 --size 48x32 --frames 2 --fps 10 --time 0.5 --seed 3 \
  --quiet --out "$TMP/r.png"
cat >"$TMP/same.json" <<JSON
{"scene": "$SCN", "size": [48, 32], "frames": 2, "fps": 10, "start_time": 0.5, "seed": 3, "repeats": 1,
 "reference": {"method": "pt", "params": {"spp": 1}},
 "methods": [{"label": "fpm", "method": "fpm", "params": {"photons": 20000}}]}
JSON
expect 0 "" -- "$FOVEA" bench "$TMP/same.json" --out "$TMP/bench" --quiet
[ -s "$TMP/bench/same/fpm.png" ] || fail "the bench wrote no image of the last frame"
# The same pixels (the files differ only in their metadata: render time, date).
"$FOVEA" compare "$TMP/r_0001.png" "$TMP/bench/same/fpm.png" --linear --json >"$TMP/cmp.json" 2>"$TMP/cmp.err" &&
  python3 -c 'import json,sys; r=json.load(open(sys.argv[1]))["regions"]["all"]; sys.exit(0 if r["mse"] == 0 and r["pixels"] == 48 * 32 else 1)' "$TMP/cmp.json" ||
  fail "fovea render and fovea bench rendered different frames: $(cat "$TMP/cmp.err") $(grep -A1 '"all"' "$TMP/cmp.json")"
# Both files record the same gaze (the trace's at t = 0.6) and method.
grep -q "gaze 0.4,0.47 from the metadata" "$TMP/cmp.err" || fail "render and bench images record different gazes: $(cat "$TMP/cmp.err")"
# The gaze both took is the scene file's trace (scenes/gaze-sweep.csv) at t = 0.5 + 1/10 = 0.6:
# x = 0.25 + 0.6 * 0.25 = 0.40, y = 0.50 - 0.6 * 0.05 = 0.47, not the centre.
grep -q "gaze (0.40, 0.47) at the last frame" "$TMP/bench/same.md" || fail "the bench did not take the scene file's gaze: $(grep -o 'gaze ([^)]*)' "$TMP/bench/same.md")"
finish
