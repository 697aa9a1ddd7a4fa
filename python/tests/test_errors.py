"""Bad input becomes an exception, never a crash: FoveaError with fovea's one-line message and
status for what fovea refuses, TypeError for a Python type the API does not take; handles are
freed when closed, at the end of a with block, or when collected (counted handle by handle), and
stay unusable after."""
import ctypes
import gc
import os
import subprocess
import sys

import numpy as np
import pytest

import fovea

PYDIR = os.path.normpath(os.path.join(os.path.dirname(__file__), ".."))


def refused(fn, needle, status=fovea.Status.INVALID):
    with pytest.raises(fovea.FoveaError) as e:
        fn()
    assert needle in e.value.message, e.value.message
    assert "\n" not in e.value.message and str(e.value) == e.value.message
    assert e.value.status == status
    return e.value


def test_bad_methods_and_parameters(cornell):
    refused(lambda: cornell.render("no-such", size=(8, 8)), "unknown method 'no-such'")
    refused(lambda: cornell.render("pt", size=(8, 8), params={"no_such_key": 1}), "no_such_key")
    refused(lambda: cornell.render("pt", size=(8, 8), params={"spp": "many"}), "spp")
    refused(lambda: cornell.render("pt", size=(8, 8), params={"spp": -3}), "spp")
    refused(lambda: cornell.render("fpm", size=(8, 8), spp=4), "fpm")  # no samples-per-pixel notion
    refused(lambda: cornell.render("pt", size=(8, 8), device="abacus"), "abacus")
    refused(lambda: cornell.render("pt", size=(0, 8)), "0")
    refused(lambda: cornell.render("pt", size=(8, 8), gaze=(1.5, 0.5)), "expected X,Y with both in [0,1]")
    refused(lambda: cornell.render("pt", size=(8, 8), gaze=(0.5, 0.5), gaze_trace=[(0, 0.5, 0.5)]), "exclude each other")
    refused(lambda: cornell.render("pt", size=(8, 8), gaze_trace=[(1, 0.5, 0.5), (0, 0.5, 0.5)]), "must increase")
    refused(lambda: cornell.render("pt", size=(8, 8), gaze_trace="/no/such/trace.csv"), "/no/such/trace.csv", fovea.Status.IO)
    refused(lambda: cornell.render("pt", size=(8, 8), gaze_trace="/dev/zero"), "not a regular file", fovea.Status.IO)
    refused(lambda: cornell.render("pt", size=(8, 8), fps=0), "fps")
    refused(lambda: cornell.render("pt", size=(8, 8), camera_pos=(1e30, 0, 0)), "camera")
    refused(lambda: cornell.render("pt", size=(8, 8), fov=200), "fov")
    refused(lambda: cornell.render("pt", size=(8, 8), aux=("depht",)), "depht")


def test_wrong_python_types(cornell):
    for call in (lambda: fovea.Scene(42), lambda: cornell.render(7), lambda: cornell.render("pt", size="8x8"),
                 lambda: cornell.render("pt", size=(8, 8), spp="4"), lambda: cornell.render("pt", size=(8, 8), params=["spp=4"]),
                 lambda: cornell.render("pt", size=(8, 8), params={"spp": [4]}), lambda: cornell.render("pt", size=(8.5, 8)),
                 lambda: cornell.render("pt", size=(8, 8), gaze="0.5,0.5"), lambda: fovea.Renderer("cornell"),
                 lambda: fovea.compare([[0]], [[0]]), lambda: fovea.write_image("/tmp/x.pfm", [[0, 0, 0]]),
                 lambda: fovea.bench(3), lambda: fovea.method(None), lambda: cornell.render("pt", progress=5)):
        with pytest.raises(TypeError):
            call()
    refused(lambda: fovea.write_image("/tmp/x.pfm", np.zeros((4, 4))), "shape")
    refused(lambda: fovea.Scene("corn\0ell"), "NUL")


def test_bad_scenes_and_files(tmp_path):
    e = refused(lambda: fovea.Scene(tmp_path / "missing.json"), "missing.json", fovea.Status.IO)
    assert e.exit_code == 2
    bad = tmp_path / "bad.json"
    bad.write_text('{"objects": [ {"mesh": "box", "size": [1, 1, 1]} ], "camera": 5}')
    refused(lambda: fovea.Scene(bad), "bad.json")
    refused(lambda: fovea.Scene("cornell", frame_view="sideways"), "frame_view sideways")
    refused(lambda: fovea.Scene("cornell", env=(-1, 0, 0)), "env")
    refused(lambda: fovea.read_image(tmp_path / "none.pfm"), "none.pfm", fovea.Status.IO)
    (tmp_path / "junk.png").write_bytes(b"not a png at all")
    refused(lambda: fovea.read_image(tmp_path / "junk.png"), "junk.png")
    rgb = np.zeros((4, 4, 3), np.float32)
    refused(lambda: fovea.write_image(tmp_path / "no/dir/x.pfm", rgb), "no/dir/x.pfm", fovea.Status.IO)
    refused(lambda: fovea.write_image(tmp_path / "x.jpg", rgb), "x.jpg")


def test_cancel_and_callback_errors(cornell):
    with cornell.renderer("pt", size=(16, 16), spp=1) as r:
        refused(lambda: r.render(progress=lambda f: False), "", fovea.Status.CANCELLED)

        def boom(fraction):
            raise KeyError("from the callback")
        with pytest.raises(KeyError, match="from the callback"):
            r.render(progress=boom)
        seen = []
        img = r.render(progress=seen.append)  # None means go on
        assert seen and img.frame == 0 and np.isfinite(img.rgb).all()


def test_handles_after_close():
    s = fovea.Scene("cornell")
    r = s.renderer("pt", size=(8, 8), spp=1)
    r.render()
    s.close()  # closes the renderer first: its technique must go before the scene
    assert s.closed and r.closed
    refused(lambda: r.render(), "after close()")
    refused(lambda: s.renderer("pt"), "after close()")
    refused(lambda: s.triangle_count, "after close()")
    s.close()
    r.close()
    with fovea.Scene("cornell") as s2, s2.renderer("pt", size=(8, 8), spp=1) as r2:
        r2.render()
    assert r2.closed and s2.closed


class Counting:
    """The library with every handle's life counted: a handle a create call hands out is live
    until its destroy call (the Python layer's bookkeeping, which ASan cannot see through ctypes)."""

    CREATE = {"fv_scene_open", "fv_technique_create", "fv_driver_create", "fv_film_create", "fv_params_create",
              "fv_gaze_path_create_keys", "fv_gaze_path_load_csv", "fv_camera_path_load_csv", "fv_image_read",
              "fv_image_read_layer", "fv_image_read_meta"}
    DESTROY = {"fv_scene_destroy", "fv_view_destroy", "fv_technique_destroy", "fv_driver_destroy", "fv_film_destroy",
               "fv_params_destroy", "fv_gaze_path_destroy", "fv_camera_keys_free", "fv_image_free"}

    def __init__(self, real):
        self.real, self.live, self.created = real, {}, 0

    @staticmethod
    def addr(x):
        x = getattr(x, "_obj", x)  # through byref()
        if isinstance(x, fovea._capi.Image):
            x = x.rgb
        if isinstance(x, ctypes._Pointer):
            return ctypes.cast(x, ctypes.c_void_p).value
        return x.value if isinstance(x, ctypes.c_void_p) else None

    def __getattr__(self, name):
        f = getattr(self.real, name)
        if name in self.CREATE:
            def create(*args):
                status = f(*args)
                for a in args[:-1] if status == 0 else ():
                    if hasattr(a, "_obj") and self.addr(a):
                        self.live[self.addr(a)] = name
                        self.created += 1
                return status
            return create
        if name in self.DESTROY:
            def destroy(h):
                a = self.addr(h)
                assert a is None or self.live.pop(a, None), f"{name} of a handle no create call gave"
                return f(h)
            return destroy
        return f


def test_every_handle_is_freed(monkeypatch, tmp_path):
    counting = Counting(fovea._capi.lib)
    monkeypatch.setattr(fovea._capi, "lib", counting)
    (tmp_path / "gaze.csv").write_text("0,0.2,0.3\n1,0.8,0.7\n")
    (tmp_path / "cam.csv").write_text("0,278,273,-800,278,273,0\n1,300,273,-800,278,273,0\n")
    with fovea.Scene("cornell") as s:
        with s.renderer("pt", size=(8, 8), spp=1, gaze_trace=tmp_path / "gaze.csv", camera_trace=tmp_path / "cam.csv") as r:
            img = r.render()
        s.render("fpm", size=(8, 8), params={"photons": 500}, gaze_trace=[(0, 0.5, 0.5)], aux=True, stereo=5.0)
        s.renderer("pt", size=(8, 8), spp=1).render()  # left to the collector
        kept = s.renderer("pt", size=(8, 8), spp=1)  # closed with its scene
        with pytest.raises(fovea.FoveaError):
            s.render("pt", size=(8, 8), params={"nope": 1})
        with pytest.raises(fovea.FoveaError):
            s.render("pt", size=(8, 8), gaze_trace=[(1, 0.5, 0.5), (0, 0.5, 0.5)])
        with pytest.raises(fovea.FoveaError):
            s.renderer("pt", size=(8, 8), spp=1).render(progress=lambda f: False)
    assert kept.closed
    with pytest.raises(fovea.FoveaError):
        fovea.Scene(tmp_path / "none.json")
    img.write(tmp_path / "a.png")
    img.write(tmp_path / "a.exr", metadata=False)
    fovea.compare(tmp_path / "a.png", tmp_path / "a.exr")
    fovea.read_image(tmp_path / "a.exr")
    fovea.bench({"name": "t", "scene": "cornell", "size": [8, 8], "repeats": 1,
                 "reference": {"method": "pt", "params": {"spp": 2}}, "methods": [{"method": "pt", "params": {"spp": 1}}]},
                out_dir=tmp_path / "b")
    del r, img
    gc.collect()
    assert counting.created > 20 and counting.live == {}


def test_library_lookup_errors():
    """A FOVEA_LIB that is not a library fails the import with one line naming it."""
    env = dict(os.environ, FOVEA_LIB="/no/such/libfovea.so", PYTHONPATH=PYDIR)
    r = subprocess.run([sys.executable, "-c", "import fovea"], capture_output=True, text=True, env=env, timeout=60)
    assert r.returncode != 0 and "ImportError" in r.stderr and "/no/such/libfovea.so" in r.stderr
    env["FOVEA_LIB"] = fovea.library_path()
    r = subprocess.run([sys.executable, "-c", "import fovea; print(fovea.library_path())"], capture_output=True, text=True,
                       env=env, timeout=60)
    assert r.returncode == 0 and r.stdout.strip() == fovea.library_path()
