"""fovea — Python values to what the C API takes, checked first: a wrong Python type is a
TypeError, a value fovea would refuse is a FoveaError with a one-line message naming it.
"""
import contextlib
import ctypes
import math
import os

import numpy as np

from . import _capi
from ._errors import FoveaError


def cstr(value, what):
    """str or path-like -> bytes for a const char * (no NUL inside)."""
    if isinstance(value, (str, os.PathLike)):
        b = os.fsencode(value)
    elif isinstance(value, bytes):
        b = value
    else:
        raise TypeError(f"{what}: expected a str or path, not {type(value).__name__}")
    if b"\0" in b:
        raise FoveaError(f"{what} {value!r}: contains a NUL character")
    return b


def integer(value, what, lo, hi):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what}: expected an int, not {type(value).__name__}")
    if not lo <= value <= hi:
        raise FoveaError(f"{what} {value}: expected an integer in [{lo}, {hi}]")
    return int(value)


def number(value, what):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{what}: expected a number, not {type(value).__name__}")
    v = float(value)
    if not math.isfinite(v):
        raise FoveaError(f"{what} {value}: expected a finite number")
    return v


def numbers(value, n, what):
    """A sequence of n finite numbers."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        raise TypeError(f"{what}: expected {n} numbers, not {type(value).__name__}")
    if len(value) != n:
        raise FoveaError(f"{what} {tuple(value)}: expected {n} numbers")
    return [number(v, what) for v in value]


def size(value, what="size"):
    """(width, height) checked as fv_film_check_size does."""
    w, h = (integer(v, what, -(1 << 31), (1 << 31) - 1) for v in _pair(value, what))
    _capi.call(_capi.lib.fv_film_check_size, w, h)
    return w, h


def _pair(value, what):
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        raise TypeError(f"{what}: expected (width, height), not {type(value).__name__}")
    if len(value) != 2:
        raise FoveaError(f"{what} {tuple(value)}: expected (width, height)")
    return value


def gaze(value, what="gaze"):
    """(x, y) in normalised screen coordinates, both in [0, 1] (as `fovea render --gaze`)."""
    x, y = numbers(value, 2, what)
    if not (0 <= x <= 1 and 0 <= y <= 1):
        raise FoveaError(f"{what} {x:g},{y:g}: expected X,Y with both in [0,1]")
    return _capi.Gaze(x, y)


def short_float(v):
    """A float32 as the shortest double that reads back as it (0.3, not 0.30000001192092896)."""
    for digits in range(1, 10):
        s = float(f"{v:.{digits}g}")
        if ctypes.c_float(s).value == v:
            return s
    return v


def vec3(value, what):
    return _capi.Vec3(*numbers(value, 3, what))


def param_text(key, value):
    """A parameter value as the text fv_params holds ("true", "16", "0.25", "focus")."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, str):
        return value
    raise TypeError(f"parameter {key}: expected a bool, int, float or str, not {type(value).__name__}")


@contextlib.contextmanager
def params_bag(params):
    """A new fv_params from a mapping, destroyed on leaving the block."""
    if params is None:
        params = {}
    if not hasattr(params, "items"):
        raise TypeError(f"params: expected a mapping of key to value, not {type(params).__name__}")
    bag = ctypes.c_void_p()
    _capi.call(_capi.lib.fv_params_create, ctypes.byref(bag))
    try:
        for k, v in params.items():
            if not isinstance(k, str):
                raise TypeError(f"params: keys are str, not {type(k).__name__}")
            _capi.call(_capi.lib.fv_params_set, bag, cstr(k, "parameter"), cstr(param_text(k, v), f"parameter {k}"))
        yield bag
    finally:
        _capi.lib.fv_params_destroy(bag)


def bag_items(bag):
    """An fv_params as a dict of str to str."""
    lib = _capi.lib
    return {_capi.text(lib.fv_params_key(bag, i)): _capi.text(lib.fv_params_value(bag, i))
            for i in range(lib.fv_params_count(bag))}


def rgb_array(value, what):
    """An HxWx3 image as a C-contiguous float32 array (a copy only when needed)."""
    if not isinstance(value, np.ndarray):
        raise TypeError(f"{what}: expected a numpy array (height, width, 3), not {type(value).__name__}")
    if value.ndim != 3 or value.shape[2] != 3 or value.shape[0] < 1 or value.shape[1] < 1:
        raise FoveaError(f"{what}: expected an array of shape (height, width, 3), not {value.shape}")
    if not (np.issubdtype(value.dtype, np.floating) or np.issubdtype(value.dtype, np.integer)):
        raise TypeError(f"{what}: expected float values, not {value.dtype}")
    return np.ascontiguousarray(value, dtype=np.float32)


def float_ptr(a):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_float))
