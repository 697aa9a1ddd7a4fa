"""fovea — comparing two images per gaze region, as `fovea compare --json` does
(include/fovea/metrics.h; docs/metrics.md says what each metric is): MSE, PSNR, E, SSIM and FLIP
over the fovea, the transition, the periphery and the whole image.

The regions come from the eye model `fovea compare` builds: the default for the image's size
(the Vive's, scaled to its width), changed by the same options. The gaze, when not given, is the
one the images record (a rendered Image's, or a file's metadata), with the tool's rule: the
test's, unless only the reference depends on its gaze; two foveated images rendered for
different gazes are refused unless ``allow_gaze_mismatch``.
"""
import ctypes

import numpy as np

from . import _capi, _convert
from ._errors import FoveaError
from ._images import Image, read_image, read_metadata


def _load(value, what):
    """(linear rgb array, metadata dict, name for the report) of an array, Image or file."""
    if isinstance(value, Image):
        return _convert.rgb_array(value.rgb, what), value.metadata, None
    if isinstance(value, np.ndarray):
        return _convert.rgb_array(value, what), {}, None
    p = _convert.cstr(value, what)
    name = value if isinstance(value, str) else p.decode("utf-8", "replace")
    return read_image(p), read_metadata(p), name


def _recorded_gaze(meta):
    """(gaze or None, foveated) from metadata keys "gaze" ("x,y") and "foveated"."""
    foveated = meta.get("foveated", "true") != "false"
    try:
        x, y = (float(t) for t in meta["gaze"].split(","))
    except (KeyError, ValueError):
        return None, foveated
    if not (0 <= x <= 1 and 0 <= y <= 1):
        return None, foveated
    return (x, y), foveated


def eye_model(width, height, *, fovea_deg=None, transition_deg=None, fovea_frac=None, transition_frac=None, ppi=None,
              eye_dist=None, fov_x=None):
    """The eye model `fovea compare` uses for an image of this size, with its options."""
    m = _capi.EyeModel()
    _capi.lib.fv_eye_model_default(width, height, ctypes.byref(m))

    def pos(v, what):
        v = _convert.number(v, what)
        if not v > 0:
            raise FoveaError(f"{what} {v:g}: expected a positive number")
        return v
    if fovea_frac is not None or transition_frac is not None:
        m.mode = _capi.FOVEA_WIDTH
        if fovea_frac is not None:
            m.fovea_frac = pos(fovea_frac, "fovea_frac")
        m.transition_frac = pos(transition_frac, "transition_frac") if transition_frac is not None else 1.5 * m.fovea_frac
    if fovea_deg is not None:
        m.fovea_deg = pos(fovea_deg, "fovea_deg")
    m.transition_deg = pos(transition_deg, "transition_deg") if transition_deg is not None else 2.0 * m.fovea_deg
    if ppi is not None:
        m.ppi = pos(ppi, "ppi")
    if eye_dist is not None:
        m.eye_dist_mm = pos(eye_dist, "eye_dist")
    if fov_x is not None:
        m.fov_x_deg = pos(fov_x, "fov_x")
    _capi.call(_capi.lib.fv_eye_model_validate, ctypes.byref(m))
    return m


def compare(ref, test, *, gaze=None, allow_gaze_mismatch=False, exposure=1.0, linear=False, ppd=67.0, flip_map=False,
            **eye):
    """Compares ``test`` against ``ref`` (each a numpy array (h, w, 3) of linear RGB, an
    :class:`fovea.Image` or an image file) per region. Returns the dict `fovea compare --json`
    prints: size, gaze, fovea_radius_px, transition_radius_px, regions {fovea, transition,
    periphery, all: {pixels, mse, psnr, e, ssim, flip, nonfinite}}, nonfinite_pixels {ref, test}
    (and ref, test: the file names, for files). Where the JSON has null (an empty region, an
    infinite PSNR) the dict has nan or inf. ``flip_map=True`` adds the per-pixel FLIP (h, w).
    ``eye``: fovea_deg, transition_deg, fovea_frac, transition_frac, ppi, eye_dist, fov_x (the
    tool's --fovea-deg, ...)."""
    a, meta_a, name_a = _load(ref, "ref")
    b, meta_b, name_b = _load(test, "test")
    if a.shape != b.shape:
        ra = name_a or "ref"
        rb = name_b or "test"
        raise FoveaError(f"size mismatch: {ra} is {a.shape[1]}x{a.shape[0]}, {rb} is {b.shape[1]}x{b.shape[0]}")
    h, w = a.shape[:2]
    if gaze is not None:
        g = _convert.gaze(gaze)
    else:
        gr, fr = _recorded_gaze(meta_a)
        gt, ft = _recorded_gaze(meta_b)
        if gr and gt and fr and ft and not allow_gaze_mismatch and (abs(gr[0] - gt[0]) > 1e-4 or abs(gr[1] - gt[1]) > 1e-4):
            raise FoveaError(f"{name_a or 'ref'} was rendered for gaze {gr[0]:g},{gr[1]:g} and {name_b or 'test'} for gaze "
                             f"{gt[0]:g},{gt[1]:g}: pass allow_gaze_mismatch=True to compare them anyway")
        from_test = gt is not None and (ft or not (gr is not None and fr))
        chosen = gt if from_test else gr
        g = _capi.Gaze(*(chosen or (0.5, 0.5)))
    for k in eye:
        if k not in ("fovea_deg", "transition_deg", "fovea_frac", "transition_frac", "ppi", "eye_dist", "fov_x"):
            raise TypeError(f"compare() got an unexpected keyword argument '{k}'")
    m = eye_model(w, h, **eye)
    opts = _capi.MetricOpts()
    _capi.lib.fv_metric_opts_default(ctypes.byref(opts))
    e = _convert.number(exposure, "exposure")
    if not e > 0:
        raise FoveaError(f"exposure {e:g}: expected a positive number")
    p = _convert.number(ppd, "ppd")
    if not p > 0:
        raise FoveaError(f"ppd {p:g}: expected a positive number")
    opts.exposure, opts.linear, opts.ppd = e, bool(linear), p
    labels = np.empty((h, w), dtype=np.uint8)
    _capi.lib.fv_eye_region_labels(ctypes.byref(m), g, labels.ctypes.data_as(ctypes.POINTER(ctypes.c_uint8)))
    fmap = np.empty((h, w), dtype=np.float32)
    rep = _capi.MetricReport()
    _capi.call(_capi.lib.fv_metrics_compare, _convert.float_ptr(a), _convert.float_ptr(b), w, h,
               labels.ctypes.data_as(ctypes.POINTER(ctypes.c_uint8)), ctypes.byref(opts), ctypes.byref(rep),
               _convert.float_ptr(fmap))
    out = {}
    if name_a is not None:
        out["ref"] = name_a
    if name_b is not None:
        out["test"] = name_b
    out.update({"size": [w, h], "gaze": [_convert.short_float(g.x), _convert.short_float(g.y)],
                "fovea_radius_px": _capi.lib.fv_eye_fovea_radius_px(ctypes.byref(m)),
                "transition_radius_px": _capi.lib.fv_eye_transition_radius_px(ctypes.byref(m)), "regions": {}})
    for r, name in enumerate(_capi.REGIONS):
        v = rep.region[r]
        out["regions"][name] = {"pixels": v.pixels, "mse": v.mse, "psnr": v.psnr, "e": v.e, "ssim": v.ssim, "flip": v.flip,
                                "nonfinite": v.nonfinite}
    out["nonfinite_pixels"] = {"ref": int(np.count_nonzero(~np.isfinite(a).all(axis=2))),
                               "test": int(np.count_nonzero(~np.isfinite(b).all(axis=2)))}
    if flip_map:
        out["flip_map"] = fmap
    return out

