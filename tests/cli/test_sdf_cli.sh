# The sphere-tracing family from the command line: each bad parameter of sdf-gt, sdf-relaxed, ipr
# and fipr exits 2 with one line naming the key, a scene without a signed distance field is refused
# by name, and a JSON scene whose "sdf" tree is bad (unknown primitive, negative radius, a radius
# that overflows to inf) exits 2 naming the JSON path; no refused render leaves a file. The same
# JSON scene, corrected, renders with every method. (The loader's own refusals are unit-tested in
# tests/unit/test_sdf_scene.c; these check the CLI path end to end.)
. "$(dirname "$0")/lib.sh"
OUT=$TMP/out.png
R="$FOVEA render sdf-primitives --size 16x12"

expect 2 "levels=0" -- $R --method ipr --param levels=0 --out "$OUT"
expect 2 "spp=3" -- $R --method sdf-gt --param spp=3 --out "$OUT"
expect 2 "fovea_deg=-1" -- $R --method fipr --param fovea_deg=-1 --out "$OUT"
expect 2 "refresh=3" -- $R --method fipr --param refresh=3 --out "$OUT"
expect 2 "levels=2" -- $R --method fipr --param levels=2 --out "$OUT"
expect 2 "relax=2.5" -- $R --method sdf-relaxed --param relax=2.5 --out "$OUT"
expect 2 "show=mask" -- $R --method sdf-gt --param show=mask --out "$OUT"
expect 2 "show=edges" -- $R --method ipr --param show=edges --out "$OUT"
expect 2 "outer_deg" -- $R --method fipr --param fovea_deg=20 --param outer_deg=10 --out "$OUT"
expect 2 "unknown parameter 'levels'" -- $R --method sdf-gt --param levels=3 --out "$OUT"
expect 2 "the scene has none" -- $FOVEA render cornell --size 16x12 --method fipr --out "$OUT"
grep -q "fipr" "$TMP/err" || fail "the refusal of cornell does not name fipr: $(cat "$TMP/err")"

# A one-sphere SDF scene, then the same with a bad tree.
sdf_scene() {
  cat >"$2" <<EOF
{"materials": {"white": {"albedo": [0.7, 0.7, 0.7]}},
 "lights": [{"type": "point", "pos": [0, 4, 2], "intensity": [20, 20, 20]}],
 "objects": [{"name": "ball", "material": "white", "sdf": $1}]}
EOF
}
sdf_scene '{"sphear": {"radius": 1}}' "$TMP/kind.json"
sdf_scene '{"sphere": {"radius": -1}}' "$TMP/neg.json"
sdf_scene '{"sphere": {"radius": 1e999}}' "$TMP/inf.json"
for m in sdf-gt fipr; do
  expect 2 "objects[0].sdf: unknown field 'sphear'" -- $FOVEA render "$TMP/kind.json" --method $m --size 16x12 --out "$OUT"
  expect 2 "objects[0].sdf.sphere.radius: must be > 0" -- $FOVEA render "$TMP/neg.json" --method $m --size 16x12 --out "$OUT"
  expect 2 "objects[0].sdf.sphere.radius: expected a finite number" -- $FOVEA render "$TMP/inf.json" --method $m --size 16x12 --out "$OUT"
done
[ -e "$OUT" ] && fail "a refused render left $OUT behind"
ls "$TMP" | grep -q 'tmp\.' && fail "temporary files left in $TMP"

sdf_scene '{"sphere": {"radius": 1}}' "$TMP/good.json"
for m in sdf-gt sdf-relaxed ipr fipr; do
  expect 0 "" -- $FOVEA render "$TMP/good.json" --method $m --size 16x12 --out "$TMP/$m.png" --quiet
  [ -s "$TMP/$m.png" ] || fail "$m wrote no image for the corrected scene"
done
finish
