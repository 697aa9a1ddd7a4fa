# `fovea bench --scene ... --methods ...`: a comparison built from the command line gives the same
# numbers as the equivalent scenario file written by hand, saves the scenario it built, and refuses
# bad options with one line and status 2, writing nothing.
. "$(dirname "$0")/lib.sh"
cat >"$TMP/hand.json" <<JSON
{"name": "hand", "scene": "cornell", "size": [32, 24], "frames": 2,
 "gaze": {"fixed": [0.3, 0.6]},
 "reference": {"method": "pt", "params": {"spp": 4}},
 "methods": [{"label": "pt", "method": "pt", "params": {"spp": 1}},
             {"label": "pm", "method": "pm", "params": {"photons": 3000, "radius": "0.05"}}]}
JSON
expect 0 "" -- "$FOVEA" bench "$TMP/hand.json" --out "$TMP/a" --repeats 1 --quiet
expect 0 "" -- "$FOVEA" bench --scene cornell --methods pt:spp=1,pm:photons=3000:radius=0.05 --reference pt:spp=4 --size 32x24 \
  --frames 2 --gaze 0.3,0.6 --repeats 1 --out "$TMP/b" --save-scenario "$TMP/saved.json" --quiet
[ -s "$TMP/b/cornell-pt-pm.json" ] || fail "the command-line run wrote no report under its name cornell-pt-pm"
grep -q '^| pm | ' "$TMP/out" || fail "the command-line run printed no result table"
python3 - "$TMP/a/hand.json" "$TMP/b/cornell-pt-pm.json" "$TMP/saved.json" <<'PY' || fail "the command line and the scenario file disagree"
import json, sys
a, b, saved = (json.load(open(p)) for p in sys.argv[1:])
for k in ("size", "frames", "seed", "eye"):
    assert a[k] == b[k], (k, a[k], b[k])
assert a["reference"]["params"] == b["reference"]["params"] == {"spp": 4}
assert a["reference"]["seed"] == b["reference"]["seed"]
ra, rb = a["results"], b["results"]
assert [r["method"] for r in ra] == [r["method"] for r in rb] == ["pt", "pm"]
for x, y in zip(ra, rb):
    assert x["params"] == y["params"], (x["params"], y["params"])
    # Deterministic renders of the same frames against the same reference: equal, not close.
    for g in ("fovea", "transition", "periphery", "all"):
        for m in ("mse", "e", "ssim", "flip"):
            assert x["error"][g][m] == y["error"][g][m], (x["method"], g, m, x["error"][g][m], y["error"][g][m])
    assert x["temporal"] == y["temporal"] and x["image_mean"] == y["image_mean"]
assert saved["name"] == "cornell-pt-pm" and saved["gaze"] == {"fixed": [0.3, 0.6]} and saved["frames"] == 2
assert saved["methods"][1] == {"label": "pm", "method": "pm", "params": {"photons": 3000, "radius": "0.05"}}, saved["methods"][1]
PY
# The saved scenario runs as a file and gives the same numbers again.
expect 0 "" -- "$FOVEA" bench "$TMP/saved.json" --out "$TMP/c" --repeats 1 --quiet
python3 - "$TMP/b/cornell-pt-pm.json" "$TMP/c/cornell-pt-pm.json" <<'PY' || fail "the saved scenario gives other numbers"
import json, sys
b, c = (json.load(open(p)) for p in sys.argv[1:])
assert [r["error"] for r in b["results"]] == [r["error"] for r in c["results"]]
PY
# A scene file given by a relative path is saved absolute, so the scenario runs from anywhere.
cp -r "$SRC/scenes" "$TMP/sc" && (cd "$TMP" &&
  "$FOVEA" bench --scene sc/showroom.json --methods pt:spp=1 --reference pt:spp=1 --size 16x16 --check --save-scenario "$TMP/room-s.json" >/dev/null 2>&1) &&
  grep -q "\"scene\":	\"$TMP/sc/showroom.json\"" "$TMP/room-s.json" || fail "a relative scene path was not saved absolute: $(grep scene "$TMP/room-s.json" 2>/dev/null)"

# Bad options: one line, status 2, nothing written.
B="$FOVEA bench --out $TMP/bad"
expect 2 "unknown method 'nope'" -- $B --scene cornell --methods nope --save-scenario "$TMP/bad.json"
expect 2 "need --scene" -- $B --methods pt
expect 2 "expected KEY=VALUE" -- $B --scene cornell --methods pt:spp
expect 2 "sets 'spp' twice" -- $B --scene cornell --methods pt:spp=1:spp=2
expect 2 "--reference: unknown method" -- $B --scene cornell --methods pt --reference ptt:spp=4
expect 2 "exclude each other" -- $B --scene cornell --methods pt --gaze 0.5,0.5 --gaze-trace x.csv
expect 2 "give no SCENARIO" -- $B --scene cornell --methods pt pt-cornell
expect 2 "nosuchscene" -- $B --scene nosuchscene --methods pt --save-scenario "$TMP/bad.json"
expect 2 "spp" -- $B --scene cornell --methods pt:spp=0 --size 8x8 --save-scenario "$TMP/bad.json"
[ -e "$TMP/bad" ] || [ -e "$TMP/bad.json" ] && fail "a refused command line wrote files"
finish
