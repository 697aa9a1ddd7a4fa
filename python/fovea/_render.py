"""fovea — rendering frames: a method on a scene, driven by the library's sequence driver
(include/fovea/drive.h) exactly as `fovea render` drives it, so the same options give the same
pixels (python/tests/test_render.py checks it against the tool, bit for bit).

A Renderer owns a technique, a driver, its films and the gaze/camera paths it loaded; it closes
them in the order the library needs (before its scene) on close(), at the end of a ``with``
block, or when collected. Frames rendered one after another continue the method's temporal
state (photon maps, SVGF history) as a `fovea render --frames N` sequence does.
"""
import ctypes
import json
import math
import os
import time as _time

from . import _capi, _convert, _registry
from ._errors import Closing, FoveaError, emit_warnings
from ._images import Image, check_readable, film_arrays
from ._scene import Scene, camera_dict


class Renderer(Closing):
    """Renders frames of ``scene`` with ``method``.

    Options (the `fovea render` flag each stands for in brackets):
      size=(w, h) [--size], spp [--spp], params={key: value} [--param], device [--device],
      gaze=(x, y) [--gaze], gaze_trace=path or [(t, x, y) | (t, xl, yl, xr, yr), ...] [--gaze-trace;
      NaN marks a missing sample], gaze_missing="hold"|"widen" [--gaze-missing],
      camera_trace=path [--camera-trace], camera_pos, camera_look, camera_up=(x, y, z), fov
      [--camera-pos, ...], time [--time], fps [--fps], seed [--seed], threads [--threads],
      stereo=separation [--stereo], aux=True or names ("depth", "normal", "albedo", "id",
      "position"): the auxiliary buffers to return (what an EXR of `fovea render` holds),
      warmup=N [--warmup]: frames rendered at frame 0's view before frame 0 when a sequence starts
      there (None: the method's ``still_warmup_frames``, so a temporal method's still is converged).
    """

    def __init__(self, scene, method="pt", *, size=(512, 512), spp=None, params=None, device=None, gaze=None,
                 gaze_trace=None, gaze_missing=None, camera_trace=None, camera_pos=None, camera_look=None,
                 camera_up=None, fov=None, time=0.0, fps=30.0, seed=1, threads=0, stereo=0.0, aux=False, warmup=None):
        self._tech = self._driver = self._gaze_path = None
        self._films = []
        self._cam_keys = None
        self._scene = None
        if not isinstance(scene, Scene):
            raise TypeError(f"scene: expected a fovea.Scene, not {type(scene).__name__}")
        if not isinstance(method, str):
            raise TypeError(f"method: expected a str, not {type(method).__name__}")
        scene_h, view_h = scene._handles()
        lib = _capi.lib
        self.method = method
        self.size = _convert.size(size)
        w, h = self.size
        self._aux = _aux_names(aux)
        self._sink = _capi.WarningSink()
        self._params = params
        opts = _capi.DriveOpts()
        lib.fv_drive_opts_init(ctypes.byref(opts))
        opts.width, opts.height = w, h
        opts.time0 = _convert.number(time, "time")
        opts.fps = _convert.number(fps, "fps")
        opts.seed = _convert.integer(seed, "seed", 0, (1 << 64) - 1)
        opts.threads = _convert.integer(threads, "threads", 0, 256)
        opts.eye_separation = _convert.number(stereo, "stereo")
        if warmup is None:
            info = _registry.method(method) if isinstance(method, str) else None
            warmup = info.still_warmup_frames if info else 0
        opts.warmup = _convert.integer(warmup, "warmup", 0, 1000)
        if gaze is not None and gaze_trace is not None:
            raise FoveaError("gaze and gaze_trace exclude each other")
        if gaze is not None:
            opts.fixed_gaze = True
            opts.gaze = _convert.gaze(gaze)
        if gaze_missing is not None:
            if gaze_missing not in ("hold", "widen"):
                raise FoveaError(f"gaze_missing {gaze_missing}: expected hold or widen")
            opts.gaze_missing = _capi.GAZE_MISSING[gaze_missing]
        for bit, field, value, what in ((_capi.DRIVE_POS, "pos", camera_pos, "camera_pos"),
                                        (_capi.DRIVE_LOOK, "look", camera_look, "camera_look"),
                                        (_capi.DRIVE_UP, "up", camera_up, "camera_up")):
            if value is not None:
                setattr(opts, field, _convert.vec3(value, what))
                opts.camera_set |= bit
        if fov is not None:
            f = _convert.number(fov, "fov")
            if not 0 < f < 180:
                raise FoveaError(f"fov {f:g}: expected degrees in (0, 180)")
            opts.fov_y, opts.camera_set = f, opts.camera_set | _capi.DRIVE_FOV
        try:
            with _convert.params_bag(self._params) as bag:
                m = _convert.cstr(method, "method")
                if device is not None:
                    dev = ctypes.c_int()
                    _capi.call(lib.fv_device_check, m, _convert.cstr(device, "device"), ctypes.byref(dev))
                    _capi.call(lib.fv_params_set, bag, b"device", _convert.cstr(device, "device"))
                if spp is not None:
                    _capi.call(lib.fv_technique_set_spp, m, bag, _convert.integer(spp, "spp", 1, 1 << 20))
                self._bag_items = _convert.bag_items(bag)
                tech = ctypes.c_void_p()
                _capi.call(lib.fv_technique_create, m, scene_h, bag, self._sink.ref(), ctypes.byref(tech))
                self._tech = tech
            self._scene = scene
            scene._adopt(self)
            if gaze_trace is not None:
                self._gaze_path = _gaze_path(gaze_trace)
                opts.gaze_path = self._gaze_path
            if camera_trace is not None:
                p = _convert.cstr(camera_trace, "camera_trace")
                check_readable(p, "camera trace")
                base = _capi.Camera()
                lib.fv_view_camera(view_h, scene_h, opts.time0, w, h, ctypes.byref(base))
                keys, count = ctypes.POINTER(_capi.CameraKey)(), ctypes.c_int()
                _capi.call(lib.fv_camera_path_load_csv, p, ctypes.byref(base), ctypes.byref(keys), ctypes.byref(count))
                self._cam_keys = keys
                self._cam_path = _capi.CameraPath(keys, count.value)
                opts.camera_path = ctypes.pointer(self._cam_path)
            self._opts = opts  # the driver keeps pointers into what opts points to
            driver = ctypes.c_void_p()
            _capi.call(lib.fv_driver_create, scene_h, view_h, ctypes.byref(opts), ctypes.byref(driver))
            self._driver = driver
            flags = 0
            for name in self._aux:
                flags |= _capi.AUX[name]
            for _ in range(lib.fv_driver_eye_count(driver)):
                film = ctypes.c_void_p()
                _capi.call(lib.fv_film_create, w, h, flags, ctypes.byref(film))
                self._films.append(film)
        except BaseException:
            self.close()
            raise
        finally:
            emit_warnings(self._sink.messages)
        self._seed = opts.seed
        self._threads = opts.threads
        self._last = None
        info = _registry.method(method)
        self._foveated = info.foveated
        self._typed = _typed_params(info, self._bag_items)

    # ---- lifetime ----

    def close(self):
        """Frees the driver, films, technique and paths (not the scene). Safe to call twice."""
        lib = _capi.lib
        if getattr(self, "_driver", None) is not None:
            lib.fv_driver_destroy(self._driver)
            self._driver = None
        for film in getattr(self, "_films", ()):
            lib.fv_film_destroy(film)
        self._films = []
        if getattr(self, "_tech", None) is not None:
            lib.fv_technique_destroy(self._tech)
            self._tech = None
        if getattr(self, "_gaze_path", None) is not None:
            lib.fv_gaze_path_destroy(self._gaze_path)
            self._gaze_path = None
        if getattr(self, "_cam_keys", None) is not None:
            lib.fv_camera_keys_free(self._cam_keys)
            self._cam_keys = None
        self._scene = None

    @property
    def closed(self):
        return self._driver is None

    @property
    def eye_count(self):
        return len(self._films)

    # ---- rendering ----

    def set_gaze(self, gaze):
        """From now on every frame uses this gaze (both eyes), as the viewer's mouse does."""
        self._check_open()
        _capi.lib.fv_driver_set_gaze(self._driver, _convert.gaze(gaze))

    def render(self, frame=None, *, progress=None):
        """Renders frame ``frame`` (default: the one after the last rendered, else 0): an
        :class:`fovea.Image`, or (left, right) for a stereo renderer. A frame right after the last
        one continues the method's temporal state; any other starts a new sequence.
        ``progress(fraction)`` is called now and then; returning False cancels (FoveaError,
        status CANCELLED)."""
        self._check_open()
        if frame is None:
            frame = 0 if self._last is None else self._last + 1
        frame = _convert.integer(frame, "frame", 0, (1 << 31) - 1)
        lib = _capi.lib
        continues = self._last is not None and frame == self._last + 1
        stats = _capi.Stats()
        films = (ctypes.c_void_p * len(self._films))(*self._films)
        cb, raised = _progress(progress)
        t0 = _time.perf_counter()
        try:
            if frame == 0 and not continues and self._opts.warmup > 0:
                # the method's warm-up frames first, as `fovea render` renders them (unwritten)
                _capi.call(lib.fv_driver_warm_up, self._driver, self._tech, films, ctypes.byref(_capi.Stats()), cb, None)
                continues = True
                t0 = _time.perf_counter()
            _capi.call(lib.fv_driver_render, self._driver, self._tech, frame, continues, films, ctypes.byref(stats), cb, None)
        except FoveaError:
            self._last = None  # the method's state is now mid-frame: the next render starts afresh
            if raised:
                raise raised[0] from None
            raise
        finally:
            emit_warnings(self._sink.messages)
        ms = (_time.perf_counter() - t0) * 1e3
        self._last = frame
        views = _capi.FrameViews()
        lib.fv_driver_views(self._driver, frame, ctypes.byref(views))
        st = {"stages_ms": {_capi.text(stats.stage[i].name): stats.stage[i].value for i in range(stats.n_stages)},
              "serial_ms": {_capi.text(stats.serial[i].name): stats.serial[i].value for i in range(stats.n_serial)},
              "counters": {_capi.text(stats.counter[i].name): stats.counter[i].value for i in range(stats.n_counters)}}
        out = []
        w, h = self.size
        for e, film in enumerate(self._films):
            rgb, aux = film_arrays(film, w, h, self._aux)
            eye = "mono" if len(self._films) == 1 else ("left", "right")[e]
            g = (_convert.short_float(views.gaze[e].x), _convert.short_float(views.gaze[e].y))
            meta = self._metadata(frame, views, e, eye, ms)
            out.append(Image(rgb, aux, meta, st, g, frame, views.time, eye, ms, self.method))
        return out[0] if len(out) == 1 else tuple(out)

    def frames(self, count, start=0, **kw):
        """Renders frames start .. start + count - 1 in order, yielding each (as render)."""
        count = _convert.integer(count, "count", 0, (1 << 31) - 1)
        for i in range(start, start + count):
            yield self.render(i, **kw)

    def _check_open(self):
        if self._driver is None:
            raise FoveaError(f"renderer {self.method}: used after close()")

    def _metadata(self, frame, views, e, eye, ms):
        """The keys drive/frame_meta.c writes into `fovea render`'s images (docs/metrics.md)."""
        lib = _capi.lib
        b = _capi.BuildInfo()
        lib.fv_build_info_get(ctypes.byref(b))
        w, h = self.size
        return {
            "method": self.method, "params": json.dumps(self._typed, separators=(",", ":")),
            "foveated": "true" if self._foveated else "false", "scene": self._scene.source if self._scene else "",
            "camera": json.dumps(_compact(camera_dict(views.camera[e])), separators=(",", ":")),
            "gaze": f"{views.gaze[e].x:.7g},{views.gaze[e].y:.7g}", "gaze_known": "true" if views.gaze_known else "false",
            "eye": eye, "frame": str(frame), "frame_time": f"{views.time:.9g}", "seed": str(self._seed),
            "warmup_frames": str(self._opts.warmup),
            "size": f"{w}x{h}", "threads": str(lib.fv_threads_used(self._threads)), "render_ms": f"{ms:.3f}",
            "version": _capi.text(b.version), "commit": _capi.text(b.commit) + ("-dirty" if b.dirty > 0 else ""),
            "date": _time.strftime("%Y-%m-%dT%H:%M:%SZ", _time.gmtime()),
        }

    def __repr__(self):
        w, h = self.size
        return f"fovea.Renderer({self.method!r}, {w}x{h}{', closed' if self.closed else ''})"


def _compact(obj):
    """Numbers as cJSON prints them in the tool's metadata: 278, not 278.0."""
    if isinstance(obj, dict):
        return {k: _compact(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_compact(v) for v in obj]
    if isinstance(obj, float):
        return int(obj) if obj.is_integer() and abs(obj) < 2 ** 53 else _convert.short_float(obj)
    return obj


def _aux_names(aux):
    if aux is True:
        return tuple(_capi.AUX)
    if aux is False or aux is None:
        return ()
    if isinstance(aux, str):
        aux = (aux,)
    names = tuple(aux)
    for n in names:
        if n not in _capi.AUX:
            raise FoveaError(f"aux {n}: expected some of {', '.join(_capi.AUX)}")
    return names


def _gaze_path(trace):
    """An fv_gaze_path from a CSV file or a list of keys; the caller destroys it."""
    lib = _capi.lib
    path = ctypes.c_void_p()
    if isinstance(trace, (str, bytes, os.PathLike)):
        p = _convert.cstr(trace, "gaze_trace")
        check_readable(p, "gaze trace")
        _capi.call(lib.fv_gaze_path_load_csv, p, ctypes.byref(path))
        return path
    if not hasattr(trace, "__len__"):
        raise TypeError(f"gaze_trace: expected a CSV path or a list of keys, not {type(trace).__name__}")
    keys = (_capi.GazeKey * max(1, len(trace)))()
    for i, k in enumerate(trace):
        if isinstance(k, (str, bytes)) or not hasattr(k, "__len__") or len(k) not in (3, 5):
            raise FoveaError(f"gaze_trace[{i}]: expected (time, x, y) or (time, xl, yl, xr, yr)")
        v = []
        for x in k:
            if isinstance(x, bool) or not isinstance(x, (int, float)) and not hasattr(x, "__float__"):
                raise TypeError(f"gaze_trace[{i}]: expected numbers, not {type(x).__name__}")
            v.append(float(x))  # NaN: a missing sample (a blink), as an empty CSV field
        if not math.isfinite(v[0]):
            raise FoveaError(f"gaze_trace[{i}]: time {v[0]} must be finite")
        right = v[3:5] if len(v) == 5 else v[1:3]
        keys[i] = _capi.GazeKey(v[0], _capi.Gaze(v[1], v[2]), _capi.Gaze(*right))
    _capi.call(lib.fv_gaze_path_create_keys, keys, len(trace), ctypes.byref(path))
    return path


def _progress(progress):
    """The C progress callback for a Python one (NULL for None), and a list that receives what
    the Python callback raised (the render is cancelled, then it is re-raised)."""
    raised = []
    if progress is None:
        return _capi.PROGRESS_FN(), raised
    if not callable(progress):
        raise TypeError(f"progress: expected a callable, not {type(progress).__name__}")

    def fn(user, fraction):
        if raised:
            return False
        try:
            return progress(fraction) is not False
        except BaseException as e:  # KeyboardInterrupt included: stop the render, raise it after
            raised.append(e)
            return False
    return _capi.PROGRESS_FN(fn), raised


def _typed_params(info, items):
    """The parameters as the method's help types them (16, false, "focus"), for the metadata."""
    types = {p.key: p.type for p in info.params}
    out = {}
    for k, v in items.items():
        t = types.get(k)
        try:
            if t == "int":
                out[k] = int(v)
            elif t == "float":
                out[k] = float(v)
            elif t == "bool":
                out[k] = {"true": True, "false": False}[v]
            else:
                out[k] = v
        except (ValueError, KeyError):
            out[k] = v
    return out
