# `cmake --install` gives a user what they need: into a temporary prefix, then the example
# (examples/) is built from a copy elsewhere against that prefix twice, with pkg-config and with
# find_package(fovea), and each binary renders the same PNG as `fovea render`; the installed tool
# lists and finds its scenarios from an unrelated folder, and the installed scenes resolve their
# files; the installed Python package loads the prefix's library and renders the same PNG. Finally
# the prefix is moved: pkg-config, the tool and the Python package still find everything.
# Run as `bash test_install.sh FOVEA SRCDIR BUILDDIR`; no network, no root.
. "$(dirname "$0")/lib.sh"
BUILD=${3:-$(dirname "$FOVEA")}
P=$TMP/prefix
unset FOVEA_BENCH_DIR CMAKE_PREFIX_PATH PKG_CONFIG_LIBDIR

if ! cmake --install "$BUILD" --prefix "$P" >"$TMP/install.log" 2>&1; then
  fail "cmake --install $BUILD failed: $(tail -n 5 "$TMP/install.log")"
  finish
fi
PC=$(find "$P" -name fovea.pc | head -n 1)
LIB=$(dirname "$(dirname "$PC")")
for f in "$PC" "$LIB/libfovea.so" "$LIB/cmake/fovea/foveaConfig.cmake" "$LIB/cmake/fovea/foveaConfigVersion.cmake" \
         "$P/include/fovea/fovea.h" "$P/bin/fovea" "$P/share/fovea/bench/pt-cornell.json" "$P/share/fovea/scenes/showroom.json"; do
  [ -s "$f" ] || fail "not installed: ${f#"$P"/}"
done

# A sanitized library needs a sanitized program around it (the runtime must be loaded first).
SAN=""
if readelf -d "$LIB/libfovea.so" 2>/dev/null | grep -q 'libasan'; then SAN="-fsanitize=address,undefined"; fi

is_png() { [ "$(head -c 8 "$1" 2>/dev/null | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ]; }

# The reference: the installed tool renders what the example does (same scene, method, spp, seed).
"$P/bin/fovea" render cornell --method pt --spp 4 --size 64x64 --seed 1 --gaze 0.5,0.5 --no-metadata --out "$TMP/ref.png" --quiet ||
  fail "installed fovea render failed"

# pkg-config, from a copy of examples/ outside the source tree.
export PKG_CONFIG_PATH="$LIB/pkgconfig"
[ "$(realpath "$(pkg-config --variable=prefix fovea)")" = "$(realpath "$P")" ] ||
  fail "fovea.pc prefix is '$(pkg-config --variable=prefix fovea)', expected $P"
pkg-config --static --libs fovea >"$TMP/static.txt" 2>&1 && grep -q -- '-lembree3' "$TMP/static.txt" ||
  fail "pkg-config --static --libs fovea: $(cat "$TMP/static.txt")"
cp -r "$SRC/examples" "$TMP/ex-pc"
rm -rf "$TMP/ex-pc/build" "$TMP/ex-pc/render_cornell"
if make -C "$TMP/ex-pc" CFLAGS="-O2 -Wall -Wextra -Werror $SAN" >"$TMP/make.log" 2>&1; then
  LD_LIBRARY_PATH="$LIB" "$TMP/ex-pc/render_cornell" "$TMP/pc.png" >"$TMP/run.log" 2>&1 ||
    fail "example built with pkg-config failed: $(head -c 400 "$TMP/run.log")"
  is_png "$TMP/pc.png" || fail "example built with pkg-config wrote no PNG"
  cmp -s "$TMP/pc.png" "$TMP/ref.png" || fail "example built with pkg-config differs from fovea render"
else
  fail "make with pkg-config failed: $(tail -n 8 "$TMP/make.log")"
fi
unset PKG_CONFIG_PATH

# CMake: find_package(fovea) + fovea::fovea. CMake's build tree carries the library's path (RPATH).
cp -r "$SRC/examples" "$TMP/ex-cmake"
rm -rf "$TMP/ex-cmake/build"
if cmake -S "$TMP/ex-cmake" -B "$TMP/ex-cmake/build" -DCMAKE_PREFIX_PATH="$P" -DCMAKE_BUILD_TYPE=Release \
     -DCMAKE_C_FLAGS="-Wall -Wextra -Werror $SAN" >"$TMP/cmake.log" 2>&1 &&
   cmake --build "$TMP/ex-cmake/build" >>"$TMP/cmake.log" 2>&1; then
  grep -q "^fovea_DIR:PATH=$P/" "$TMP/ex-cmake/build/CMakeCache.txt" ||
    fail "find_package(fovea) did not find the temporary prefix: $(grep fovea_DIR "$TMP/ex-cmake/build/CMakeCache.txt")"
  "$TMP/ex-cmake/build/render_cornell" "$TMP/cmake.png" >"$TMP/run.log" 2>&1 ||
    fail "example built with CMake failed: $(head -c 400 "$TMP/run.log")"
  is_png "$TMP/cmake.png" || fail "example built with CMake wrote no PNG"
  cmp -s "$TMP/cmake.png" "$TMP/ref.png" || fail "example built with CMake differs from fovea render"
else
  fail "CMake build of the example failed: $(tail -n 8 "$TMP/cmake.log")"
fi

# The example reports a failure in one line.
if [ -x "$TMP/ex-cmake/build/render_cornell" ]; then
  expect 1 "nodir/x.png" -- "$TMP/ex-cmake/build/render_cornell" "$TMP/nodir/x.png"
fi

# The installed tool, from a folder with no bench/ of its own: it lists and finds the installed
# scenarios, not the source tree's.
check_tool() { # $1 = prefix
  local bench
  bench=$(realpath "$1/share/fovea/bench")
  mkdir -p "$TMP/elsewhere"
  (cd "$TMP/elsewhere" && "$1/bin/fovea" bench --list) >"$TMP/list.txt" 2>&1 || fail "$1/bin/fovea bench --list failed"
  grep -qxF "$bench:" "$TMP/list.txt" || fail "bench --list does not show $bench: $(head -c 300 "$TMP/list.txt")"
  grep -qF "$SRC" "$TMP/list.txt" && fail "bench --list of an installed tool shows the source tree"
  for j in "$SRC"/bench/*.json; do
    # each scenario with the first sentence of its description
    grep -qE "^  $(basename "$j" .json) +[^ ]" "$TMP/list.txt" || fail "bench --list lacks $(basename "$j" .json) or its description"
  done
  (cd "$TMP/elsewhere" && "$1/bin/fovea" bench fpm-showroom --check) >"$TMP/check.txt" 2>&1 ||
    fail "installed bench fpm-showroom --check: $(head -c 300 "$TMP/check.txt")"
  grep -qF "$bench/fpm-showroom.json: ok" "$TMP/check.txt" || fail "fpm-showroom not found in $bench: $(cat "$TMP/check.txt")"
}
check_tool "$P"

# The Python package (docs/python.md), with the python3 the build found with numpy (FV_PYTHON,
# set by tests/CMakeLists.txt; empty, e.g. in a sanitized build: skipped): from an unrelated folder,
# without FOVEA_LIB, it loads the prefix's own library, finds the prefix's scenarios and renders
# the example's image, byte for byte.
check_python() { # $1 = prefix
  [ -n "${FV_PYTHON:-}" ] || return 0
  local paths
  paths=$(find "$1" -name _paths.py -path '*/fovea/_paths.py' | head -n 1)
  [ -n "$paths" ] || { fail "the Python package (fovea/_paths.py) is not installed under $1"; return; }
  (cd "$TMP/elsewhere" && env -u FOVEA_LIB PYTHONPATH="$(dirname "$(dirname "$paths")")" "$FV_PYTHON" -B -c '
import os, sys, fovea
prefix = os.path.realpath(sys.argv[1])
assert os.path.realpath(fovea.library_path()).startswith(prefix + "/"), fovea.library_path()
assert os.path.realpath(fovea.find_scenario("pt-cornell")) == prefix + "/share/fovea/bench/pt-cornell.json", fovea.find_scenario("pt-cornell")
fovea.render("cornell", "pt", spp=4, size=(64, 64), seed=1, gaze=(0.5, 0.5)).write(sys.argv[2], metadata=False)
' "$1" "$TMP/py.png") >"$TMP/py.log" 2>&1 || { fail "installed Python package under $1: $(tail -n 3 "$TMP/py.log")"; return; }
  cmp -s "$TMP/py.png" "$TMP/ref.png" || fail "the installed Python package renders another image than fovea render"
}
check_python "$P"

# Scenarios name scene files relative to themselves ("../scenes/showroom.json"): each must exist in
# the installed layout and load, with the files it names in turn (meshes, gaze trace).
for j in "$P"/share/fovea/bench/*.json; do
  scene=$(sed -n 's/^ *"scene": *"\([^"]*\)".*/\1/p' "$j" | head -n 1)
  case $scene in */* | *.*) ;; *) continue ;; esac
  [ -f "$(dirname "$j")/$scene" ] || fail "$(basename "$j"): scene $scene is not installed"
  "$P/bin/fovea" render "$(dirname "$j")/$scene" --method pt --spp 1 --size 16x16 --out "$TMP/scene.png" --quiet \
    >"$TMP/scene.log" 2>&1 || fail "installed scene $scene does not load: $(cat "$TMP/scene.log")"
done

# $FOVEA_BENCH_DIR comes first.
mkdir -p "$TMP/mine"
cp "$SRC/bench/pt-cornell.json" "$TMP/mine/my-scenario.json"
(cd "$TMP/elsewhere" && FOVEA_BENCH_DIR="$TMP/mine" "$P/bin/fovea" bench --list) >"$TMP/list.txt" 2>&1
[ "$(head -n 1 "$TMP/list.txt")" = "$TMP/mine:" ] &&
  sed -n 2p "$TMP/list.txt" | grep -q "^  my-scenario  *The reference path tracer at increasing samples per pixel" ||
  fail "FOVEA_BENCH_DIR is not listed first: $(head -n 3 "$TMP/list.txt")"

# Relocated: the whole prefix moved elsewhere still works.
mv "$P" "$TMP/moved"
[ "$(realpath "$(PKG_CONFIG_PATH="$TMP/moved/${LIB#"$P"/}/pkgconfig" pkg-config --variable=includedir fovea)")" = "$(realpath "$TMP/moved/include")" ] ||
  fail "fovea.pc does not follow a moved prefix"
check_tool "$TMP/moved"
check_python "$TMP/moved"

finish
