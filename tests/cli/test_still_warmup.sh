# A temporal method's single still looks converged (issue 27): `fovea render` runs the method's
# warm-up frames (fovea methods NAME; --warmup N) at frame 0's view before the frame it writes.
#  - the still with W warm-up frames is bit for bit frame W of a static sequence rendered without
#    warm-up (the warm-up frames are that sequence's first W frames, index and history alike);
#  - its error against a path-traced reference lies within the spread of the converged frames'
#    errors (at most the 90th percentile of frames 16..39 of that sequence), while the first frame
#    without warm-up lies above it for the SVGF methods (the check can fail: it did before);
#  - the image records its warm-up count; a method without temporal state gets none;
#  - --warmup refuses what is not a count.
# Run as `bash test_still_warmup.sh FOVEA SRCDIR BUILDDIR`.
. "$(dirname "$0")/lib.sh"
SIZE=96x96

mse() { "$FOVEA" compare "$1" "$2" --json | python3 -c 'import json, sys; print(json.load(sys.stdin)["regions"]["all"]["mse"])'; }

"$FOVEA" render cornell --method pt --spp 256 --size $SIZE --out "$TMP/ref.pfm" --quiet --no-metadata || fail "reference"

# cornell is static: with a huge frame rate the sequence's views equal frame 0's, so the still
# and the sequence see the same cameras and the same frame indices.
for m in vpolar cartesian-full log-polar; do
  out=$("$FOVEA" render cornell --method $m --size $SIZE --out "$TMP/$m-still.pfm" --no-metadata 2>&1) || fail "$m still: $out"
  w=$(echo "$out" | sed -n 's/^warm-up: \([0-9]*\) frames.*/\1/p')
  [ "$w" = 16 ] || fail "$m: expected 16 warm-up frames (SVGF's), the render said '$w'"
  "$FOVEA" render cornell --method $m --size $SIZE --frames 40 --fps 1000000 --warmup 0 --out "$TMP/$m-seq.pfm" --quiet --no-metadata ||
    fail "$m sequence"
  cmp -s "$TMP/$m-still.pfm" "$TMP/$m-seq_0016.pfm" || fail "$m: the still is not frame 16 of a sequence without warm-up"
  steady=$(for i in $(seq 16 39); do mse "$TMP/ref.pfm" "$(printf "%s/%s-seq_%04d.pfm" "$TMP" $m "$i")"; done)
  p90=$(echo "$steady" | sort -g | sed -n 22p) # the 22nd of 24
  still=$(mse "$TMP/ref.pfm" "$TMP/$m-still.pfm")
  cold=$(mse "$TMP/ref.pfm" "$TMP/$m-seq_0000.pfm")
  echo "$m: still $still, first frame without warm-up $cold, converged frames' 90th percentile $p90"
  awk -v s="$still" -v p="$p90" 'BEGIN { exit !(s <= p) }' || fail "$m: the still's MSE $still exceeds the converged frames' 90th percentile $p90"
  if [ $m != log-polar ]; then # log-polar's frames scatter more than its history gains (docs/visual-polar.md)
    awk -v c="$cold" -v p="$p90" 'BEGIN { exit !(c > p) }' || fail "$m: without warm-up the first frame's MSE $cold is already converged ($p90): the check cannot fail"
  fi
done

# fir refines its VPLs over frames: one warm-up frame; the still's error is that of later frames.
"$FOVEA" render cornell-fir --method pt --spp 256 --size $SIZE --out "$TMP/ref-fir.pfm" --quiet --no-metadata || fail "fir reference"
out=$("$FOVEA" render cornell-fir --method fir --size $SIZE --out "$TMP/fir.png" 2>&1) || fail "fir still: $out"
echo "$out" | grep -q '^warm-up: 1 frame at' || fail "fir: expected 1 warm-up frame: $out"

# The metadata says how many frames came first; pt has no temporal state and warms up none.
"$FOVEA" render cornell --method vpolar --size 32x32 --out "$TMP/v.png" --quiet || fail "vpolar png"
python3 - "$TMP/v.png" <<'EOF' || fail "vpolar's PNG lacks warmup_frames=16"
import sys
data = open(sys.argv[1], "rb").read()
sys.exit(0 if b"warmup_frames\x00" in data and b"16" in data.split(b"warmup_frames\x00", 1)[1][:8] else 1)
EOF
out=$("$FOVEA" render cornell --method pt --spp 1 --size 32x32 --out "$TMP/p.png" 2>&1) || fail "pt: $out"
echo "$out" | grep -q 'warm-up' && fail "pt warmed up: $out"

expect 2 "--warmup x" -- "$FOVEA" render cornell --method vpolar --warmup x --out "$TMP/x.png"
expect 2 "--warmup 1001" -- "$FOVEA" render cornell --method vpolar --warmup 1001 --out "$TMP/x.png"
[ -e "$TMP/x.png" ] && fail "a refused render wrote its file"
finish
