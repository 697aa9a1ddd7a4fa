"""Rendering through the package: what comes back (shape, type, finite, lit), and that it is the
image `fovea render` writes for the same settings, bit for bit (both go through the sequence
driver; PFM keeps the floats exactly)."""
import os

import numpy as np
import pytest

import fovea

SIZE = (40, 32)


def cli_pfm(cli, tmp_path, name, *args):
    out = tmp_path / f"{name}.pfm"
    cli("render", *args, "--size", f"{SIZE[0]}x{SIZE[1]}", "--no-metadata", "--quiet", "--out", out)
    return fovea.read_image(out)


def test_tiny_cornell_at_a_gaze(cornell, cli, tmp_path):
    img = cornell.render("pt", size=SIZE, spp=2, gaze=(0.3, 0.6))
    assert isinstance(img, fovea.Image)
    assert img.rgb.shape == (SIZE[1], SIZE[0], 3) and img.rgb.dtype == np.float32
    assert np.isfinite(img.rgb).all()
    # lit: the light and the walls, not black; the red wall on the left, the green one on the right
    assert img.rgb.mean() > 0.05 and img.rgb.max() > 1.0
    red_minus_green = (img.rgb[..., 0] - img.rgb[..., 1]).mean(axis=0)  # per column
    third = SIZE[0] // 3
    assert red_minus_green[:third].mean() > red_minus_green[-third:].mean() + 0.04
    assert img.gaze == (0.3, 0.6) and img.frame == 0 and img.eye == "mono" and img.method == "pt"
    assert img.stats["counters"]["samples"] == SIZE[0] * SIZE[1] * 2
    ref = cli_pfm(cli, tmp_path, "pt", "cornell", "--method", "pt", "--spp", 2, "--gaze", "0.3,0.6")
    assert np.array_equal(img.rgb, ref)
    # and written by the package, the file is the tool's, byte for byte
    img.write(tmp_path / "py.pfm")
    assert (tmp_path / "py.pfm").read_bytes() == (tmp_path / "pt.pfm").read_bytes()


def test_foveated_method_follows_the_gaze(cornell, cli, tmp_path):
    params = {"photons": 4000, "filter": False}
    a = cornell.render("fpm", size=SIZE, params=params, gaze=(0.25, 0.5), seed=3)
    b = cornell.render("fpm", size=SIZE, params=params, gaze=(0.75, 0.5), seed=3)
    ref = cli_pfm(cli, tmp_path, "fpm", "cornell", "--method", "fpm", "--param", "photons=4000", "--param", "filter=false",
                  "--gaze", "0.25,0.5", "--seed", 3)
    assert np.array_equal(a.rgb, ref)
    assert not np.array_equal(a.rgb, b.rgb)
    assert a.metadata["foveated"] == "true" and a.metadata["gaze"] == "0.25,0.5"


def test_a_sequence_continues_like_the_tool(cornell, cli, tmp_path):
    # pm-t keeps its static photons between frames: frame 1 of a sequence is not frame 1 alone
    opts = dict(size=SIZE, params={"photons": 3000}, gaze=(0.5, 0.5))
    with cornell.renderer("pm-t", **opts) as r:
        frames = list(r.frames(2))
    assert [f.frame for f in frames] == [0, 1]
    out = tmp_path / "seq.pfm"
    cli("render", "cornell", "--method", "pm-t", "--param", "photons=3000", "--frames", 2, "--size", f"{SIZE[0]}x{SIZE[1]}",
        "--no-metadata", "--quiet", "--out", out)
    for i in range(2):
        assert np.array_equal(frames[i].rgb, fovea.read_image(tmp_path / f"seq_{i:04d}.pfm"))


def test_gaze_trace_keys_equal_a_csv(cornell, tmp_path):
    csv = tmp_path / "gaze.csv"
    csv.write_text("time,x,y\n0,0.2,0.3\n1,0.8,0.7\n")
    keys = [(0, 0.2, 0.3), (1, 0.8, 0.7)]
    a = cornell.render("fpm", size=SIZE, params={"photons": 2000}, gaze_trace=csv, time=0.5)
    b = cornell.render("fpm", size=SIZE, params={"photons": 2000}, gaze_trace=keys, time=0.5)
    assert a.gaze == pytest.approx((0.5, 0.5)) and np.array_equal(a.rgb, b.rgb)


def test_aux_and_stereo(cornell, tmp_path):
    img = cornell.render("pt", size=SIZE, spp=1, aux=True)
    assert img.depth.shape == (SIZE[1], SIZE[0]) and img.normal.shape == (SIZE[1], SIZE[0], 3)
    assert img.id.dtype == np.uint32 and img.id.max() >= 1
    # the camera looks into the open box from outside: no surface (id 0) exactly where depth is +inf
    assert np.array_equal(img.id == 0, np.isinf(img.depth))
    assert 0 < img.depth[SIZE[1] // 2, SIZE[0] // 2] < np.inf
    img.write(tmp_path / "aux.exr")
    assert np.array_equal(fovea.read_image(tmp_path / "aux.exr"), img.rgb)
    assert np.array_equal(fovea.read_image(tmp_path / "aux.exr", layer="albedo"), img.albedo)
    left, right = cornell.render("pt", size=SIZE, spp=1, stereo=20.0)
    assert (left.eye, right.eye) == ("left", "right") and not np.array_equal(left.rgb, right.rgb)


def test_write_and_read_image(tmp_path):
    rgb = np.linspace(0, 1, 6 * 4 * 3, dtype=np.float32).reshape(4, 6, 3)
    fovea.write_image(tmp_path / "a.pfm", rgb)
    assert np.array_equal(fovea.read_image(tmp_path / "a.pfm"), rgb)
    fovea.write_image(tmp_path / "a.exr", rgb.astype(np.float64))
    assert np.array_equal(fovea.read_image(tmp_path / "a.exr"), rgb)
    fovea.write_image(tmp_path / "a.png", rgb, metadata={"note": "hello"})
    assert np.abs(fovea.read_image(tmp_path / "a.png") - rgb).max() < 0.01  # 8-bit sRGB
    assert fovea.read_metadata(tmp_path / "a.png") == {"note": "hello"}


def test_read_metadata_of_a_malformed_exr_says_nothing(tmp_path, capfd):
    # A header cut inside the channel list: one FoveaError, and none of OpenEXR's own lines on
    # stderr (issue 42, item 5).
    bad = tmp_path / "cut.exr"
    bad.write_bytes(b"v/1\x01\x02\x00\x00\x00channels\x00chlist\x00\x05")
    with pytest.raises(fovea.FoveaError):
        fovea.read_metadata(bad)
    assert capfd.readouterr().err == ""


def test_set_gaze_and_scene_queries(cornell):
    with cornell.renderer("fpm", size=SIZE, params={"photons": 2000}) as r:
        r.set_gaze((0.2, 0.8))
        a = r.render(0)
    b = cornell.render("fpm", size=SIZE, params={"photons": 2000}, gaze=(0.2, 0.8))
    assert a.gaze == (0.2, 0.8) and np.array_equal(a.rgb, b.rgb)
    assert cornell.triangle_count == 32  # `fovea scenes`: "... ceiling light; 32 triangles"
    assert cornell.camera(SIZE) == {"pos": (278, 273, -800), "look": (278, 273, 0), "up": (0, 1, 0), "fov_y": 37.5}
    lo, hi = cornell.bounds
    assert all(lo[i] < hi[i] for i in range(3))


def test_scene_files_as_the_tool_loads_them(cli, tmp_path):
    src = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", ".."))
    mesh = os.path.join(src, "tests", "data", "box_closed.obj")  # no light: the default one, with a warning
    with pytest.warns(fovea.FoveaWarning, match="no lights"):
        scene = fovea.Scene(mesh)
    with scene:
        img = scene.render("pt", size=SIZE, spp=2)
    assert img.rgb.mean() > 0.01
    assert np.array_equal(img.rgb, cli_pfm(cli, tmp_path, "mesh", mesh, "--method", "pt", "--spp", 2))
    with fovea.Scene(os.path.join(src, "scenes", "cornell-obj.json")) as scene:  # a JSON scene naming an OBJ file
        assert scene.triangle_count > 1000 and scene.light_count >= 1
