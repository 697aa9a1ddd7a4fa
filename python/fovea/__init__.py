"""fovea — Python bindings of libfovea, the foveated global illumination renderer (docs/python.md).

    import fovea
    with fovea.Scene("cornell") as scene:
        img = scene.render("fpm", size=(128, 128), gaze=(0.3, 0.5), params={"photons": 20000})
    img.rgb                        # (128, 128, 3) float32, linear
    img.write("fpm.png")
    fovea.compare(reference, img)  # per-region errors, as `fovea compare --json`

Pure Python over ctypes: the library is found by FOVEA_LIB, then the installation this package
belongs to, then the build tree next to the source tree, then the system (fovea._loader).
"""
from ._capi import VERSION as __version__
from ._capi import library_path as _library_path
from ._capi import library_version as _library_version
from ._bench import bench, find_scenario
from ._errors import FoveaError, FoveaWarning, Status
from ._images import Image, read_image, read_metadata, write_image
from ._registry import Method, Param, families, method, methods, scenes
from ._metrics import compare
from ._render import Renderer
from ._scene import Scene

__all__ = ["FoveaError", "FoveaWarning", "Image", "Method", "Param", "Renderer", "Scene", "Status", "bench", "compare",
           "find_scenario", "library_path", "library_version", "method", "methods", "families", "read_image",
           "read_metadata", "render", "scenes", "write_image"]


def library_path():
    """The path of the libfovea this package loaded."""
    return _library_path


def library_version():
    """The loaded libfovea's version ("0.1.0")."""
    return _library_version()


def render(scene="cornell", method="pt", **options):
    """One frame of a scene (a name, a path or a :class:`Scene`) with a method: an
    :class:`Image` (a pair for stereo). Options as :class:`Renderer`'s, plus ``frame``."""
    if isinstance(scene, Scene):
        return scene.render(method, **options)
    with Scene(scene) as s:
        return s.render(method, **options)

for _cls in (FoveaError, FoveaWarning, Status, Image, Method, Param, Renderer, Scene):
    _cls.__module__ = __name__  # shown as fovea.Scene, not the private module it lives in
del _cls
