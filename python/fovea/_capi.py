"""fovea — the C API as ctypes sees it: the structs of include/fovea/*.h, field for field, and the
prototype of every function the package calls. Nothing else in the package names a C type; when
a public header changes, this file changes with it (the package refuses a library of another
minor version, whose structs may differ).

Handles are opaque (c_void_p). Calls that can fail go through :func:`call`, which passes a fresh
fv_error and raises FoveaError with its message.
"""
import ctypes
from ctypes import (CFUNCTYPE, POINTER, Structure, c_bool, c_char, c_char_p, c_double, c_float, c_int, c_longlong,
                    c_uint, c_uint8, c_uint32, c_uint64, c_void_p)

from . import _loader
from ._errors import FoveaError, Status

VERSION = "0.1.0"  # the libfovea this package was written against (FOVEA_VERSION_STRING)

lib, library_path = _loader.load()

# ---- status.h ----


class Error(Structure):
    _fields_ = [("status", c_int), ("msg", c_char * 512)]


WARN_FN = CFUNCTYPE(None, c_void_p, c_char_p)


class Log(Structure):
    _fields_ = [("warn", WARN_FN), ("user", c_void_p)]

# ---- math.h, camera.h, gaze.h ----


class Vec3(Structure):
    _fields_ = [("x", c_float), ("y", c_float), ("z", c_float)]


class Camera(Structure):
    _fields_ = [("pos", Vec3), ("look", Vec3), ("up", Vec3), ("fov_y", c_float), ("width", c_int), ("height", c_int)]


class CameraKey(Structure):
    _fields_ = [("time", c_double), ("pos", Vec3), ("look", Vec3), ("up", Vec3), ("fov_y", c_float)]


class CameraPath(Structure):
    _fields_ = [("keys", POINTER(CameraKey)), ("count", c_int)]


class Gaze(Structure):
    _fields_ = [("x", c_float), ("y", c_float)]


class GazeKey(Structure):
    _fields_ = [("time", c_double), ("left", Gaze), ("right", Gaze)]


class EyeModel(Structure):
    _fields_ = [("width", c_int), ("height", c_int), ("ppi", c_float), ("eye_dist_mm", c_float), ("fov_x_deg", c_float),
                ("mode", c_int), ("fovea_deg", c_float), ("transition_deg", c_float), ("fovea_frac", c_float),
                ("transition_frac", c_float)]


FOVEA_ANGLE, FOVEA_WIDTH = 0, 1
GAZE_MISSING = {"path": 0, "hold": 1, "widen": 2}
REGIONS = ("fovea", "transition", "periphery", "all")  # fv_region order

# ---- scene.h ----


LIGHT_POINT = 0


class LightDesc(Structure):
    _fields_ = [("type", c_int), ("pos", Vec3), ("dir", Vec3), ("intensity", Vec3), ("inner_deg", c_float),
                ("outer_deg", c_float)]


class EnvDesc(Structure):
    _fields_ = [("zenith", Vec3), ("horizon", Vec3), ("ground", Vec3), ("up", Vec3)]

# ---- stats.h, frame.h, drive.h ----


class StatEntry(Structure):
    _fields_ = [("name", c_char * 32), ("value", c_double)]


class Stats(Structure):
    _fields_ = [("n_stages", c_int), ("n_counters", c_int), ("stage", StatEntry * 32), ("counter", StatEntry * 32),
                ("n_serial", c_int), ("serial", StatEntry * 32)]


PROGRESS_FN = CFUNCTYPE(c_bool, c_void_p, c_double)

DRIVE_POS, DRIVE_LOOK, DRIVE_UP, DRIVE_FOV = 1, 2, 4, 8


class DriveOpts(Structure):
    _fields_ = [("width", c_int), ("height", c_int), ("time0", c_double), ("fps", c_double), ("seed", c_uint64),
                ("threads", c_int), ("eye_separation", c_float), ("camera_path", POINTER(CameraPath)),
                ("camera_set", c_uint), ("pos", Vec3), ("look", Vec3), ("up", Vec3), ("fov_y", c_float),
                ("fixed_gaze", c_bool), ("gaze", Gaze), ("gaze_path", c_void_p), ("gaze_missing", c_int),
                ("eye_model", POINTER(EyeModel)), ("warmup", c_int)]


class FrameViews(Structure):
    _fields_ = [("time", c_double), ("eye_count", c_int), ("camera", Camera * 2), ("gaze", Gaze * 2),
                ("gaze_known", c_bool), ("eye_model", POINTER(EyeModel))]

# ---- film.h ----


AUX = {"depth": 1, "normal": 2, "albedo": 4, "id": 8, "position": 16}
AUX_CHANNELS = {"depth": 1, "normal": 3, "albedo": 3, "id": 1, "position": 3}


class Image(Structure):
    _fields_ = [("width", c_int), ("height", c_int), ("rgb", POINTER(c_float))]

# ---- metrics.h ----


class MetricOpts(Structure):
    _fields_ = [("exposure", c_float), ("linear", c_bool), ("ppd", c_float)]


class MetricValues(Structure):
    _fields_ = [("mse", c_double), ("psnr", c_double), ("e", c_double), ("ssim", c_double), ("flip", c_double),
                ("pixels", c_longlong), ("nonfinite", c_longlong)]


class MetricReport(Structure):
    _fields_ = [("region", MetricValues * 4)]

# ---- bench.h ----


BENCH_MODES = {"default": 0, "quick": 1, "full": 2}
LINE_FN = CFUNCTYPE(None, c_void_p, c_char_p)
BENCH_PROGRESS_FN = CFUNCTYPE(None, c_void_p, c_int, c_int, c_double)


class BenchOptions(Structure):
    _fields_ = [("out_dir", c_char_p), ("cache_dir", c_char_p), ("mode", c_int), ("threads", c_int), ("repeats", c_int),
                ("log", POINTER(Log)), ("status", LINE_FN), ("status_user", c_void_p), ("device", c_char_p),
                ("table", LINE_FN), ("command", c_char_p), ("report", LINE_FN), ("split", c_void_p),
                ("progress", BENCH_PROGRESS_FN)]

# ---- provenance.h ----


class BuildInfo(Structure):
    _fields_ = [("version", c_char_p), ("commit", c_char_p), ("dirty", c_int), ("build_type", c_char_p),
                ("compiler", c_char_p), ("embree", c_char_p), ("sanitize", c_bool)]

# ---- prototypes ----


_E = POINTER(Error)
_P = c_void_p  # any opaque handle
_OUT = POINTER(c_void_p)


def _proto(name, restype, *argtypes):
    f = getattr(lib, name)
    f.restype = restype
    f.argtypes = list(argtypes)


for _name, _res, _args in [
    ("fv_status_name", c_char_p, [c_int]),
    ("fv_abi_sizeof", ctypes.c_size_t, [c_char_p]),
    ("fv_build_info_get", None, [POINTER(BuildInfo)]),
    ("fv_threads_used", c_int, [c_int]),
    # technique.h, device.h
    ("fv_technique_count", c_int, []),
    ("fv_technique_name", c_char_p, [c_int]),
    ("fv_technique_summary", c_char_p, [c_int]),
    ("fv_methods_json", c_void_p, [c_char_p, _E]),
    ("fv_methods_json_free", None, [c_void_p]),
    ("fv_technique_index", c_int, [c_char_p]),
    ("fv_technique_spp_param", c_char_p, [c_int]),
    ("fv_technique_foveated", c_bool, [c_int]),
    ("fv_technique_has_device", c_bool, [c_int, c_int]),
    ("fv_technique_set_spp", c_int, [c_char_p, _P, c_int, _E]),
    ("fv_technique_create", c_int, [c_char_p, _P, _P, POINTER(Log), _OUT, _E]),
    ("fv_technique_destroy", None, [_P]),
    ("fv_device_check", c_int, [c_char_p, c_char_p, POINTER(c_int), _E]),
    # params.h
    ("fv_params_create", c_int, [_OUT, _E]),
    ("fv_params_destroy", None, [_P]),
    ("fv_params_set", c_int, [_P, c_char_p, c_char_p, _E]),
    ("fv_params_count", c_int, [_P]),
    ("fv_params_key", c_char_p, [_P, c_int]),
    ("fv_params_value", c_char_p, [_P, c_int]),
    # scene.h, view.h
    ("fv_builtin_count", c_int, []),
    ("fv_builtin_name", c_char_p, [c_int]),
    ("fv_builtin_summary", c_char_p, [c_int]),
    ("fv_scene_open", c_int, [c_char_p, POINTER(Log), _OUT, _OUT, _E]),
    ("fv_scene_commit", c_int, [_P, POINTER(Log), _E]),
    ("fv_scene_destroy", None, [_P]),
    ("fv_scene_add_light", c_int, [_P, POINTER(LightDesc), _E]),
    ("fv_env_uniform", EnvDesc, [Vec3]),
    ("fv_scene_set_env", c_int, [_P, POINTER(EnvDesc), _E]),
    ("fv_scene_env", c_bool, [_P, POINTER(EnvDesc)]),
    ("fv_scene_add_default_lighting", c_int, [_P, _P, POINTER(Log), POINTER(c_bool), _E]),
    ("fv_scene_triangle_count", c_int, [_P]),
    ("fv_scene_object_count", c_int, [_P]),
    ("fv_scene_light_count", c_int, [_P]),
    ("fv_scene_material_count", c_int, [_P]),
    ("fv_scene_bounds", None, [_P, POINTER(Vec3), POINTER(Vec3)]),
    ("fv_view_destroy", None, [_P]),
    ("fv_view_set_frame", None, [_P, c_int]),
    ("fv_view_camera", None, [_P, _P, c_double, c_int, c_int, POINTER(Camera)]),
    ("fv_frame_view_from_name", c_bool, [c_char_p, POINTER(c_int)]),
    # gaze.h, camera.h
    ("fv_gaze_path_create_keys", c_int, [POINTER(GazeKey), c_int, _OUT, _E]),
    ("fv_gaze_path_load_csv", c_int, [c_char_p, _OUT, _E]),
    ("fv_gaze_path_destroy", None, [_P]),
    ("fv_camera_path_load_csv", c_int, [c_char_p, POINTER(Camera), POINTER(POINTER(CameraKey)), POINTER(c_int), _E]),
    ("fv_camera_keys_free", None, [POINTER(CameraKey)]),
    ("fv_eye_model_default", None, [c_int, c_int, POINTER(EyeModel)]),
    ("fv_eye_model_validate", c_int, [POINTER(EyeModel), _E]),
    ("fv_eye_fovea_radius_px", c_double, [POINTER(EyeModel)]),
    ("fv_eye_transition_radius_px", c_double, [POINTER(EyeModel)]),
    ("fv_eye_region_labels", None, [POINTER(EyeModel), Gaze, POINTER(c_uint8)]),
    # drive.h
    ("fv_drive_opts_init", None, [POINTER(DriveOpts)]),
    ("fv_driver_create", c_int, [_P, _P, POINTER(DriveOpts), _OUT, _E]),
    ("fv_driver_destroy", None, [_P]),
    ("fv_driver_views", None, [_P, c_int, POINTER(FrameViews)]),
    ("fv_driver_eye_count", c_int, [_P]),
    ("fv_driver_eye_model", POINTER(EyeModel), [_P]),
    ("fv_driver_set_gaze", None, [_P, Gaze]),
    ("fv_driver_warm_up", c_int, [_P, _P, POINTER(c_void_p), POINTER(Stats), PROGRESS_FN, c_void_p, _E]),
    ("fv_driver_render", c_int, [_P, _P, c_int, c_bool, POINTER(c_void_p), POINTER(Stats), PROGRESS_FN, c_void_p, _E]),
    # film.h
    ("fv_film_check_size", c_int, [c_int, c_int, _E]),
    ("fv_film_create", c_int, [c_int, c_int, c_uint, _OUT, _E]),
    ("fv_film_destroy", None, [_P]),
    ("fv_film_color", POINTER(c_float), [_P]),
    ("fv_film_depth", POINTER(c_float), [_P]),
    ("fv_film_normal", POINTER(c_float), [_P]),
    ("fv_film_albedo", POINTER(c_float), [_P]),
    ("fv_film_position", POINTER(c_float), [_P]),
    ("fv_film_id", POINTER(c_uint32), [_P]),
    ("fv_film_write_meta", c_int, [_P, c_char_p, c_float, _P, _E]),
    ("fv_image_format_from_path", c_int, [c_char_p]),
    ("fv_image_write_meta", c_int, [c_char_p, POINTER(c_float), c_int, c_int, c_float, _P, _E]),
    ("fv_image_read", c_int, [c_char_p, POINTER(Image), _E]),
    ("fv_image_read_layer", c_int, [c_char_p, c_char_p, POINTER(Image), _E]),
    ("fv_image_read_meta", c_int, [c_char_p, _OUT, _E]),
    ("fv_image_free", None, [POINTER(Image)]),
    # metrics.h
    ("fv_metric_opts_default", None, [POINTER(MetricOpts)]),
    ("fv_metrics_compare", c_int, [POINTER(c_float), POINTER(c_float), c_int, c_int, POINTER(c_uint8),
                                   POINTER(MetricOpts), POINTER(MetricReport), POINTER(c_float), _E]),
    # bench.h
    ("fv_bench_run", c_int, [c_char_p, POINTER(BenchOptions), _E]),
    ("fv_bench_run_text", c_int, [c_char_p, c_char_p, c_char_p, POINTER(BenchOptions), _E]),
]:
    _proto(_name, _res, *_args)
del _name, _res, _args


def library_version():
    b = BuildInfo()
    lib.fv_build_info_get(ctypes.byref(b))
    return b.version.decode()


def _check_version():
    have = library_version()
    if have.split(".")[:2] != VERSION.split(".")[:2]:
        raise ImportError(f"fovea: {library_path} is libfovea {have}; this package is for {VERSION} "
                          "(set FOVEA_LIB to a matching build)")


_check_version()

# The structs this module mirrors, by their C names: each must have the library's size, else a
# call would read or write past the end of one (fv_abi_sizeof, include/fovea/fovea.h).
_MIRRORED = {"fv_error": Error, "fv_log": Log, "fv_vec3": Vec3, "fv_camera": Camera, "fv_camera_key": CameraKey,
             "fv_camera_path": CameraPath, "fv_gaze": Gaze, "fv_gaze_key": GazeKey, "fv_eye_model": EyeModel,
             "fv_light_desc": LightDesc, "fv_env_desc": EnvDesc, "fv_stat_entry": StatEntry, "fv_stats": Stats,
             "fv_drive_opts": DriveOpts, "fv_frame_views": FrameViews, "fv_image": Image, "fv_metric_opts": MetricOpts,
             "fv_metric_values": MetricValues, "fv_metric_report": MetricReport, "fv_bench_options": BenchOptions,
             "fv_build_info": BuildInfo}


def _check_layouts():
    bad = []
    for name, cls in _MIRRORED.items():
        have = lib.fv_abi_sizeof(name.encode())
        if have != ctypes.sizeof(cls):
            bad.append(f"{name} ({ctypes.sizeof(cls)} bytes here, {have} in the library)")
    if bad:
        raise ImportError(f"fovea: {library_path} lays out its structs differently from this package: {', '.join(bad)} "
                          "(set FOVEA_LIB to the build this package came with)")


_check_layouts()


def call(fn, *args):
    """Calls fn(*args, &err) and raises FoveaError with fovea's message when it fails."""
    err = Error()
    status = fn(*args, ctypes.byref(err))
    if status != Status.OK:
        raise FoveaError(err.msg.decode("utf-8", "replace") or lib.fv_status_name(status).decode(), status)


def methods_json(name=None):
    """fv_methods_json: the registry as a JSON text (one method's when name is given); FoveaError
    naming the known methods for an unknown name."""
    err = Error()
    p = lib.fv_methods_json(name.encode() if name is not None else None, ctypes.byref(err))
    if not p:
        raise FoveaError(err.msg.decode("utf-8", "replace") or "out of memory", Status.INVALID if err.msg else Status.NOMEM)
    try:
        return ctypes.string_at(p).decode("utf-8")
    finally:
        lib.fv_methods_json_free(p)


def text(p):
    """A static C string from the library as str ('' for NULL)."""
    return p.decode("utf-8", "replace") if p else ""


class WarningSink:
    """An fv_log whose warnings are kept for re-emission as FoveaWarning after the call. Whoever
    hands its ``log`` to the library keeps the sink alive as long as the library may use it."""

    def __init__(self):
        self.messages = []
        self._fn = WARN_FN(self._warn)
        self.log = Log(self._fn, None)

    def _warn(self, user, msg):
        self.messages.append(text(msg))

    def ref(self):
        return ctypes.byref(self.log)
