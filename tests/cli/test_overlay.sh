# `fovea render --overlay` and heat maps, at the command line: the overlay is refused over linear
# data (PFM, EXR: exit 2, one line, no file); an overlaid PNG says so in its metadata, also under
# --no-metadata (then byte-reproducible), and `fovea compare` refuses it and heat maps; bad
# --heatmap-max values exit 2; --json reports the heat map's scale. The pixels are checked in
# tests/unit/test_overlay.c.
. "$(dirname "$0")/lib.sh"
R="$FOVEA render cornell --size 32x24 --spp 1 --threads 2 --quiet"
C="$FOVEA compare"

expect 2 "--overlay: draws over a .png only" -- $R --overlay --out "$TMP/o.exr"
[ -e "$TMP/o.exr" ] && fail "--overlay with .exr left a file"
expect 2 "--overlay: draws over a .png only" -- $R --overlay --out "$TMP/o.pfm"
[ -e "$TMP/o.pfm" ] && fail "--overlay with .pfm left a file"

expect 0 "" -- $R --out "$TMP/ref.pfm"
expect 0 "" -- $R --gaze 0.4,0.5 --overlay --out "$TMP/o.png"
grep -q "fovea:overlay" "$TMP/o.png" || fail "the overlaid PNG does not say so in its metadata"
expect 2 "o.png has the eye model's rings drawn over it (fovea render --overlay)" -- $C "$TMP/ref.pfm" "$TMP/o.png"
expect 2 "o.png has the eye model's rings drawn over it" -- $C "$TMP/o.png" "$TMP/ref.pfm"
# --no-metadata keeps the one key that says what the pixels are, and stays byte-reproducible
expect 0 "" -- $R --gaze 0.4,0.5 --overlay --no-metadata --out "$TMP/n1.png"
expect 0 "" -- $R --gaze 0.4,0.5 --overlay --no-metadata --out "$TMP/n2.png"
cmp -s "$TMP/n1.png" "$TMP/n2.png" || fail "--overlay --no-metadata is not byte-reproducible"
grep -q "fovea:overlay" "$TMP/n1.png" || fail "--overlay --no-metadata dropped the overlay key"
grep -q "fovea:method" "$TMP/n1.png" && fail "--no-metadata wrote more than the overlay key"
expect 2 "rings drawn over it" -- $C "$TMP/ref.pfm" "$TMP/n1.png"
# without --overlay nothing is marked and compare takes it
expect 0 "" -- $R --gaze 0.4,0.5 --out "$TMP/plain.png"
grep -q "fovea:overlay" "$TMP/plain.png" && fail "a PNG without --overlay is marked as overlaid"
expect 0 "" -- $C "$TMP/ref.pfm" "$TMP/plain.png"

# heat maps: the scale in JSON and in the file; a heat map is not an image to compare
expect 0 "" -- $C "$TMP/ref.pfm" "$TMP/plain.png" --json --heatmap "$TMP/h.png" --heatmap-metric mse --heatmap-max 0.25
python3 -c 'import json,sys; h=json.load(open(sys.argv[1]))["heatmap"]; assert h["metric"]=="mse" and h["max"]==0.25 and h["file"].endswith("h.png"), h' "$TMP/out" \
  || fail "compare --json lacks the heat map's scale: $(cat "$TMP/out")"
grep -q "fovea:heatmap_max" "$TMP/h.png" || fail "the heat map does not record its scale"
expect 2 "h.png is a heat map" -- $C "$TMP/ref.pfm" "$TMP/h.png"
expect 2 "--heatmap-max 0: expected a positive number" -- $C "$TMP/ref.pfm" "$TMP/plain.png" --heatmap "$TMP/h2.png" --heatmap-max 0
expect 2 "--heatmap-max -1: expected a positive number" -- $C "$TMP/ref.pfm" "$TMP/plain.png" --heatmap "$TMP/h2.png" --heatmap-max -1
expect 2 "--heatmap-max inf: expected a positive number" -- $C "$TMP/ref.pfm" "$TMP/plain.png" --heatmap "$TMP/h2.png" --heatmap-max inf
expect 2 "--heatmap-max x: expected a positive number" -- $C "$TMP/ref.pfm" "$TMP/plain.png" --heatmap "$TMP/h2.png" --heatmap-max x
expect 2 "--heatmap-max: only with --heatmap FILE" -- $C "$TMP/ref.pfm" "$TMP/plain.png" --heatmap-max 1
[ -e "$TMP/h2.png" ] && fail "a refused heat map was written"
finish
