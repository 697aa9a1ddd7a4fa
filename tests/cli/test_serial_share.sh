# Each stage's serial part in `fovea render --stats` and --stats-json (docs/threads.md): the time a
# stage spends outside parallel regions (or in a region's one-thread part). For every stage that
# has one: present, non-negative and at most the stage's time. A stage with no region at all (the
# VPL family's compose, one loop on the rendering thread) is serial throughout: its serial part
# equals its time, by construction. A stage that is one tile loop (pt's trace, ir's shading) is
# almost all parallel: less than half serial, with 2 threads — a bound no load can break, since a
# thread taken off its core inside the loop still counts as inside it.
# Run as `bash test_serial_share.sh FOVEA SRCDIR BUILDDIR`.
. "$(dirname "$0")/lib.sh"

check() { # JSON: every frame's serial parts against its stages; then the named bounds
  python3 - "$@" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
frames = d["frames"] if isinstance(d, dict) else d
bad = []
for f in frames:
    st, se = f["stages_ms"], f.get("serial_ms")
    if not se: bad.append("frame %s: no serial_ms" % f["frame"]); continue
    for k, v in se.items():
        if k not in st: bad.append("%s: serial without a stage" % k)
        elif not (0.0 <= v <= st[k] + 1e-9): bad.append("%s: serial %g of %g ms" % (k, v, st[k]))
    for spec in sys.argv[2:]:
        name, rel, share = spec.split(":")
        if name not in se: bad.append("%s: no serial part" % name); continue
        r = se[name] / st[name] if st[name] > 0 else 0.0
        if rel == "eq" and se[name] != st[name]: bad.append("%s: serial %g != stage %g" % (name, se[name], st[name]))
        if rel == "lt" and not r < float(share): bad.append("%s: serial share %.3f, not below %s" % (name, r, share))
print("\n".join(bad))
sys.exit(1 if bad else 0)
PY
}

"$FOVEA" render cornell-fir --method ir --size 64x48 --frames 2 --threads 2 --stats --stats-json "$TMP/ir.json" \
  --out "$TMP/ir.pfm" 2>"$TMP/ir.err" >/dev/null || fail "ir: render exited $?: $(tail -n 2 "$TMP/ir.err")"
grep -q '^  serial:  gbuffer [0-9.]* ms ([0-9]*%)' "$TMP/ir.err" || fail "ir: --stats prints no serial line: $(tail -n 3 "$TMP/ir.err")"
out=$(check "$TMP/ir.json" compose:eq:1 shading:lt:0.5) || fail "ir: $out"

"$FOVEA" render cornell --method pt --param spp=4 --size 64x48 --frames 2 --threads 2 --stats-json "$TMP/pt.json" \
  --out "$TMP/pt.pfm" --quiet || fail "pt: render exited $?"
out=$(check "$TMP/pt.json" trace:lt:0.5) || fail "pt: $out"

# fir's management is one region with serial steps inside (master): every stage still has its part
"$FOVEA" render cornell-fir --method fir --size 48x36 --frames 2 --threads 2 --stats-json "$TMP/fir.json" \
  --out "$TMP/fir.pfm" --quiet || fail "fir: render exited $?"
out=$(check "$TMP/fir.json" voxelize:lt:1.01 inject:lt:1.01 vpl_generation:lt:1.01 radiosity:lt:1.01 cube_maps:lt:1.01) ||
  fail "fir: $out"

# every method: each of its stages has a serial part (issue 29: --stats reports each stage's share)
for m in $("$FOVEA" methods | awk '/^[a-z]/ {print $1}'); do
  case $m in pm | pm-t | fpm | fpm-guided | ppm) a=(cornell-fpm --param photons=2000) ;; sdf-* | ipr | fipr) a=(sdf-temple) ;;
    ir | ir-low) a=(cornell-fir --param vpls=32) ;; fir) a=(cornell-fir) ;; *) a=(cornell) ;; esac
  [ "$m" = ppm ] && a+=(--param passes=2)
  "$FOVEA" render "${a[@]}" --method "$m" --size 24x16 --threads 2 --stats-json "$TMP/m.json" --out "$TMP/m.pfm" --quiet ||
    { fail "$m: render exited $?"; continue; }
  python3 - "$TMP/m.json" "$m" <<'PY' || fail "$m: a stage without its serial part"
import json, sys
d = json.load(open(sys.argv[1]))
for f in (d["frames"] if isinstance(d, dict) else d):
    missing = [k for k in f["stages_ms"] if k not in (f.get("serial_ms") or {})]
    assert f["stages_ms"] and not missing, (sys.argv[2], missing)
PY
done
finish
