# The library boundary: libfovea.so exports exactly the functions the public headers declare with
# FV_API, all named fv_*; nothing internal leaks (the build hides everything else), and nothing
# declared is missing. Run as `bash test_abi.sh FOVEA SRCDIR BUILDDIR`.
. "$(dirname "$0")/lib.sh"
BUILD=${3:-$(dirname "$FOVEA")}
SO=$(ls "$BUILD"/libfovea.so 2>/dev/null | head -n 1)
[ -n "$SO" ] || { fail "no libfovea.so in $BUILD"; finish; }
nm -D --defined-only "$SO" | awk '$2 == "T" || $2 == "D" || $2 == "B" || $2 == "R" {print $3}' | sort -u >"$TMP/exported"
# Declared: the function name before '(' on every FV_API line of include/fovea/*.h.
grep -h '^FV_API' "$SRC"/include/fovea/*.h | sed -E 's/\(.*//; s/.*[ *]([a-z_0-9]+)$/\1/' | sort -u >"$TMP/declared"
[ -s "$TMP/declared" ] || fail "no FV_API declarations found"
bad=$(grep -v '^fv_' "$TMP/exported" | head -n 5)
[ -z "$bad" ] || fail "exported symbols not named fv_*: $bad"
extra=$(comm -23 "$TMP/exported" "$TMP/declared" | head -n 10)
[ -z "$extra" ] || fail "exported but not declared FV_API in include/fovea: $extra"
missing=$(comm -13 "$TMP/exported" "$TMP/declared" | head -n 10)
[ -z "$missing" ] || fail "declared FV_API but not exported (or not defined): $missing"
n=$(wc -l <"$TMP/exported")
[ "$n" -gt 50 ] || fail "only $n exported symbols"
finish
