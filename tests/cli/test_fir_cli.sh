# The instant-radiosity family from the command line: each bad parameter of ir, ir-low and fir exits
# 2 with one line naming the key (VPL count <= 0, more tiles than VPLs, a foveal radius outside
# (0, 1], cube maps below 8 texels), no refused render leaves a file, and each method renders the
# moving Cornell box with --stats reporting its counters (fir: valid, reused and new VPLs, cube maps
# built; the stage timings of the paper's Table 4).
. "$(dirname "$0")/lib.sh"
OUT=$TMP/out.png
R="$FOVEA render cornell-fir --size 24x24"

expect 2 "vpls=" -- $R --method fir --param vpls=0 --out "$OUT"
expect 2 "vpls=" -- $R --method ir --param vpls=-3 --out "$OUT"
expect 2 "vpls=" -- $R --method ir-low --param vpls=0 --out "$OUT"
expect 2 "tiles_x=" -- $R --method fir --param vpls=20 --param tiles_x=5 --param tiles_y=5 --out "$OUT"
expect 2 "radius=" -- $R --method fir --param radius=0 --out "$OUT"
expect 2 "radius=" -- $R --method fir --param radius=1.01 --out "$OUT"
expect 2 "cube_size=" -- $R --method fir --param cube_size=7 --out "$OUT"
expect 2 "cube_size=" -- $R --method ir-low --param cube_size=2 --out "$OUT"
# maps too large to allocate are the parameters' fault (exit 2, not 1); AddressSanitizer's
# allocator aborts on such a request instead of failing it, so only the plain build asks
if [ "${FOVEA_SANITIZED:-0}" != 1 ]; then
  expect 2 "the cube maps need 393.2 GB" -- $R --method fir --param vpls=1000000 --param candidates=10 --size 32x32 --out "$OUT"
fi
expect 2 "filter=" -- $R --method fir --param filter=median --out "$OUT"
expect 2 "unknown parameter 'cube_size'" -- $R --method ir --param cube_size=64 --out "$OUT"
[ -e "$OUT" ] && fail "a refused render left $OUT behind"

for m in ir ir-low fir; do
  expect 0 "" -- $R --method $m --param vpls=50 --frames 2 --stats --out "$TMP/$m.png"
  [ -s "$TMP/${m}_0001.png" ] || fail "$m wrote no second frame"
done
$R --method fir --param vpls=50 --frames 3 --stats --out "$TMP/f.png" 2>"$TMP/stats" >/dev/null || fail "fir --stats failed"
for k in valid_vpls= reused_vpls= new_vpls= cube_maps_built= voxelize vpl_generation cube_maps shading; do
  grep -q "$k" "$TMP/stats" || fail "fir --stats does not report $k: $(cat "$TMP/stats")"
done
finish
