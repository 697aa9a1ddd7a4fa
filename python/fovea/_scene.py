"""fovea — a scene and the view it came with (include/fovea/scene.h, view.h), loaded the way
`fovea render` loads it: a built-in name or a file (.json scene, or a mesh file assimp reads),
the command line's extra lights and environment, the default lighting, then committed.

A Scene owns two handles (fv_scene, fv_view). Renderers made on it borrow them, so closing the
scene closes its renderers first (a technique must be destroyed before its scene); a renderer
keeps its scene alive while it is open.
"""
import ctypes
import os
import weakref

from . import _capi, _convert
from ._errors import Closing, FoveaError, emit_warnings


class Scene(Closing):
    """A committed scene, ready to render.

    ``source``: a built-in name (:func:`fovea.scenes`) or a path. ``point_lights``: (x, y, z, r, g,
    b) tuples, added as `--point-light`; ``env``: a uniform environment radiance (r, g, b), as
    `--env`; ``frame_view``: the default camera's side when the scene has no camera ("front",
    "three-quarter", ...), as `--frame-view`; ``default_light=False`` is `--no-default-light`.
    """

    def __init__(self, source="cornell", *, point_lights=(), env=None, frame_view=None, default_light=True):
        self._scene = None
        self._view = None
        self._dependents = weakref.WeakSet()
        name = _convert.cstr(source, "scene")
        self.source = os.fsdecode(name)
        self._sink = _capi.WarningSink()
        lib = _capi.lib
        scene, view = ctypes.c_void_p(), ctypes.c_void_p()
        try:
            _capi.call(lib.fv_scene_open, name, self._sink.ref(), ctypes.byref(scene), ctypes.byref(view))
            self._scene, self._view = scene, view
            for i, light in enumerate(point_lights):
                v = _convert.numbers(light, 6, f"point_lights[{i}]")
                desc = _capi.LightDesc(_capi.LIGHT_POINT, _capi.Vec3(*v[:3]), _capi.Vec3(0, -1, 0), _capi.Vec3(*v[3:]), 0, 0)
                _capi.call(lib.fv_scene_add_light, scene, ctypes.byref(desc))
            if env is not None:
                e = lib.fv_env_uniform(_convert.vec3(env, "env"))
                had = _capi.EnvDesc()
                if lib.fv_scene_env(scene, ctypes.byref(had)):
                    e.up = had.up
                _capi.call(lib.fv_scene_set_env, scene, ctypes.byref(e))
            if frame_view is not None:
                fv = ctypes.c_int()
                if not isinstance(frame_view, str):
                    raise TypeError(f"frame_view: expected a str, not {type(frame_view).__name__}")
                if "\0" in frame_view or not lib.fv_frame_view_from_name(frame_view.encode(), ctypes.byref(fv)):
                    raise FoveaError(f"frame_view {frame_view}: expected front, back, left, right, top or three-quarter")
                lib.fv_view_set_frame(view, fv)
            if default_light:
                _capi.call(lib.fv_scene_add_default_lighting, scene, view, self._sink.ref(), None)
            try:
                _capi.call(lib.fv_scene_commit, scene, self._sink.ref())
            except FoveaError as e:
                raise FoveaError(f"{self.source}: {e.message}", e.status) from None
        except BaseException:
            self.close()
            raise
        finally:
            emit_warnings(self._sink.messages)

    # ---- lifetime ----

    def close(self):
        """Frees the scene, after closing every renderer made on it. Safe to call twice."""
        for d in list(getattr(self, "_dependents", ())):
            d.close()
        lib = _capi.lib
        if getattr(self, "_view", None) is not None:
            lib.fv_view_destroy(self._view)
            self._view = None
        if getattr(self, "_scene", None) is not None:
            lib.fv_scene_destroy(self._scene)
            self._scene = None

    @property
    def closed(self):
        return self._scene is None

    def _handles(self):
        if self._scene is None:
            raise FoveaError(f"scene {self.source}: used after close()")
        return self._scene, self._view

    def _adopt(self, dependent):
        self._dependents.add(dependent)

    # ---- queries ----

    @property
    def triangle_count(self):
        return _capi.lib.fv_scene_triangle_count(self._handles()[0])

    @property
    def object_count(self):
        return _capi.lib.fv_scene_object_count(self._handles()[0])

    @property
    def light_count(self):
        """Delta lights, emissive triangles and the environment."""
        return _capi.lib.fv_scene_light_count(self._handles()[0])

    @property
    def material_count(self):
        return _capi.lib.fv_scene_material_count(self._handles()[0])

    @property
    def bounds(self):
        """((x, y, z) low, (x, y, z) high) of the scene now."""
        lo, hi = _capi.Vec3(), _capi.Vec3()
        _capi.lib.fv_scene_bounds(self._handles()[0], ctypes.byref(lo), ctypes.byref(hi))
        return (lo.x, lo.y, lo.z), (hi.x, hi.y, hi.z)

    def camera(self, size=(512, 512), time=0.0):
        """The view's camera at time t for an image of this size: {pos, look, up, fov_y}."""
        scene, view = self._handles()
        w, h = _convert.size(size)
        c = _capi.Camera()
        _capi.lib.fv_view_camera(view, scene, _convert.number(time, "time"), w, h, ctypes.byref(c))
        return camera_dict(c)

    # ---- rendering ----

    def renderer(self, method="pt", **options):
        """A :class:`fovea.Renderer` of this scene (options as there)."""
        from ._render import Renderer
        return Renderer(self, method, **options)

    def render(self, method="pt", **options):
        """Renders one frame (frame 0, or options' ``frame``) and frees everything but the image:
        an :class:`fovea.Image`, or (left, right) for ``stereo``."""
        frame = options.pop("frame", 0)
        with self.renderer(method, **options) as r:
            return r.render(frame)

    def __repr__(self):
        state = "closed" if self.closed else f"{self.triangle_count} triangles, {self.light_count} lights"
        return f"fovea.Scene({self.source!r}: {state})"


def camera_dict(c):
    return {"pos": (c.pos.x, c.pos.y, c.pos.z), "look": (c.look.x, c.look.y, c.look.z), "up": (c.up.x, c.up.y, c.up.z),
            "fov_y": c.fov_y}
