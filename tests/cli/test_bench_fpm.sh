# `fovea bench fpm-speed --quick` (its quick block shrunk): the photon mapping scenario runs end
# to end and reports what the paper's Table 2 and Fig. 9 need: per-stage times, the foveated
# paths' reuse rate, and the PM_eq search; fpm-guided beside them with its stages and the passes pm
# needs to match its fovea; bad fpm and fpm-guided parameters exit 2.
. "$(dirname "$0")/lib.sh"
OUT=$TMP/bench
# The scenario itself parses and names methods that exist; the run below is its own --quick block
# shrunk (a ninth of the pixels, fewer photons, reference passes and search values), written
# beside it: every method, stage, counter and search the report needs still runs, and none of
# the checks below depends on the size (the whole quick block cost 67 s of CPU here, 210 s of the
# suite under the sanitizers; this one 14 s). fpm-wo's reuse rate of 0 is still checked against
# fpm's, which stays near 0.28 at this size.
expect 0 "" -- $FOVEA bench fpm-speed --check
python3 - "$SRC/bench/fpm-speed.json" "$TMP/fpm-speed.json" <<'PY' || fail "cannot shrink fpm-speed.json"
import json, sys
d = json.load(open(sys.argv[1]))
q = d["quick"]
q["size"] = [45, 50]
q["reference"]["params"].update(photons=4000, passes=12)
for m in q["methods"]:
    m["params"]["photons"] = 4000
for m in q["match"]:
    m["values"] = [1000, 2000, 4000] if m["param"] == "photons" else [1, 2]
json.dump(d, open(sys.argv[2], "w"))
PY
expect 0 "" -- $FOVEA bench "$TMP/fpm-speed.json" --quick --out "$OUT" --quiet
python3 - "$OUT/fpm-speed.json" <<'PY' || fail "fpm-speed.json is incomplete or wrong"
import json, sys
d = json.load(open(sys.argv[1]))
rows = {r["method"]: r for r in d["results"]}
assert set(rows) == {"fpm-guided", "fpm", "fpm-wo", "pm", "pm-t", "pm-eq", "pm-eq-guided"}, list(rows)
f = rows["fpm"]
for s in ("light_tracing", "tpm", "foveated_tracing", "render"):
    assert s in f["stages_ms"], s
assert 0.0 <= f["counters"]["reuse_rate"] <= 1.0
assert rows["fpm-wo"]["counters"]["reuse_rate"] == 0.0
assert f["counters"]["foveated_photons"] > 0 and f["counters"]["light_photons"] > 0
assert "tpm" not in rows["pm"]["stages_ms"]
m = rows["pm-eq"]["match"]
assert m["target"] == "fpm" and m["region"] == "fovea" and m["param"] == "photons"
g = rows["fpm-guided"]
for s in ("light_tracing", "focus_cells", "guided_tracing", "render", "fill"):
    assert s in g["stages_ms"], s
assert g["counters"]["guided_photons"] > 0 and g["counters"]["focus_cells"] > 0
m = rows["pm-eq-guided"]["match"]
assert m["target"] == "fpm-guided" and m["param"] == "passes"
for r in rows.values():
    assert r["temporal"]["fovea"]["mse"] is not None  # two frames: MSE' exists
PY
expect 2 "fov_fraction" -- $FOVEA render cornell-fpm --method fpm --param fov_fraction=1.5 --size 8x8 --out "$TMP/x.png"
expect 2 "photons" -- $FOVEA render cornell --method pm --param photons=0 --size 8x8 --out "$TMP/x.png"
expect 2 "radius" -- $FOVEA render cornell --method pm-t --param radius=-1 --size 8x8 --out "$TMP/x.png"
# a radius beyond every coordinate the scene may have (issue 25, item 10), for each photon mapper
for m in pm pm-t fpm fpm-guided ppm; do
  expect 2 "parameter radius=1e30: out of range [0, 1e+09]" -- $FOVEA render cornell-fpm --method $m --param radius=1e30 --size 8x8 --out "$TMP/x.png"
done
expect 2 "fovea_spp" -- $FOVEA render cornell-fpm --method fpm-guided --param fovea_spp=0 --size 8x8 --out "$TMP/x.png"
expect 2 "periphery_step" -- $FOVEA render cornell-fpm --method fpm-guided --param periphery_step=0 --size 8x8 --out "$TMP/x.png"
expect 2 "fovea_spp" -- $FOVEA render cornell-fpm --method fpm-guided --spp 1000 --size 8x8 --out "$TMP/x.png"
[ -e "$TMP/x.png" ] && fail "a failed render left x.png"
finish
