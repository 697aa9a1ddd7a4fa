# Every result says how it was made (issue 27): a bench report holds the build, the machine, the
# threads it used, the run's real settings and typed parameters; rendered PNG/EXR carry their
# metadata, which `fovea compare` takes the gaze from and refuses to mix; `render --stats-json`
# logs every frame; the build-time header records a git commit, its dirty flag, or "unknown".
. "$(dirname "$0")/lib.sh"
OUT=$TMP/bench
cat >"$TMP/tiny.json" <<JSON
{"name": "tiny", "description": "Two pm settings at 64x48.", "scene": "cornell", "size": [64, 48], "frames": 1, "repeats": 3,
 "reference": {"method": "pt", "params": {"spp": 4}}, "baseline": "pm",
 "methods": [{"label": "pm", "method": "pm", "params": {"photons": 3000, "filter": "off"}},
             {"label": "pt", "method": "pt", "params": {"spp": 1}}],
 "quick": {"size": [32, 24], "repeats": 2}}
JSON
OMP_NUM_THREADS=3 expect 0 "" -- "$FOVEA" bench "$TMP/tiny.json" --quick --out "$OUT" --quiet
# The result table on stdout when the run ends, even with --quiet: one row per method.
[ "$(grep -c '^| p[mt] | ' "$TMP/out")" = 2 ] || fail "bench printed no result table: $(head -c 300 "$TMP/out")"
# --list: each scenario with the first sentence of its description.
FOVEA_BENCH_DIR="$TMP" "$FOVEA" bench --list >"$TMP/list.txt" 2>&1
grep -q "^  tiny  *Two pm settings at 64x48.$" "$TMP/list.txt" || fail "bench --list: $(head -n 3 "$TMP/list.txt")"
python3 - "$OUT/tiny.json" <<'PY' || fail "tiny.json lacks provenance or typed parameters"
import json, re, sys
d = json.load(open(sys.argv[1]))
p = d["provenance"]
assert p["commit"] == "unknown" or re.fullmatch(r"[0-9a-f]{40}", p["commit"]), p["commit"]
assert p["dirty"] in (True, False, None), p["dirty"]
for k in ("fovea_version", "build_type", "compiler", "embree", "cpu", "os", "date"):
    assert isinstance(p[k], str) and p[k], k
assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", p["date"]), p["date"]
assert p["cores"] >= 1
# --threads 0 (all) ran on the 3 threads OMP_NUM_THREADS allowed: the report says 3, not 0.
assert p["threads"] == 3 and d["threads"] == 3, (p["threads"], d["threads"])
# The quick overrides, not the file's top level: 32x24, 2 repeats, stated in the run's description.
assert d["size"] == [32, 24] and d["repeats"] == 2 and d["mode"] == "quick", (d["size"], d["repeats"])
assert "This quick run" in d["run_description"] and "32x24" in d["run_description"], d["run_description"]
assert "2 repeat(s)" in d["run_description"], d["run_description"]
rows = {r["method"]: r for r in d["results"]}
# Numbers as numbers, switches as booleans.
assert rows["pm"]["params"] == {"photons": 3000, "filter": False}, rows["pm"]["params"]
assert rows["pt"]["params"] == {"spp": 1}, rows["pt"]["params"]
ref = d["reference"]
assert ref["method"] == "pt" and ref["params"] == {"spp": 4} and ref["stream"] == "reference", ref
assert ref["seed"] != d["seed"], "the reference must not draw from the methods' seed"
for r in d["results"]:
    t = r["ms_per_frame"]
    assert t["min"] <= t["median"] <= t["max"] and len(t["repeats"]) == 2, t
    assert r["stages_ms_range"], r["method"]
    for name, s in r["stages_ms_range"].items():
        assert s["min"] <= s["median"] <= s["max"], (name, s)
        assert s["median"] == r["stages_ms"][name]
PY
# The bench's images carry the same metadata as fovea render's: compare finds their gaze (the
# scene's own, the centre here) and the reference says it is pt, not foveated.
expect 0 "" -- "$FOVEA" compare "$OUT/tiny/reference.png" "$OUT/tiny/pm.png"
grep -q "gaze 0.5,0.5 from the metadata of $OUT/tiny/pm.png" "$TMP/err" || fail "bench images carry no gaze: $(cat "$TMP/err")"
LC_ALL=C grep -aq "fovea:foveated" "$OUT/tiny/reference.png" && LC_ALL=C grep -aq '{"spp":4}' "$OUT/tiny/reference.png" ||
  fail "the bench's reference image does not say how it was made"
grep -q "^Made by fovea .*commit" "$OUT/tiny.md" || fail "tiny.md does not say which build made it"
grep -q "This quick run: scene \`cornell\`, 32x24" "$OUT/tiny.md" || fail "tiny.md does not state the quick run's settings"
grep -q "The scenario (its default run): Two pm settings at 64x48." "$OUT/tiny.md" || fail "tiny.md presents the default run's description as this run's"

grep -q "^Made by fovea .*, with \`fovea bench $TMP/tiny.json --quick --out $OUT --quiet\`.$" "$OUT/tiny.md" || fail "tiny.md does not give the command"
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if d["provenance"]["command"].startswith("fovea bench ") and d["provenance"]["command"].endswith(" --quick --out "+sys.argv[2]+" --quiet") else 1)' "$OUT/tiny.json" "$OUT" ||
  fail "tiny.json does not give the command"
# fovea --version names the build.
"$FOVEA" --version | grep -qE "^fovea [0-9.]+, commit ([0-9a-f]{12}|unknown)" || fail "fovea --version: $("$FOVEA" --version)"

# Rendered images carry their metadata: two renders for different gazes, one PNG, one EXR.
R="$FOVEA render cornell --size 32x24 --quiet"
expect 0 "" -- $R --method fpm --param photons=2000 --gaze 0.25,0.75 --seed 7 --out "$TMP/a.png" --stats-json "$TMP/a.json"
expect 0 "" -- $R --method fpm --param photons=2000 --gaze 0.25,0.75 --seed 8 --out "$TMP/b.exr"
expect 0 "" -- $R --method fpm --param photons=2000 --gaze 0.75,0.25 --out "$TMP/c.png"
expect 0 "" -- $R --method pt --spp 1 --out "$TMP/ref.png"
for f in a.png b.exr; do
  LC_ALL=C grep -aq "fovea:gaze" "$TMP/$f" && LC_ALL=C grep -aq "fovea:method" "$TMP/$f" && LC_ALL=C grep -aq "fovea:commit" "$TMP/$f" ||
    fail "$f carries no fovea metadata"
done
# compare without --gaze takes the test image's recorded gaze and says so; the regions then sit
# where that render put them (the JSON's gaze).
expect 0 "" -- "$FOVEA" compare "$TMP/ref.png" "$TMP/a.png" --json
grep -q "gaze 0.25,0.75 from the metadata of $TMP/a.png" "$TMP/err" || fail "compare did not say where its gaze came from: $(cat "$TMP/err")"
grep -q '"gaze": \[0.25, 0.75\]' "$TMP/out" || fail "compare did not use the recorded gaze: $(grep gaze "$TMP/out")"
expect 0 "" -- "$FOVEA" compare "$TMP/b.exr" "$TMP/a.png" --json
grep -q '"gaze": \[0.25, 0.75\]' "$TMP/out" || fail "compare of an EXR and a PNG with the same gaze"
# --gaze wins, silently.
expect 0 "" -- "$FOVEA" compare "$TMP/ref.png" "$TMP/a.png" --json --gaze 0.5,0.5
grep -q '"gaze": \[0.5, 0.5\]' "$TMP/out" && [ ! -s "$TMP/err" ] || fail "--gaze did not override the metadata"
# Two foveated renders for different gazes are refused, with the way out in the one line.
expect 2 "pass --allow-gaze-mismatch" -- "$FOVEA" compare "$TMP/a.png" "$TMP/c.png"
expect 2 "rendered for gaze 0.25,0.75" -- "$FOVEA" compare "$TMP/a.png" "$TMP/c.png" --gaze 0.5,0.5
expect 0 "" -- "$FOVEA" compare "$TMP/a.png" "$TMP/c.png" --allow-gaze-mismatch --json
grep -q '"gaze": \[0.75, 0.25\]' "$TMP/out" || fail "with --allow-gaze-mismatch the test image's gaze is used"
# The reference is pt (not foveated, recorded at the centre): its gaze does not matter, and the
# foveated image's gaze places the regions, whichever side it is on.
expect 0 "" -- "$FOVEA" compare "$TMP/ref.png" "$TMP/c.png" --json
grep -q '"gaze": \[0.75, 0.25\]' "$TMP/out" || fail "compare with a pt reference: $(grep gaze "$TMP/out")"
expect 0 "" -- "$FOVEA" compare "$TMP/c.png" "$TMP/ref.png" --json
grep -q '"gaze": \[0.75, 0.25\]' "$TMP/out" || fail "compare with pt as TEST took pt's gaze: $(grep gaze "$TMP/out")"
# --no-metadata writes the bare image.
expect 0 "" -- $R --method pt --spp 1 --out "$TMP/bare.png" --no-metadata
LC_ALL=C grep -aq "fovea:" "$TMP/bare.png" && fail "--no-metadata still wrote metadata"

# --stats-json: every frame's stages and counters, the method's typed parameters, the build.
expect 0 "" -- $R --method pt --spp 2 --frames 3 --out "$TMP/f.png" --stats-json "$TMP/s.json" --threads 2
python3 - "$TMP/s.json" "$TMP/a.json" <<'PY' || fail "the --stats-json log is incomplete"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["complete"] is True and d["method"] == "pt" and d["params"] == {"spp": 2}, d
assert d["provenance"]["threads"] == 2
assert [f["frame"] for f in d["frames"]] == [0, 1, 2]
for f in d["frames"]:
    assert f["ms"] > 0 and f["stages_ms"] and f["counters"]["samples"] == 32 * 24 * 2, f
a = json.load(open(sys.argv[2]))
assert a["params"] == {"photons": 2000} and a["frames"][0]["gaze"] == [[0.25, 0.75]], a["frames"][0]
PY
expect 2 "--stats-json" -- $R --out "$TMP/g.png" --stats-json "$TMP/no/such/dir/s.json"
[ -e "$TMP/g.png" ] && fail "a bad --stats-json path still rendered"

# The build-time header: a tree that is not a git work tree says "unknown"; a commit is recorded
# with its dirty flag, which an edit of a tracked file sets.
if command -v git >/dev/null && command -v cmake >/dev/null; then
  gen() { cmake -DSRC="$1" -DIN="$SRC/cmake/fv_build_info.h.in" -DOUT="$TMP/h.h" -DBUILD_TYPE=Release -DCOMPILER=cc -DSANITIZE=0 \
            -P "$SRC/cmake/build_info.cmake" >/dev/null 2>&1; }
  mkdir -p "$TMP/tar/src" && echo x >"$TMP/tar/src/a.c"
  gen "$TMP/tar/src"
  grep -q 'FV_BUILD_COMMIT "unknown"' "$TMP/h.h" && grep -q 'FV_BUILD_DIRTY -1' "$TMP/h.h" || fail "a tree without .git: $(cat "$TMP/h.h")"
  git -C "$TMP/tar" init -q && git -C "$TMP/tar" -c user.name=t -c user.email=t@t add . && git -C "$TMP/tar" -c user.name=t -c user.email=t@t commit -qm x
  # A subfolder of another repository is not that repository's build: still unknown.
  gen "$TMP/tar/src"
  grep -q 'FV_BUILD_COMMIT "unknown"' "$TMP/h.h" || fail "a subfolder of another repository took its commit"
  gen "$TMP/tar"
  head=$(git -C "$TMP/tar" rev-parse HEAD)
  grep -q "FV_BUILD_COMMIT \"$head\"" "$TMP/h.h" && grep -q 'FV_BUILD_DIRTY 0' "$TMP/h.h" || fail "a clean checkout: $(cat "$TMP/h.h")"
  echo y >>"$TMP/tar/src/a.c"
  gen "$TMP/tar"
  grep -q 'FV_BUILD_DIRTY 1' "$TMP/h.h" || fail "an edited checkout is not dirty: $(cat "$TMP/h.h")"
fi
finish
