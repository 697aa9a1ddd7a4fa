# `fovea bench`: the pt-cornell scenario in quick mode writes a complete JSON report whose errors
# fall with spp in every region; the reference is cached; bad scenarios exit 2.
. "$(dirname "$0")/lib.sh"
B="$FOVEA bench"
OUT=$TMP/bench
expect 0 "" -- $B pt-cornell --quick --out "$OUT" --quiet
python3 - "$OUT/pt-cornell.json" <<'PY' || fail "pt-cornell.json is incomplete or wrong"
import json, sys
d = json.load(open(sys.argv[1]))
rows = d["results"]
assert len(rows) == 3, rows
for r in rows:
    for k in ("method", "params", "ms_per_frame", "stages_ms", "speedup", "error", "temporal", "counters", "images"):
        assert k in r, k
    assert r["ms_per_frame"]["min"] <= r["ms_per_frame"]["median"] <= r["ms_per_frame"]["max"]
    # frame pacing over every timed frame of every repeat: ordered, and the worst frame is at least
    # the slowest repeat's mean frame (a mean never exceeds its largest term)
    fm = r["frame_ms"]
    assert fm["frames"] == d["repeats"] * d["frames"], (fm, d["repeats"], d["frames"])
    assert 0.0 < fm["p50"] <= fm["p99"] <= fm["max"], fm
    assert fm["max"] >= r["ms_per_frame"]["max"] * (1 - 1e-12), (fm, r["ms_per_frame"])
    for g in ("fovea", "transition", "periphery", "all"):
        for m in ("mse", "ssim", "flip"):
            assert r["error"][g][m] is not None, (g, m)
    assert r["counters"]["rays"] > 0
    # every stage's serial share (as --stats-json gives it), a fraction of the stage's time
    ss = r["stages_serial_share"]
    assert set(ss) == set(r["stages_ms"]), (ss, r["stages_ms"])
    assert all(0.0 <= v <= 1.0 for v in ss.values()), ss
spp = [int(r["params"]["spp"]) for r in rows]
assert spp == [1, 4, 16], spp
for g in ("fovea", "transition", "periphery", "all"):
    e = [r["error"][g]["mse"] for r in rows]
    assert e[0] > e[1] > e[2], (g, e)
base = [r for r in rows if r["method"] == d["baseline"]][0]
assert abs(base["speedup"] - 1.0) < 1e-9
PY
for f in pt-cornell.md pt-cornell-sweep.csv pt-cornell/reference.png pt-cornell/pt-spp=4.png pt-cornell/pt-spp=4-flip.png pt-cornell/pt-spp=4-fovea.png; do
  [ -s "$OUT/$f" ] || fail "missing $f"
done
# Every method's heat map on one scale (FLIP's 0..1), said in the report and in each file, with the
# colour bar's strip below the frame.
python3 - "$OUT" <<'PY' || fail "the heat maps do not share one stated scale"
import json, struct, sys, zlib
out = sys.argv[1]
d = json.load(open(f"{out}/pt-cornell.json"))
assert d["heatmaps"] == {"metric": "flip", "max": 1, "shared": True}, d["heatmaps"]
def png(path):
    data, pos, text = open(path, "rb").read(), 8, {}
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR": w, h = struct.unpack(">II", body[:8])
        if kind == b"tEXt":
            k, v = body.split(b"\0", 1)
            text[k.decode()] = v.decode()
        pos += 12 + n
    return w, h, text
for r in d["results"]:
    w, h, text = png(f"{out}/{r['images']['flip']}")
    assert text.get("fovea:heatmap") == "FLIP" and text.get("fovea:heatmap_max") == "1", (r["images"]["flip"], text)
    assert w >= d["size"][0] and h > d["size"][1], (w, h, d["size"])
PY
# The Markdown table's pacing column says the JSON's p50 / p99 / worst, rounded to 0.1 ms.
python3 - "$OUT" <<'PY' || fail "pt-cornell.md's frame p50 / p99 / worst column disagrees with the JSON"
import json, sys
out = sys.argv[1]
d = json.load(open(f"{out}/pt-cornell.json"))
lines = open(f"{out}/pt-cornell.md").read().splitlines()
head = [l for l in lines if l.startswith("| method | params | ms/frame |")][0].split("|")
col = [c.strip() for c in head].index("frame p50 / p99 / worst")
for r in d["results"]:
    row = [l for l in lines if l.startswith(f"| {r['method']} |")][0].split("|")
    got = [float(x) for x in row[col].split("/")]
    fm = r["frame_ms"]
    assert all(abs(g - fm[k]) <= 0.05 + 1e-9 for g, k in zip(got, ("p50", "p99", "max"))), (got, fm)
PY
# Pacing over several frames and repeats: 5 frames x 3 repeats = 15 timed frames per row; with
# nearest rank, p50 is the 8th of them and p99 the 15th, the worst (fewer than 100 frames).
expect 0 "" -- $B --scene cornell --methods pt:spp=1,pt:spp=2 --reference pt:spp=4 --frames 5 --size 24x24 --repeats 3 \
  --out "$TMP/pace" --quiet
python3 - "$TMP/pace" <<'PY' || fail "the 15-frame bench's frame pacing is wrong"
import glob, json, sys
d = json.load(open(glob.glob(f"{sys.argv[1]}/*.json")[0]))
assert d["frames"] == 5 and d["repeats"] == 3, (d["frames"], d["repeats"])
for r in d["results"]:
    fm, ms = r["frame_ms"], r["ms_per_frame"]
    assert fm["frames"] == 15, fm
    assert 0.0 < fm["p50"] <= fm["p99"] == fm["max"], fm
    # the worst frame is at least the slowest repeat's mean (a mean never exceeds its largest term)
    assert fm["max"] >= ms["max"] * (1 - 1e-12), (fm, ms)
PY
grep -q "on one scale, shared by every method: 0 (no error) to 1" "$OUT/pt-cornell.md" || fail "pt-cornell.md does not state the heat maps' scale"
ls "$OUT"/cache/ref-*.pfm >/dev/null 2>&1 || fail "no cached reference"
expect 0 "" -- $B pt-cornell --quick --out "$OUT" --repeats 1
grep -q "from the cache" "$TMP/err" || fail "second run did not use the cached reference"

expect 2 "unknown scenario 'nope'" -- $B nope
printf '{\n  "scene": "cornell",\n  "reference": {"method": "pt"}\n  "methods": []\n}\n' > "$TMP/bad1.json"
expect 2 "bad1.json:4:" -- $B "$TMP/bad1.json" --out "$OUT"
printf '{"scene": "cornell", "reference": {"method": "pt"}, "methods": [{"method": "pt"}], "sizes": [8, 8]}' > "$TMP/bad2.json"
expect 2 "unknown field 'sizes'" -- $B "$TMP/bad2.json" --out "$OUT"
printf '{"scene": "cornell", "reference": {"method": "pt"}, "methods": [{"method": "pt"}], "gaze": {"fixed": [1.2, 0.5]}}' > "$TMP/bad3.json"
expect 2 "gaze" -- $B "$TMP/bad3.json" --out "$OUT"
printf '{"scene": "cornell", "reference": {"method": "pt"}, "methods": [{"method": "warp"}]}' > "$TMP/bad4.json"
expect 2 "unknown method 'warp'" -- $B "$TMP/bad4.json" --out "$OUT"
printf '{"scene": "cornell", "reference": {"method": "pt"}, "methods": [{"method": "pt", "params": {"sp": 4}}], "size": [8, 8]}' > "$TMP/bad5.json"
expect 2 "unknown parameter 'sp'" -- $B "$TMP/bad5.json" --out "$OUT" --quiet
printf '{"scene": "cornell", "reference": {"method": "pt"}, "methods": [{"method": "pt"}], "size": [100000, 8]}' > "$TMP/bad6.json"
expect 2 "size" -- $B "$TMP/bad6.json" --out "$OUT"
expect 0 "" -- $B pt-cornell --check

# A second reference: every row also reports its error against it.
printf '{"scene": "cornell", "size": [16, 16], "repeats": 1, "reference": {"method": "pt", "params": {"spp": 16}},
 "extra_references": [{"label": "pt-hi", "method": "pt", "params": {"spp": 32}}], "methods": [{"method": "pt", "params": {"spp": 1}}]}' > "$TMP/extra.json"
expect 0 "" -- $B "$TMP/extra.json" --out "$OUT" --quiet
python3 -c 'import json,sys; r=json.load(open(sys.argv[1]))["results"][0]; e=r["error_vs"]["pt-hi"]; assert e["all"]["mse"] > 0 and e["fovea"]["pixels"] if "pixels" in e["fovea"] else True' "$OUT/extra.json" \
  || fail "no error_vs block in extra.json"
# References are drawn from their own random stream: a method identical to the reference (pt at
# 1 spp) is not measured against its own samples, so its error is that of two independent 1-spp
# images, not zero.
printf '{"scene": "cornell", "size": [16, 16], "repeats": 1, "reference": {"method": "pt", "params": {"spp": 1}},
 "methods": [{"method": "pt", "params": {"spp": 1}}]}' > "$TMP/same.json"
expect 0 "" -- $B "$TMP/same.json" --out "$OUT" --quiet
python3 -c 'import json,sys; r=json.load(open(sys.argv[1]))["results"][0]; assert r["error"]["all"]["mse"] > 1e-4, r["error"]["all"]' "$OUT/same.json" \
  || fail "a method identical to the reference measured zero error: the reference shares its random stream"
printf '{"scene": "cornell", "reference": {"method": "pt"}, "extra_references": [{"label": "reference", "method": "pt"}], "methods": [{"method": "pt"}]}' > "$TMP/bad7.json"
expect 2 "'reference' is taken" -- $B "$TMP/bad7.json" --out "$OUT"
# A refused parameter of an extra reference, a method and the reference: one line each and, under
# ASan (scripts/test's second pass), nothing leaked (issue 25, item 10).
for where in '"extra_references": [{"label": "x", "method": "pt", "params": {"spp": [1]}}], "reference": {"method": "pt"}, "methods": [{"method": "pt"}]' \
             '"reference": {"method": "pt", "params": {"spp": {"a": 1}}}, "methods": [{"method": "pt"}]' \
             '"reference": {"method": "pt"}, "methods": [{"method": "pt", "params": {"spp": null}}]'; do
  printf '{"scene": "cornell", %s}' "$where" > "$TMP/bad8.json"
  expect 2 "expected a number, string or boolean" -- $B "$TMP/bad8.json" --check
done
finish
