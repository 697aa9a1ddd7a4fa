# `fovea bench fpm-speed --quick`: the photon mapping scenario runs end to end and reports what the
# paper's Table 2 and Fig. 9 need: per-stage times, the foveated paths' reuse rate, and the PM_eq
# search; bad fpm parameters exit 2.
. "$(dirname "$0")/lib.sh"
OUT=$TMP/bench
expect 0 "" -- $FOVEA bench fpm-speed --quick --out "$OUT" --quiet
python3 - "$OUT/fpm-speed.json" <<'PY' || fail "fpm-speed.json is incomplete or wrong"
import json, sys
d = json.load(open(sys.argv[1]))
rows = {r["method"]: r for r in d["results"]}
assert set(rows) == {"fpm", "fpm-wo", "pm", "pm-t", "pm-eq"}, list(rows)
f = rows["fpm"]
for s in ("light_tracing", "tpm", "foveated_tracing", "render"):
    assert s in f["stages_ms"], s
assert 0.0 <= f["counters"]["reuse_rate"] <= 1.0
assert rows["fpm-wo"]["counters"]["reuse_rate"] == 0.0
assert f["counters"]["foveated_photons"] > 0 and f["counters"]["light_photons"] > 0
assert "tpm" not in rows["pm"]["stages_ms"]
m = rows["pm-eq"]["match"]
assert m["target"] == "fpm" and m["region"] == "fovea" and m["param"] == "photons"
for r in rows.values():
    assert r["temporal"]["fovea"]["mse"] is not None  # two frames: MSE' exists
PY
expect 2 "fov_fraction" -- $FOVEA render cornell-fpm --method fpm --param fov_fraction=1.5 --size 8x8 --out "$TMP/x.png"
expect 2 "photons" -- $FOVEA render cornell --method pm --param photons=0 --size 8x8 --out "$TMP/x.png"
expect 2 "radius" -- $FOVEA render cornell --method pm-t --param radius=-1 --size 8x8 --out "$TMP/x.png"
[ -e "$TMP/x.png" ] && fail "a failed render left x.png"
finish
