# `fovea bench sdf-quality --quick`: the sphere-tracing scenario runs end to end with what the
# paper's Table 1 needs (errors per region against sdf-gt and against the path-traced pt-direct),
# and its rows keep the relations the method promises: the pyramid spends fewer camera-ray steps
# than the ground truth, the min filter matters, fipr's fovea is ipr's fovea pixel for pixel.
. "$(dirname "$0")/lib.sh"
OUT=$TMP/bench
expect 0 "" -- $FOVEA bench sdf-quality --quick --out "$OUT" --quiet
python3 - "$OUT/sdf-quality.json" <<'PY' || fail "sdf-quality.json is incomplete or wrong"
import json, sys
d = json.load(open(sys.argv[1]))
rows = {r["method"]: r for r in d["results"]}
assert set(rows) == {"gt", "relaxed", "ipr", "ipr-nomin", "ipr-sr", "fipr", "fipr-r4", "fipr-blur", "fipr-r4-sr"}, list(rows)
gt, ipr, nomin, fipr = rows["gt"], rows["ipr"], rows["ipr-nomin"], rows["fipr"]
# the reference is sdf-gt itself: gt's error is exactly zero
assert gt["error"]["all"]["mse"] == 0.0, gt["error"]["all"]
# every row is also measured against the path-traced reference
for r in rows.values():
    assert "pt-direct" in r["error_vs"], r["method"]
# the pyramid: fewer camera-ray steps, the same number of target rays as gt
assert ipr["counters"]["steps"] < 0.7 * gt["counters"]["steps"], (ipr["counters"]["steps"], gt["counters"]["steps"])
assert ipr["counters"]["rays_level2"] == gt["counters"]["rays_level0"]
# the min filter is what keeps ipr close to the ground truth (Fig. 3)
assert ipr["error"]["all"]["ssim"] > 0.9, ipr["error"]["all"]
assert nomin["error"]["all"]["mse"] > 10 * ipr["error"]["all"]["mse"], (nomin["error"]["all"], ipr["error"]["all"])
# fipr traces its mask (the whole fovea) as ipr does: the same fovea error
assert abs(fipr["error"]["fovea"]["mse"] - ipr["error"]["fovea"]["mse"]) <= 1e-9, (fipr["error"]["fovea"], ipr["error"]["fovea"])
assert 0 < fipr["counters"]["mask_pixels"] < fipr["counters"]["samples"]
assert fipr["counters"]["rays_level2"] == fipr["counters"]["mask_pixels"]
# shadow_reuse (ours) traces fewer shadow steps for nearly the same image
sr = rows["ipr-sr"]
assert sr["counters"]["shadow_steps"] < ipr["counters"]["shadow_steps"], (sr["counters"], ipr["counters"])
assert sr["error"]["all"]["ssim"] > ipr["error"]["all"]["ssim"] - 0.02, (sr["error"]["all"], ipr["error"]["all"])
# refresh 1/4 shades fewer middle-level rays per frame than refresh 1
assert rows["fipr-r4"]["counters"]["refreshed_pixels"] < fipr["counters"]["refreshed_pixels"]
PY
for f in sdf-quality.md sdf-quality/reference.png sdf-quality/ipr.png sdf-quality/fipr-flip.png; do
    [ -s "$OUT/$f" ] || fail "missing $f"
done
# every sdf scenario parses and names methods that exist (a bad one would exit 2 here)
for s in sdf-speed sdf-speed-columns sdf-speed-primitives sdf-speed-grid sdf-quality-columns sdf-quality-primitives sdf-fov; do
    expect 0 "" -- $FOVEA bench $s --check
done
finish
