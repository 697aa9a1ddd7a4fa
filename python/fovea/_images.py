"""fovea — images as numpy arrays, and image files through the library's readers and writers
(include/fovea/film.h): PNG (tone-mapped sRGB, 8 bits), PFM (linear floats, exact) and EXR
(linear floats, with the auxiliary channels of a film). Files are written whole or not at all,
by the library's atomic writer, with the same metadata `fovea render` writes unless told not to.

Arrays are row-major from the top-left pixel: colour (height, width, 3) float32, linear.
"""
import ctypes
import os
import stat

import numpy as np

from . import _capi, _convert
from ._errors import FoveaError

_KINDS = {stat.S_IFCHR: "a character device", stat.S_IFBLK: "a block device", stat.S_IFIFO: "a FIFO",
          stat.S_IFSOCK: "a socket", stat.S_IFDIR: "a folder"}


def check_readable(path, what="image"):
    """Refuses anything but a regular file before a reader opens it by name, as the tools do
    (core/fileio.h): /dev/zero or a FIFO would make the image readers wait forever."""
    p = os.fsdecode(path)
    try:
        st = os.stat(p)
    except OSError as e:
        raise FoveaError(f"cannot open {what} '{p}': {e.strerror}", 2) from None
    if not stat.S_ISREG(st.st_mode):
        kind = _KINDS.get(stat.S_IFMT(st.st_mode), "not a file")
        raise FoveaError(f"cannot open {what} '{p}': not a regular file ({kind})", 2)


def read_image(path, layer=None):
    """An image file (PNG decoded from sRGB, PFM, EXR) as linear float32 (height, width, 3).
    ``layer``: an EXR layer's LAYER.R/G/B channels ("albedo" for the albedo a render stores)."""
    p = _convert.cstr(path, "image")
    check_readable(p)
    img = _capi.Image()
    if layer:
        _capi.call(_capi.lib.fv_image_read_layer, p, _convert.cstr(layer, "layer"), ctypes.byref(img))
    else:
        _capi.call(_capi.lib.fv_image_read, p, ctypes.byref(img))
    try:
        return np.ctypeslib.as_array(img.rgb, shape=(img.height, img.width, 3)).copy()
    finally:
        _capi.lib.fv_image_free(ctypes.byref(img))


def read_metadata(path):
    """The "fovea:" metadata of a PNG or EXR as {key: text} ({} for a PFM or none)."""
    p = _convert.cstr(path, "image")
    check_readable(p)
    bag = ctypes.c_void_p()
    _capi.call(_capi.lib.fv_image_read_meta, p, ctypes.byref(bag))
    try:
        return _convert.bag_items(bag)
    finally:
        _capi.lib.fv_params_destroy(bag)


def _meta_bag(metadata):
    """An fv_params for the metadata (None: no bag); the caller destroys it."""
    if not metadata:
        return None
    if not hasattr(metadata, "items"):
        raise TypeError(f"metadata: expected a mapping of key to text, not {type(metadata).__name__}")
    bag = ctypes.c_void_p()
    _capi.call(_capi.lib.fv_params_create, ctypes.byref(bag))
    try:
        for k, v in metadata.items():
            _capi.call(_capi.lib.fv_params_set, bag, _convert.cstr(k, "metadata key"),
                       _convert.cstr(_convert.param_text(k, v), f"metadata {k}"))
    except BaseException:
        _capi.lib.fv_params_destroy(bag)
        raise
    return bag


def write_image(path, rgb, exposure=1.0, metadata=None):
    """Writes linear RGB (height, width, 3) by the path's extension (.png, .pfm, .exr).
    PNG: times ``exposure``, clamped, sRGB, 8 bits. ``metadata``: {key: text} stored in PNG/EXR."""
    p = _convert.cstr(path, "path")
    a = _convert.rgb_array(rgb, "rgb")
    exp = _convert.number(exposure, "exposure")
    bag = _meta_bag(metadata)
    try:
        _capi.call(_capi.lib.fv_image_write_meta, p, _convert.float_ptr(a), a.shape[1], a.shape[0], exp, bag)
    finally:
        _capi.lib.fv_params_destroy(bag)


class Image:
    """A rendered image: ``rgb`` (height, width, 3) float32 linear, and the auxiliary buffers the
    renderer was asked for (``aux``: depth (h, w), normal, albedo, position (h, w, 3) float32,
    id (h, w) uint32: object id + 1 at the first hit, 0 for none), with how it was made:
    ``metadata`` (the keys `fovea render` writes into its images), ``stats`` ({"stages_ms": {...},
    "counters": {...}}), ``gaze`` (x, y), ``frame``, ``time``, ``eye`` ("mono", "left", "right"),
    ``render_ms``. The arrays are the image's own (copied out of the film)."""

    def __init__(self, rgb, aux=None, metadata=None, stats=None, gaze=None, frame=0, time=0.0, eye="mono",
                 render_ms=None, method=None):
        self.rgb = rgb
        self.aux = dict(aux or {})
        self.metadata = dict(metadata or {})
        self.stats = stats or {"stages_ms": {}, "counters": {}}
        self.gaze = gaze
        self.frame = frame
        self.time = time
        self.eye = eye
        self.render_ms = render_ms
        self.method = method

    @property
    def width(self):
        return self.rgb.shape[1]

    @property
    def height(self):
        return self.rgb.shape[0]

    def __getattr__(self, name):
        # depth, normal, albedo, position, id: None when not rendered
        if name in _capi.AUX:
            return self.__dict__.get("aux", {}).get(name)
        raise AttributeError(name)

    def write(self, path, exposure=1.0, metadata=True):
        """Writes the image (.png, .pfm, .exr; an EXR gets the auxiliary buffers as channels too).
        ``metadata``: True writes the image's own (as `fovea render`), False none (as
        `--no-metadata`), a dict that one."""
        p = _convert.cstr(path, "path")
        exp = _convert.number(exposure, "exposure")
        if metadata is True:
            meta = dict(self.metadata, exposure=f"{exp:.9g}")
        elif metadata is False or metadata is None:
            meta = None
        else:
            meta = metadata
        rgb = _convert.rgb_array(self.rgb, "Image.rgb")
        bag = _meta_bag(meta)
        film = ctypes.c_void_p()
        try:
            flags = 0
            for name in self.aux:
                if name not in _capi.AUX:
                    raise FoveaError(f"Image.aux: unknown buffer '{name}' (known: {', '.join(_capi.AUX)})")
                flags |= _capi.AUX[name]
            _capi.call(_capi.lib.fv_film_create, rgb.shape[1], rgb.shape[0], flags, ctypes.byref(film))
            _copy_into(_capi.lib.fv_film_color(film), rgb, np.float32, rgb.size)
            for name, arr in self.aux.items():
                getter = getattr(_capi.lib, "fv_film_" + name)
                _copy_into(getter(film), arr, np.uint32 if name == "id" else np.float32,
                           rgb.shape[0] * rgb.shape[1] * _capi.AUX_CHANNELS[name])
            _capi.call(_capi.lib.fv_film_write_meta, film, p, exp, bag)
        finally:
            _capi.lib.fv_film_destroy(film)
            _capi.lib.fv_params_destroy(bag)

    def __repr__(self):
        extra = f", aux={sorted(self.aux)}" if self.aux else ""
        return f"fovea.Image({self.width}x{self.height}, method={self.method!r}, frame={self.frame}, gaze={self.gaze}{extra})"


def _copy_into(ptr, arr, dtype, want):
    a = np.ascontiguousarray(arr, dtype=dtype)
    if a.size != want:
        raise FoveaError(f"image buffer of shape {a.shape} does not match the image's size")
    ctypes.memmove(ptr, a.ctypes.data, a.nbytes)


def film_arrays(film, width, height, aux_names):
    """Copies a film's colour and the named auxiliary buffers out into numpy arrays."""
    lib = _capi.lib
    rgb = np.ctypeslib.as_array(lib.fv_film_color(film), shape=(height, width, 3)).copy()
    aux = {}
    for name in aux_names:
        ptr = getattr(lib, "fv_film_" + name)(film)
        ch = _capi.AUX_CHANNELS[name]
        shape = (height, width) if ch == 1 else (height, width, ch)
        aux[name] = np.ctypeslib.as_array(ptr, shape=shape).copy()
    return rgb, aux
