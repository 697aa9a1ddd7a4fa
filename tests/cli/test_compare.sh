# `fovea compare`: identical images give zero error, a noisier render gives more error than a
# less noisy one, JSON output parses, a heat map is written; bad input exits 2.
. "$(dirname "$0")/lib.sh"
C="$FOVEA compare"
$FOVEA render cornell --size 48x48 --spp 64 --out "$TMP/ref.pfm" --quiet || fail "render ref"
$FOVEA render cornell --size 48x48 --spp 1 --seed 7 --out "$TMP/a.pfm" --quiet || fail "render a"
$FOVEA render cornell --size 48x48 --spp 8 --seed 7 --out "$TMP/b.png" --quiet || fail "render b"
$FOVEA render cornell --size 32x32 --spp 1 --out "$TMP/small.pfm" --quiet || fail "render small"

expect 0 "" -- $C "$TMP/ref.pfm" "$TMP/ref.pfm"
awk 'NR > 1 && ($3 != 0 || $4 != "inf" || $5 != 0 || $7 != 0) { bad = 1 } END { exit bad }' "$TMP/out" \
  || fail "identical images: non-zero error in some region: $(cat "$TMP/out")"
grep -q '^fovea ' "$TMP/out" || fail "no fovea row: $(cat "$TMP/out")"

expect 0 "" -- $C "$TMP/ref.pfm" "$TMP/a.pfm" --json --gaze 0.3,0.6 --heatmap "$TMP/heat.png"
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); r=d["regions"]; assert set(r)=={"fovea","transition","periphery","all"}; assert r["all"]["mse"]>0 and 0<r["all"]["flip"]<1; assert d["gaze"]==[0.3,0.6]' "$TMP/out" \
  || fail "bad JSON from compare: $(cat "$TMP/out")"
cp "$TMP/out" "$TMP/a.json"
[ -s "$TMP/heat.png" ] || fail "no heat map written"
expect 0 "" -- $C "$TMP/ref.pfm" "$TMP/b.png" --json --gaze 0.3,0.6
python3 -c 'import json,sys; a=json.load(open(sys.argv[1]))["regions"]["all"]; b=json.load(open(sys.argv[2]))["regions"]["all"]; assert b["mse"]<a["mse"] and b["flip"]<a["flip"] and b["ssim"]>a["ssim"], (a,b)' "$TMP/a.json" "$TMP/out" \
  || fail "8 spp is not closer to the reference than 1 spp"
expect 0 "" -- $C "$TMP/ref.pfm" "$TMP/a.pfm" --fovea-frac 0.25 --heatmap "$TMP/heat-mse.png" --heatmap-metric mse

# Empty regions (a sub-pixel fovea and transition) have no values: "-" in the table, null in
# JSON; file names with quotes stay valid JSON.
expect 0 "" -- $C "$TMP/ref.pfm" "$TMP/a.pfm" --fovea-frac 0.001 --transition-frac 0.002
awk '$1 == "fovea" && ($2 != 0 || $3 != "-") { bad = 1 } END { exit bad }' "$TMP/out" || fail "empty fovea row: $(cat "$TMP/out")"
cp "$TMP/a.pfm" "$TMP/we\"ird.pfm"
expect 0 "" -- $C "$TMP/ref.pfm" "$TMP/we\"ird.pfm" --json --fovea-frac 0.001 --transition-frac 0.002
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); f=d["regions"]["fovea"]; assert f["pixels"]==0 and f["mse"] is None and f["flip"] is None; assert d["test"].endswith("we\"ird.pfm")' "$TMP/out" \
  || fail "JSON with empty regions or a quoted file name: $(cat "$TMP/out")"
expect 0 "" -- $C "$TMP/ref.pfm" "$TMP/ref.pfm" --json
python3 -c 'import json,sys; a=json.load(open(sys.argv[1]))["regions"]["all"]; assert a["mse"]==0 and a["psnr"] is None and a["ssim"]>0.99999' "$TMP/out" \
  || fail "identical images in JSON: $(cat "$TMP/out")"

expect 2 "size mismatch" -- $C "$TMP/ref.pfm" "$TMP/small.pfm"
expect 2 "missing.png" -- $C "$TMP/ref.pfm" "$TMP/missing.png"
expect 2 "--gaze" -- $C "$TMP/ref.pfm" "$TMP/a.pfm" --gaze 0.5,-0.1
expect 2 "expected two images" -- $C "$TMP/ref.pfm"
printf 'not an image' > "$TMP/junk.png"
expect 2 "junk.png" -- $C "$TMP/ref.pfm" "$TMP/junk.png"
expect 2 "--heatmap" -- $C "$TMP/ref.pfm" "$TMP/a.pfm" --heatmap "$TMP/heat.jpg"
# A malformed EXR (its header cut inside the channel list, or not an EXR version at all): fovea's
# one line, without OpenEXR's own messages (which its default handler printed, 2 to 4 lines, when
# the metadata was read; issue 42, item 5).
printf 'v/1\001\002\000\000\000channels\000chlist\000\005' >"$TMP/cut.exr"
expect 2 "cut.exr" -- $C "$TMP/cut.exr" "$TMP/cut.exr"
printf 'v/1\001garbage' >"$TMP/garbage.exr"
expect 2 "garbage.exr" -- $C "$TMP/ref.pfm" "$TMP/garbage.exr"
finish
