# Default lighting and framing from the command line (issue 14): a mesh file without lights gets
# a sky and a key light, said in one line on stderr, and renders lit; --env sets a uniform
# environment instead (a diffuse quad of albedo a under L has radiance a L); --no-default-light
# keeps the old last-resort light; --frame-view frames from a named side; bad values exit 2 with
# one line; a box whose only light is a small emissive label gets them too; every method family
# renders the closed box.
. "$(dirname "$0")/lib.sh"
D=$SRC/tests/data
OUT=$TMP/out.png
R="$FOVEA render"

expect 2 "--env 1,2: expected R,G,B" -- $R "$D/box_closed.obj" --env 1,2 --size 8x8 --out "$OUT"
expect 2 "--env -1,0,0" -- $R "$D/box_closed.obj" --env -1,0,0 --size 8x8 --out "$OUT"
expect 2 "--frame-view bottom: expected front, back, left, right, top or three-quarter" -- $R "$D/box_closed.obj" --frame-view bottom --size 8x8 --out "$OUT"
[ -e "$OUT" ] && fail "a refused render left $OUT behind"

# mean of the green channel of a PFM over its centre half (the model there)
pfm_mean() {
  python3 - "$1" <<'PY'
import struct, sys
d = open(sys.argv[1], 'rb').read()
parts = d.split(b'\n', 3)
w, h = map(int, parts[1].split()); scale = float(parts[2])
fmt = '<' if scale < 0 else '>'
px = struct.unpack(fmt + '%df' % (3 * w * h), parts[3][:12 * w * h])
vals = [px[3 * (y * w + x) + 1] for y in range(h // 4, 3 * h // 4) for x in range(w // 4, 3 * w // 4)]
print('%.4f' % (sum(vals) / len(vals)))
PY
}

$R "$D/box_closed.obj" --size 32x24 --spp 4 --out "$TMP/box.pfm" 2>"$TMP/err" >/dev/null || fail "box_closed.obj did not render"
grep -q "no lights: added a sky environment" "$TMP/err" || fail "no note about the default light: $(cat "$TMP/err")"
[ "$(grep -c warning "$TMP/err")" = 1 ] || fail "the note is not one line: $(cat "$TMP/err")"
m=$(pfm_mean "$TMP/box.pfm")
python3 -c "import sys; sys.exit(0 if $m > 0.2 else 1)" || fail "box_closed.obj is dark by default (mean $m)"

# the old last resort: a point light inside the closed box, which lights nothing seen
expect 0 "" -- $R "$D/box_closed.obj" --no-default-light --size 32x24 --spp 4 --out "$TMP/dark.pfm"
m=$(pfm_mean "$TMP/dark.pfm")
python3 -c "import sys; sys.exit(0 if $m < 0.01 else 1)" || fail "--no-default-light still lit the box (mean $m)"

# --env 2,2,2 on the closed box seen face-on from the front: a convex diffuse object under a uniform
# environment has radiance a L exactly; the OBJ has no material, so assimp's default, diffuse 0.6.
ALBEDO=0.6
expect 0 "" -- $R "$D/box_closed.obj" --env 2,2,2 --frame-view front --size 32x24 --spp 64 --out "$TMP/env.pfm" --quiet
m=$(pfm_mean "$TMP/env.pfm")
python3 -c "import sys; sys.exit(0 if abs($m - 2 * $ALBEDO) < 0.02 * 2 * $ALBEDO else 1)" || fail "--env 2,2,2: front face radiance $m, expected $(python3 -c "print(2 * $ALBEDO)")"

# only a small emitter (a 0.1 x 0.05 label of radiance 2 on the closed box): the default light is
# added too, in one line; --no-default-light leaves the box dark around its label
$R "$D/emissive_accent.obj" --size 32x24 --spp 4 --out "$TMP/accent.pfm" 2>"$TMP/err" >/dev/null || fail "emissive_accent.obj did not render"
grep -q "only lights are 2 small emissive triangles" "$TMP/err" || fail "no note about the small emitters: $(cat "$TMP/err")"
[ "$(grep -c warning "$TMP/err")" = 1 ] || fail "the note is not one line: $(cat "$TMP/err")"
m=$(pfm_mean "$TMP/accent.pfm")
python3 -c "import sys; sys.exit(0 if $m > 0.2 else 1)" || fail "emissive_accent.obj is dark by default (mean $m)"
expect 0 "" -- $R "$D/emissive_accent.obj" --no-default-light --size 32x24 --spp 4 --out "$TMP/accent_dark.pfm"
m=$(pfm_mean "$TMP/accent_dark.pfm")
python3 -c "import sys; sys.exit(0 if $m < 0.05 else 1)" || fail "--no-default-light lit the box beyond its label (mean $m)"

# the same when the glow is an emission texture (MTL map_Ke, glTF emissiveTexture): a screen whose
# texture is black but for a 2 x 2 corner of white texels; its brightest texel decides "dim"
$R "$D/emissive_tex/screen.obj" --size 32x24 --spp 4 --out "$TMP/screen.pfm" 2>"$TMP/err" >/dev/null || fail "emissive_tex/screen.obj did not render"
grep -q "only lights are 2 small emissive triangles" "$TMP/err" || fail "screen.obj: no note about the small emitters: $(cat "$TMP/err")"
m=$(pfm_mean "$TMP/screen.pfm")
python3 -c "import sys; sys.exit(0 if $m > 0.1 else 1)" || fail "emissive_tex/screen.obj is dark by default (mean $m)"
expect 0 "" -- $R "$D/emissive_tex/nofactor.gltf" --size 32x24 --spp 4 --out "$TMP/nofactor.pfm" --quiet

for v in front back left right top three-quarter; do
  expect 0 "" -- $R "$D/tray.gltf" --frame-view $v --size 16x12 --spp 1 --out "$TMP/v_$v.png" --quiet
done
for m in pt pm fir vpolar ir; do
  expect 0 "" -- $R "$D/box_closed.obj" --method $m --size 16x12 --out "$TMP/m_$m.png" --quiet
done
finish
