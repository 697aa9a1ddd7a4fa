# Visual-Polar path tracing from the command line: bad parameters of every method of the family exit
# 2 with one line naming the key and leave no file; each method renders; the quick vp-quality and
# vp-coherence-cornell scenarios write complete reports with the pipeline's stages and counters,
# vpolar has the lowest fovea FLIP among the equal-count methods, and the Visual-Polar launch is the
# coherent one; a scenario whose measure_from is not below frames is refused.
. "$(dirname "$0")/lib.sh"
OUT=$TMP/out.png
R="$FOVEA render cornell --size 32x36"

expect 2 "reduction" -- $R --method vpolar --param reduction=0 --out "$OUT"
# the denoiser's parameters are refused by the names a user types (issue 25, item 10: "alpha_color")
for m in vpolar cartesian-full; do
  expect 2 "parameter svgf_alpha=0 must be in (0, 1]" -- $R --method $m --param svgf_alpha=0 --out "$OUT"
  expect 2 "parameter sigma_lum=0 must be > 0" -- $R --method $m --param sigma_lum=0 --out "$OUT"
  expect 2 "parameter sigma_normal=0 must be > 0" -- $R --method $m --param sigma_normal=0 --out "$OUT"
  expect 2 "parameter sigma_depth=0 must be > 0" -- $R --method $m --param sigma_depth=0 --out "$OUT"
done
expect 2 "reduction" -- $R --method vpolar --param reduction=1 --out "$OUT"
expect 2 "reduction" -- $R --method vpolar --param reduction=1.5 --out "$OUT"
expect 2 "reduction" -- $R --method cartesian --param reduction=-0.1 --out "$OUT"
expect 2 "blur_sigma" -- $R --method vpolar --param blur_sigma=-1 --out "$OUT"
expect 2 "sigma" -- $R --method log-polar --param sigma=0.5 --out "$OUT"
expect 2 "alpha" -- $R --method log-polar --param alpha=-4 --out "$OUT"
expect 2 "falloff_probability" -- $R --method linear-falloff --param falloff_probability=2 --out "$OUT"
expect 2 "order" -- $R --method vpolar --param order=spiral --out "$OUT"
expect 2 "spp=0" -- $R --method vpolar --param spp=0 --out "$OUT"
expect 2 "unknown parameter 'reduction'" -- $R --method cartesian-full --param reduction=0.5 --out "$OUT"
expect 2 "fovea" -- $R --method vpolar --param reduction=0.999 --out "$OUT"
[ -e "$OUT" ] && fail "a refused render left $OUT behind"

for m in vpolar cartesian cartesian-full linear-falloff log-polar; do
  expect 0 "" -- $R --method $m --frames 2 --out "$TMP/$m.png" --quiet
  [ -s "$TMP/${m}_0001.png" ] || fail "$m wrote no second frame"
done
expect 0 "" -- $R --method vpolar --param show=space --out "$TMP/space.exr" --quiet
expect 0 "" -- $R --method vpolar --spp 2 --out "$TMP/spp2.png" --quiet
expect 0 "" -- $R --method vpolar --stereo 60 --out "$TMP/st.png" --quiet
[ -s "$TMP/st_left.png" ] && [ -s "$TMP/st_right.png" ] || fail "stereo vpolar wrote $(ls "$TMP")"

expect 0 "" -- $FOVEA bench vp-quality --quick --out "$TMP/b" --quiet
python3 - "$TMP/b/vp-quality.json" <<'PY' || fail "vp-quality.json is incomplete or wrong"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["measure_from"] == 2, d["measure_from"]
rows = {r["method"]: r for r in d["results"]}
assert set(rows) == {"vpolar", "cartesian", "log-polar", "linear-falloff", "cartesian-full"}, rows.keys()
for r in rows.values():
    for st in ("trace", "denoise", "mip", "map", "blur"):
        assert st in r["stages_ms"], (r["method"], st)
    assert r["counters"]["rays"] > 0 and r["counters"]["history_fraction"] > 0.3
share = {k: r["counters"]["sample_share"] for k, r in rows.items()}
assert abs(share["vpolar"] - 0.39) < 0.01, share
assert abs(share["cartesian"] - share["vpolar"]) < 0.01, share
assert abs(share["log-polar"] - share["vpolar"]) < 0.01, share
assert share["cartesian-full"] == 1.0, share
fl = {k: r["error"]["fovea"]["flip"] for k, r in rows.items()}
assert fl["vpolar"] < min(fl["cartesian"], fl["log-polar"], fl["linear-falloff"]), fl
assert rows["vpolar"]["temporal"]["fovea"]["mse"] is not None
PY
for f in vp-quality.md vp-quality/reference.png vp-quality/vpolar.png vp-quality/vpolar-flip.png vp-quality/vpolar-fovea.png; do
  [ -s "$TMP/b/$f" ] || fail "missing $f"
done

expect 0 "" -- $FOVEA bench vp-coherence-cornell --quick --out "$TMP/b" --quiet
python3 - "$TMP/b/vp-coherence-cornell.json" <<'PY' || fail "vp-coherence-cornell.json is incomplete or wrong"
import json, sys
d = json.load(open(sys.argv[1]))
rows = {r["method"]: r for r in d["results"]}
c = {k: r["counters"] for k, r in rows.items()}
# the same samples in another order: the same rays
assert c["vpolar"]["rays"] == c["vpolar-random"]["rays"], c
assert c["vpolar"]["samples"] == c["vpolar-random"]["samples"], c
for k in c:
    assert c[k]["mrays_per_s"] > 0, k
PY

sed 's/"measure_from": 5/"measure_from": 10/' "$SRC/bench/vp-quality.json" > "$TMP/bad.json"
expect 2 "measure_from" -- $FOVEA bench "$TMP/bad.json" --out "$TMP/b2" --quiet
finish
