# Writes the installed Python package's fovea/_paths.py at install time (CMakeLists.txt's
# install(CODE)), when CMAKE_INSTALL_PREFIX is the prefix actually installed into (`cmake --install
# --prefix P` changes it after configuring). In: FV_PY_DIR (the package's folder), FV_PY_LIB (the
# library's soname file) and FV_PY_BENCH (the scenarios), each relative to the prefix or absolute.
# The package tries the path relative to itself first, so a moved prefix keeps working.
foreach(v FV_PY_DIR FV_PY_LIB FV_PY_BENCH)
  if(IS_ABSOLUTE "${${v}}")
    set(${v}_FULL "${${v}}")
  else()
    set(${v}_FULL "${CMAKE_INSTALL_PREFIX}/${${v}}")
  endif()
endforeach()
set(pkg "${FV_PY_DIR_FULL}/fovea")
file(RELATIVE_PATH lib_rel "${pkg}" "${FV_PY_LIB_FULL}")
file(RELATIVE_PATH bench_rel "${pkg}" "${FV_PY_BENCH_FULL}")
# Python string literals: backslashes and quotes escaped.
foreach(v lib_rel FV_PY_LIB_FULL bench_rel FV_PY_BENCH_FULL)
  string(REPLACE "\\" "\\\\" ${v} "${${v}}")
  string(REPLACE "\"" "\\\"" ${v} "${${v}}")
endforeach()
set(out "$ENV{DESTDIR}${pkg}/_paths.py")
message(STATUS "Installing: ${out}")
file(WRITE "${out}" "\"\"\"Written by `cmake --install` (cmake/python_paths.cmake): where this installation's libfovea and
scenarios are, relative to this package first, then as installed.\"\"\"
LIBRARY = \"${lib_rel}\"
LIBRARY_ABSOLUTE = \"${FV_PY_LIB_FULL}\"
BENCH = \"${bench_rel}\"
BENCH_ABSOLUTE = \"${FV_PY_BENCH_FULL}\"
")
list(APPEND CMAKE_INSTALL_MANIFEST_FILES "${out}")
