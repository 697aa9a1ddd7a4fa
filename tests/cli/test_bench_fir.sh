# The instant-radiosity benchmarks in quick mode: every fir scenario runs from the scenario files,
# writes its report, and reports what the paper's tables need (E per region, E' over the sequence,
# fir's stage times and VPL counters; one CSV per sweep of fir-params).
. "$(dirname "$0")/lib.sh"
B="$SRC/bench"
for n in fir-quality fir-speed fir-temporal-still fir-params; do
  expect 0 "" -- "$FOVEA" bench --quick --out "$TMP/res" "$B/$n.json"
  [ -s "$TMP/res/$n.json" ] || fail "$n wrote no report"
done
grep -A3 '"temporal"' "$TMP/res/fir-quality.json" | grep -q '"e":[[:space:]]*[0-9]' || fail "fir-quality reports no temporal error (E')"
# the Markdown shows the paper's metrics too: E per region and E' per region, numbers in each row
grep -q "^| method | E fovea | E transition | E periphery | E all | E' fovea" "$TMP/res/fir-quality.md" || fail "fir-quality.md has no E / E' table"
for m in fir ir; do
  row=$(grep -A8 "^| method | E fovea" "$TMP/res/fir-quality.md" | grep "^| $m |")
  echo "$row" | awk -F'|' '{ exit !($3 + 0 > 0 && $7 + 0 > 0) }' || fail "$m: no E or E' in the fovea: $row"
  echo "$row" | grep -Eq '^\| [a-z-]+ (\| ([0-9.e-]+|–) ){8}\|$' ||
    fail "fir-quality.md's E / E' row of $m is not eight numbers (– for its empty transition region): $(grep -A8 '^| method | E fovea' "$TMP/res/fir-quality.md" | grep "^| $m |")"
done
# ... and a path-tracing report does not
"$FOVEA" bench --quick --out "$TMP/res" "$B/pt-cornell.json" >/dev/null 2>&1 || fail "pt-cornell"
grep -q "| E' fovea" "$TMP/res/pt-cornell.md" && fail "pt-cornell.md shows instant radiosity's table"
for k in vpl_generation cube_maps valid_vpls reused_vpls new_vpls cube_maps_built; do
  grep -q "$k" "$TMP/res/fir-speed.json" || fail "fir-speed reports no $k"
done
for p in cube_size vpls radius; do
  [ -s "$TMP/res/fir-params-sweep-$p.csv" ] || fail "fir-params wrote no sweep CSV for $p"
done
finish
