# scripts/check-includes (ctest check_includes) passes on the tree and fails, naming the file, on
# each kind of fault it exists for: an upward include, a reach into another module's private
# header, a method's name compared outside src/technique/, an allowed exception no longer there.
. "$(dirname "$0")/lib.sh"
CHECK=$SRC/scripts/check-includes

python3 "$CHECK" "$SRC" >"$TMP/out" 2>&1 || fail "check-includes fails on the tree: $(cat "$TMP/out")"

# tree NAME: a copy of the sources the script reads, to break one way.
tree() {
  mkdir -p "$TMP/$1"
  cp -r "$SRC/src" "$SRC/include" "$SRC/tools" "$TMP/$1/"
  T=$TMP/$1
}
# refused NAME NEEDLE: the script fails on tree NAME and says NEEDLE.
refused() {
  if python3 "$CHECK" "$TMP/$1" >"$TMP/$1.out" 2>&1; then
    fail "$1: check-includes passed"
  else
    grep -qF -- "$2" "$TMP/$1.out" || fail "$1: output lacks '$2': $(cat "$TMP/$1.out")"
  fi
}

tree up
printf '#include "fovea/frame.h"\n' >>"$T/src/core/csv.c"
refused up 'src/core/csv.c: includes fovea/frame.h: core may not know technique'

tree sideways
printf '#include "gaze/overlay.h"\n' >>"$T/src/filter/grid.h"
refused sideways 'src/filter/grid.h: includes gaze/overlay.h: filter may not know gaze'

tree private
printf '#include "scene/load_impl.h"\n' >>"$T/src/bench/scenario.c"
refused private 'src/bench/scenario.c: includes scene/load_impl.h, a private header of scene'

tree name
printf 'static int f(const char *m) { return strcmp(m, "fipr") == 0; }\n' >>"$T/src/drive/driver.c"
refused name 'src/drive/driver.c:'
refused name 'compares with the method name "fipr"'

tree stale
sed -i '/#include "kernel\/kpath_impl.h"/d' "$T/src/transport/path.c"
refused stale 'allowed but no longer found: src/transport/path.c -> kernel/kpath_impl.h'

finish
