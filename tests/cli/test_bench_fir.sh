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
for k in vpl_generation cube_maps valid_vpls reused_vpls new_vpls cube_maps_built; do
  grep -q "$k" "$TMP/res/fir-speed.json" || fail "fir-speed reports no $k"
done
for p in cube_size vpls radius; do
  [ -s "$TMP/res/fir-params-sweep-$p.csv" ] || fail "fir-params wrote no sweep CSV for $p"
done
finish
