# `fovea bench` in stereo ("stereo": eye separation) and the GPU pacing scenarios: a stereo row's
# left eye is `fovea render --stereo`'s left image pixel for pixel (not the right one), its frame
# is both eyes, a bad separation is refused; every bench/gpu-*.json validates with its cuda rows
# moved to the CPU (a build without CUDA refuses cuda rows, one line, as gpu-pt does), and the
# gaze trace with saccades they use loads.
. "$(dirname "$0")/lib.sh"
cat >"$TMP/st.json" <<'JSON'
{"scene": "cornell", "size": [32, 24], "frames": 2, "repeats": 2, "stereo": 60,
 "gaze": {"fixed": [0.4, 0.5]},
 "reference": {"method": "pt", "params": {"spp": 4}}, "baseline": "pt",
 "methods": [{"label": "pt", "method": "pt", "params": {"spp": 1}}]}
JSON
expect 0 "" -- "$FOVEA" bench "$TMP/st.json" --out "$TMP/o" --quiet
expect 0 "" -- "$FOVEA" render cornell --method pt --spp 1 --stereo 60 --size 32x24 --frames 2 --gaze 0.4,0.5 --out "$TMP/r.png" --quiet
# fovea compare's "all" row: MSE 0 against the left eye, above 0 against the right
mse() { "$FOVEA" compare "$1" "$2" 2>/dev/null | awk '$1 == "all" {print $3}'; }
[ "$(mse "$TMP/o/st/pt.png" "$TMP/r_left_0001.png")" = 0 ] || fail "the stereo bench's image is not render --stereo's left eye"
awk -v m="$(mse "$TMP/o/st/pt.png" "$TMP/r_right_0001.png")" 'BEGIN { exit !(m > 0) }' || fail "the stereo bench's image is the right eye's"
python3 - "$TMP/o/st.json" <<'PY' || fail "the stereo report is wrong"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["stereo"] == 60, d.get("stereo")
assert "stereo, eyes 60 apart" in d["run_description"], d["run_description"]
fm = d["results"][0]["frame_ms"]
assert fm["frames"] == 4 and 0 < fm["p50"] <= fm["p99"] <= fm["max"], fm
PY
# a mono scenario's report says nothing of stereo
sed 's/, "stereo": 60//' "$TMP/st.json" >"$TMP/mono.json"
expect 0 "" -- "$FOVEA" bench "$TMP/mono.json" --out "$TMP/m" --quiet
grep -q '"stereo"' "$TMP/m/mono.json" && fail "a mono report has a stereo field"
for bad in '-1' '"far"' '1e12'; do
  sed "s/\"stereo\": 60/\"stereo\": $bad/" "$TMP/st.json" >"$TMP/bad.json"
  expect 2 "stereo" -- "$FOVEA" bench "$TMP/bad.json" --check
done

# The GPU scenarios, cuda rows moved to the CPU, next to the repository's scenes (their gaze trace
# and scene files are named relative to the scenario).
mkdir -p "$TMP/tree/bench"
ln -s "$SRC/scenes" "$TMP/tree/scenes"
n=0
for j in "$SRC"/bench/gpu-*.json; do
  sed 's/"device": "cuda"/"device": "cpu"/' "$j" >"$TMP/tree/bench/$(basename "$j")"
  expect 0 "" -- "$FOVEA" bench "$TMP/tree/bench/$(basename "$j")" --check
  n=$((n + 1))
done
[ "$n" -ge 7 ] || fail "only $n bench/gpu-*.json found"
# the pacing scenarios: stereo at 1440x1600 per eye, the saccade trace, 90 Hz, cpu and cuda rows
python3 - "$SRC/bench" <<'PY' || fail "the gpu pacing scenarios are not as issue 28 defines them"
import json, sys
b = sys.argv[1]
for name in ("gpu-vp-speed", "gpu-vp-speed-city", "gpu-sdf-speed", "gpu-sdf-speed-columns", "gpu-sdf-speed-primitives"):
    d = json.load(open(f"{b}/{name}.json"))
    assert d["size"] == [1440, 1600] and d["stereo"] > 0 and d["fps"] == 90, name
    assert d["gaze"] == {"trace": "../scenes/gaze-saccades.csv"}, name
    devs = {m["params"]["device"] for m in d["methods"]}
    assert devs == {"cpu", "cuda"}, (name, devs)
    if "sdf" in name:
        assert d["full"]["size"] == [2468, 2740], name
        rows = {(m["method"], m["params"]["spp"], m["params"]["device"]) for m in d["methods"]}
        assert rows == {(m, s, v) for m in ("sdf-gt", "ipr", "fipr") for s in (1, 4, 16) for v in ("cpu", "cuda")}, name
PY
# The trace moves like an eye: the gaze of `fovea render` along it jumps between two frames at
# 90 Hz during the first saccade (0.18-0.23 s) by far more than during the fixation before it.
python3 - "$SRC/scenes/gaze-saccades.csv" <<'PY' || fail "gaze-saccades.csv has no saccade"
import sys
rows = [tuple(map(float, l.split(","))) for l in open(sys.argv[1]) if l[0].isdigit()]
def at(t):
    for (t0, x0, y0), (t1, x1, y1) in zip(rows, rows[1:]):
        if t0 <= t <= t1:
            f = (t - t0) / (t1 - t0)
            return x0 + f * (x1 - x0), y0 + f * (y1 - y0)
step = lambda t: sum((a - b) ** 2 for a, b in zip(at(t + 1 / 90), at(t))) ** 0.5
assert step(0.195) > 10 * step(0.05), (step(0.195), step(0.05))
assert all(0 <= x <= 1 and 0 <= y <= 1 for _, x, y in rows)
assert all(b[0] > a[0] for a, b in zip(rows, rows[1:]))
PY
expect 0 "" -- "$FOVEA" render cornell --method pt --spp 1 --size 16x16 --gaze-trace "$SRC/scenes/gaze-saccades.csv" --frames 2 \
  --out "$TMP/g.png" --quiet
finish
