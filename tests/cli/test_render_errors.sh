# `fovea render` on bad input: every case exits 2 with one line naming the problem and leaves no
# output file; good input renders a valid image.
. "$(dirname "$0")/lib.sh"
D=$SRC/tests/data
OUT=$TMP/out.png
R="$FOVEA render"

expect 2 "no/such/scene.obj" -- $R "$TMP/no/such/scene.obj" --size 8x8 --out "$OUT"
expect 2 "unknown scene 'cornel'" -- $R cornel --size 8x8 --out "$OUT"
expect 2 "unknown method" -- $R cornell --method nope --size 8x8 --out "$OUT"
expect 2 "unknown parameter 'bogus'" -- $R cornell --param bogus=1 --size 8x8 --out "$OUT"
expect 2 "max_depth" -- $R cornell --param max_depth=-3 --size 8x8 --out "$OUT"
expect 2 "0x10" -- $R cornell --size 0x10 --out "$OUT"
expect 2 "-5x5" -- $R cornell --size -5x5 --out "$OUT"
expect 2 "100000x100000" -- $R cornell --size 100000x100000 --out "$OUT"
expect 2 "--size" -- $R cornell --size abc --out "$OUT"
expect 2 "--spp" -- $R cornell --spp 0 --out "$OUT"
# --spp names the parameter to use instead for a method without samples per pixel.
expect 2 "method 'pm' has no samples-per-pixel parameter (one eye path per pixel centre" -- $R cornell --method pm --spp 4 --size 8x8 --out "$OUT"
expect 2 "use --param vpls=N" -- $R cornell --method fir --spp 4 --size 8x8 --out "$OUT"
expect 2 "use --param vpls=N" -- $R cornell --method ir --spp 4 --size 8x8 --out "$OUT"
expect 2 "spp=8 must be 1, 4 or 16" -- $R sdf-primitives --method sdf-gt --spp 8 --size 8x8 --out "$OUT"
expect 2 "--gaze" -- $R cornell --gaze 1.5,0.5 --size 8x8 --out "$OUT"
expect 2 "nope.csv" -- $R cornell --gaze-trace "$TMP/nope.csv" --size 8x8 --out "$OUT"
expect 2 "unknown image format" -- $R cornell --size 8x8 --out "$TMP/x.jpg"
expect 2 "cannot write" -- $R cornell --size 8x8 --out "$TMP/missing/dir/x.png"
expect 2 "empty.obj" -- $R "$D/empty.obj" --size 8x8 --out "$OUT"
expect 2 "bad_syntax.json:4:" -- $R "$D/bad_syntax.json" --size 8x8 --out "$OUT"
expect 2 "unknown field 'albdo'" -- $R "$D/bad_field.json" --size 8x8 --out "$OUT"
expect 2 "unknown material 'whte'" -- $R "$D/bad_material.json" --size 8x8 --out "$OUT"
# --env within the range a JSON environment has; a --param given twice (issue 25, item 10)
expect 2 "--env 1e30,1,1: expected R,G,B radiances in [0, 1e+09]" -- $R cornell --env 1e30,1,1 --size 8x8 --out "$OUT"
expect 2 "--param spp=3: spp is already set (to 2); give each parameter once" -- $R cornell --param spp=2 --param spp=3 --size 8x8 --out "$OUT"
# a JSON scene's camera and environment are named once, not twice (issue 25, item 10)
printf '{"materials": {"m": {"type": "diffuse"}}, "camera": {"pos": [0,0,5], "look": [0,0,5]}, "objects": [{"sphere": {"center": [0,0,0], "radius": 1}, "material": "m"}]}' >"$TMP/cam.json"
expect 2 "cam.json: camera: look-at point equals the position" -- $R "$TMP/cam.json" --size 8x8 --out "$OUT"
grep -q "camera: camera" "$TMP/err" && fail "doubled prefix: $(cat "$TMP/err")"
printf '{"materials": {"m": {"type": "diffuse"}}, "environment": {"zenith": [1,1,1], "horizon": [1,1,1], "ground": [1,1,1], "up": [0,0,0]}, "objects": [{"sphere": {"center": [0,0,0], "radius": 1}, "material": "m"}]}' >"$TMP/env.json"
expect 2 "env.json: environment: up must be finite and non-zero" -- $R "$TMP/env.json" --size 8x8 --out "$OUT"
grep -q "environment: environment" "$TMP/err" && fail "doubled prefix: $(cat "$TMP/err")"
# a JSON nested beyond cJSON's limit is named as such, not "malformed" (issue 25, item 10)
{ for i in $(seq 1800); do printf '{"a":'; done; printf '1'; for i in $(seq 1800); do printf '}'; done; } >"$TMP/deep.json"
expect 2 "deep.json:1: objects and arrays nested deeper than 1000 levels" -- $R "$TMP/deep.json" --size 8x8 --out "$OUT"
expect 2 "materials.white.emission" -- $R "$D/bad_inf.json" --size 8x8 --out "$OUT"
expect 2 "lights[1].animation: animation of light 1: key times must increase" -- $R "$D/bad_light_anim.json" --size 8x8 --out "$OUT"
expect 2 "unknown or incomplete option" -- $R cornell --frobnicate
expect 2 "unknown command" -- $FOVEA frobnicate
[ -e "$OUT" ] && fail "a failed render left $OUT behind"
ls "$TMP" | grep -q 'tmp\.' && fail "temporary files left in $TMP"

# A mesh with NaN and degenerate triangles renders, with a warning.
expect 0 "" -- $R "$D/nan.obj" --size 8x8 --spp 1 --out "$OUT"
grep -q "dropped 2 of 3 triangles" "$TMP/err" || fail "no warning about the dropped triangles: $(cat "$TMP/err")"
[ -s "$OUT" ] || fail "no image written for nan.obj"

# Good renders: PNG, PFM, EXR; a sequence gets numbered files.
expect 0 "" -- $R cornell --size 16x12 --spp 2 --out "$TMP/c.png" --quiet
head -c 8 "$TMP/c.png" | od -An -c | grep -q 'P   N   G' || fail "c.png is not a PNG"
expect 0 "" -- $R cornell --size 16x12 --spp 1 --out "$TMP/c.pfm" --quiet
head -c 2 "$TMP/c.pfm" | grep -q PF || fail "c.pfm is not a PFM"
expect 0 "" -- $R cornell-fpm --size 16x12 --spp 1 --frames 2 --out "$TMP/seq.exr" --quiet
[ -s "$TMP/seq_0000.exr" ] && [ -s "$TMP/seq_0001.exr" ] || fail "sequence frames missing: $(ls "$TMP")"
expect 0 "" -- $FOVEA scenes
grep -q "cornell-fpm" "$TMP/out" || fail "fovea scenes does not list cornell-fpm"
expect 0 "" -- $FOVEA methods
grep -q "^pt " "$TMP/out" || fail "fovea methods does not list pt"
finish
