# The bench estimates its reference's own error and warns when the reference is too noisy for the
# errors it measures (issue 27; src/bench/ref_noise.c):
#  - the estimate (a probe with 1/4 of the samples on its own stream) is close to the reference's
#    true MSE, measured here against a render with 64x the samples;
#  - a reference no better than a measured method gets the warning, in one line on stderr, in the
#    JSON and in the Markdown, with the samples that fix it; a good reference gets none;
#  - a reference without a samples-per-pixel parameter says why it was not estimated.
# Run as `bash test_bench_ref_noise.sh FOVEA SRCDIR BUILDDIR`.
. "$(dirname "$0")/lib.sh"
B="--scene cornell --size 32x32 --repeats 1"

json() { python3 -c "import json, sys; d = json.load(open(sys.argv[1])); print($2)" "$1"; }

# 1. The estimate against the truth: a 32-sample reference, its true error from a 2048-sample render
#    (whose own error, 1/64 of it, is taken off).
"$FOVEA" bench $B --methods pt:spp=1 --reference pt:spp=32 --out "$TMP/a" 2>"$TMP/a.err" || fail "bench a: $(cat "$TMP/a.err")"
ref=$(ls "$TMP"/a/cache/ref-*.pfm | head -1)
[ -f "$ref" ] || fail "no cached reference"
"$FOVEA" render cornell --method pt --spp 2048 --size 32x32 --out "$TMP/truth.pfm" --quiet --no-metadata || fail "truth"
truth=$("$FOVEA" compare "$TMP/truth.pfm" "$ref" --json --gaze 0.5,0.5 | python3 -c 'import json, sys; print(json.load(sys.stdin)["regions"]["all"]["mse"] * 64 / 65)')
report=$(ls "$TMP"/a/*.json | head -1)
est=$(json "$report" 'd["reference"]["noise"]["mse"]["all"]')
probe=$(json "$report" 'd["reference"]["noise"]["probe_spp"]')
echo "32-sample reference: estimated MSE $est, measured $truth (probe of $probe samples)"
[ "$probe" = 8 ] || fail "probe of $probe samples, expected 32 / 4 = 8"
awk -v e="$est" -v t="$truth" 'BEGIN { exit !(e > 0.65 * t && e < 1.35 * t) }' || fail "the estimate $est is not within 35% of the measured $truth"
[ "$(json "$report" 'd["reference"]["noise"]["warning"]')" = None ] || fail "a 1-sample method against a 32-sample reference got a warning"
grep -q "too noisy" "$TMP/a.err" && fail "warning on stderr for a good reference: $(cat "$TMP/a.err")"

# 2. A reference as noisy as the method it measures: the warning, with the fix (half the measured
#    error is the reference's, so 64 x 0.9 / 0.1 = 576 -> 1024 samples).
"$FOVEA" bench $B --methods pt:spp=64 --reference pt:spp=64 --out "$TMP/b" 2>"$TMP/b.err" || fail "bench b: $(cat "$TMP/b.err")"
n=$(grep -c "too noisy" "$TMP/b.err")
[ "$n" = 1 ] || fail "expected one warning line on stderr, got $n: $(cat "$TMP/b.err")"
grep -q "spp=1024" "$TMP/b.err" || fail "the warning does not say spp=1024: $(cat "$TMP/b.err")"
report=$(ls "$TMP"/b/*.json | head -1)
json "$report" 'd["reference"]["noise"]["warning"]' | grep -q "too noisy" || fail "no warning in the JSON"
grep -q "Warning:.*too noisy" "$TMP"/b/*.md || fail "no warning in the Markdown"
# ... and the fix it names silences it
"$FOVEA" bench $B --methods pt:spp=64 --reference pt:spp=1024 --out "$TMP/c" 2>"$TMP/c.err" || fail "bench c"
grep -q "too noisy" "$TMP/c.err" && fail "still too noisy with the samples the warning named: $(cat "$TMP/c.err")"

# 3. A reference without samples per pixel (pm: photons) is not estimated, and says why.
"$FOVEA" bench $B --methods pt:spp=1 --reference pm:photons=2000 --out "$TMP/d" 2>"$TMP/d.err" || fail "bench d: $(cat "$TMP/d.err")"
report=$(ls "$TMP"/d/*.json | head -1)
why=$(json "$report" 'd["reference"]["noise"].get("why_not", "")')
[ -n "$why" ] || fail "no reason for the missing estimate"
echo "pm reference: $why"
finish
