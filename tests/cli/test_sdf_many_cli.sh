# SDF scenes of many shapes from the command line (issue 29): scripts/gen-sdf-grid writes a
# 15x15 grid (225 shapes) as one flat "union" and as one object per shape; both load and render
# with sdf-gt and pt, and the sphere tracer's two layouts give the same image. A union nested 49
# levels deep (real nesting, not a flat list) is still refused in one line, exit 2, no file left,
# and so is a flat union of 40 000 spheres (80 000 nodes: over the 65 536-node limit).
. "$(dirname "$0")/lib.sh"
python3 "$SRC/scripts/gen-sdf-grid" --n 15 --out-dir "$TMP" >/dev/null || fail "gen-sdf-grid failed"
[ -s "$TMP/sdf-grid225.json" ] && [ -s "$TMP/sdf-grid225-objects.json" ] || fail "gen-sdf-grid wrote no scenes"
for l in "" -objects; do
  expect 0 "" -- $FOVEA render "$TMP/sdf-grid225$l.json" --method sdf-gt --size 64x36 --out "$TMP/gt$l.pfm" --quiet
  expect 0 "" -- $FOVEA render "$TMP/sdf-grid225$l.json" --method pt --spp 1 --size 32x18 --out "$TMP/pt$l.png" --quiet
  [ -s "$TMP/pt$l.png" ] || fail "pt wrote no image of layout '$l'"
done
cmp -s "$TMP/gt.pfm" "$TMP/gt-objects.pfm" || fail "sdf-gt: the union and the objects layouts differ"
python3 - "$TMP/sdf-grid225.json" <<'PY' || fail "the scene is not a flat union of 225 children"
import json, sys
d = json.load(open(sys.argv[1]))
assert len(d["objects"][1]["sdf"]["union"]) == 225
PY

# 49 unions each inside the next one's second child: nesting, refused
python3 - "$TMP/deep.json" <<'PY'
import json, sys
n = {"sphere": {"radius": 1}}
for _ in range(49):
    n = {"union": [{"sphere": {"radius": 1}}, n]}
json.dump({"materials": {"white": {"albedo": [0.7, 0.7, 0.7]}},
           "lights": [{"type": "point", "pos": [0, 4, 2], "intensity": [20, 20, 20]}],
           "objects": [{"name": "deep", "material": "white", "sdf": n}]}, open(sys.argv[1], "w"))
PY
expect 2 "nested deeper than 48 levels" -- $FOVEA render "$TMP/deep.json" --method sdf-gt --size 16x12 --out "$TMP/deep.png"
[ -e "$TMP/deep.png" ] && fail "a refused render left deep.png behind"

python3 - "$TMP/huge.json" <<'PY'
import json, sys
kids = [{"transform": {"translate": [i % 200, 0, i // 200], "child": {"sphere": {"radius": 0.3}}}} for i in range(40000)]
json.dump({"materials": {"white": {"albedo": [0.7, 0.7, 0.7]}},
           "lights": [{"type": "point", "pos": [0, 4, 2], "intensity": [20, 20, 20]}],
           "objects": [{"name": "huge", "material": "white", "sdf": {"union": kids}}]}, open(sys.argv[1], "w"))
PY
expect 2 "the sdf compiles to more than 65536 nodes (each shape and transform is one, and an operator of n children n - 1: its largest, of 40000 children, 39999)" -- $FOVEA render "$TMP/huge.json" --method sdf-gt --size 16x12 --out "$TMP/huge.png"
[ -e "$TMP/huge.png" ] && fail "a refused render left huge.png behind"
finish
