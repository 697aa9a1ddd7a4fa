"""fovea — finding and loading libfovea.so (docs/python.md, "Which library").

In order: the FOVEA_LIB environment variable (only it, when set: a wrong path fails loudly rather
than falling back to another build); the library of the installation this package belongs to
(_paths.py, written by ``cmake --install``, relative to the package so a moved prefix still
works); the build tree beside the source tree's package (python/fovea -> build/libfovea.so); the
system's (ctypes.util.find_library, i.e. ldconfig's list). The package is pure Python over
ctypes, so it runs on whichever libfovea it finds; one of another version is refused.
"""
import ctypes
import ctypes.util
import os

_HERE = os.path.dirname(os.path.abspath(__file__))


def candidates():
    """(where it comes from, path) pairs, in the order they are tried."""
    env = os.environ.get("FOVEA_LIB")
    if env:
        return [("FOVEA_LIB", env)]
    out = []
    try:
        from . import _paths  # only in an installed package
    except ImportError:
        _paths = None
    if _paths is not None:
        out.append(("installed package", os.path.normpath(os.path.join(_HERE, _paths.LIBRARY))))
        out.append(("installed package", _paths.LIBRARY_ABSOLUTE))
    out.append(("build tree", os.path.normpath(os.path.join(_HERE, "..", "..", "build", "libfovea.so"))))
    found = ctypes.util.find_library("fovea")
    if found:
        out.append(("system", found))
    return out


def load():
    """The loaded library and the path it came from; ImportError saying where it looked."""
    tried = []
    for origin, path in candidates():
        # find_library returns a bare soname for the dynamic loader to resolve
        if origin != "system" and not os.path.exists(path):
            tried.append(f"{path} ({origin}: no such file)")
            continue
        try:
            return ctypes.CDLL(path), path
        except OSError as e:
            tried.append(f"{path} ({origin}: {e})")
    raise ImportError("fovea: cannot load libfovea: tried " + "; ".join(tried) +
                      " (build it with cmake, or set FOVEA_LIB to its path)")


def source_bench_dir():
    """The source tree's bench/ folder when this package is the source tree's, else None."""
    d = os.path.normpath(os.path.join(_HERE, "..", "..", "bench"))
    return d if os.path.isfile(os.path.join(_HERE, "..", "..", "include", "fovea", "fovea.h")) else None


def installed_bench_dir():
    """The installed scenarios (share/fovea/bench of the package's prefix), or None."""
    try:
        from . import _paths
    except ImportError:
        return None
    for d in (os.path.normpath(os.path.join(_HERE, _paths.BENCH)), _paths.BENCH_ABSOLUTE):
        if os.path.isdir(d):
            return d
    return None
