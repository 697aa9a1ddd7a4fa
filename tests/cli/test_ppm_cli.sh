# `fovea render --method ppm`: bad parameters exit 2 with one line naming the parameter and leave no
# file; --spp sets the passes (one jittered eye path per pixel each); a good render writes an image.
. "$(dirname "$0")/lib.sh"
OUT=$TMP/out.pfm
R="$FOVEA render cornell --method ppm --size 8x8 --out $OUT"
expect 2 "parameter alpha=0: must lie strictly between 0 and 1" -- $R --param alpha=0
expect 2 "parameter alpha=1: must lie strictly between 0 and 1" -- $R --param alpha=1
expect 2 "alpha" -- $R --param alpha=2
expect 2 "alpha" -- $R --param alpha=-0.5
expect 2 "passes" -- $R --param passes=0
expect 2 "passes" -- $R --param passes=1.5
expect 2 "photons" -- $R --param photons=0
expect 2 "parameter radius=0: the initial gather radius must be > 0" -- $R --param radius=0
expect 2 "radius" -- $R --param radius=-2
expect 2 "--spp" -- $R --spp 0
expect 2 "unknown parameter 'filter' for method 'ppm'" -- $R --param filter=false
[ -e "$OUT" ] && fail "a refused render left $OUT behind"
# pm names ppm as the method that takes --spp.
expect 2 "ppm" -- $FOVEA render cornell --method pm --spp 4 --size 8x8 --out "$OUT"
# --spp 3 is passes=3: the third pass gathers with r_1 sqrt(5/6 * 8/9) (Eq. 8 at 8x8: r_1 = 1386.67).
expect 0 "" -- $R --spp 3 --param photons=1000 --stats
grep -q "radius_first=1386.66" "$TMP/err" || fail "first radius: $(cat "$TMP/err")"
grep -q "radius_last=1193.45" "$TMP/err" || fail "third pass radius: $(cat "$TMP/err")"
[ -s "$OUT" ] || fail "no image written"
finish
