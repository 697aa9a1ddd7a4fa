"""fovea.compare gives the numbers `fovea compare --json` prints for the same two files, for
files, arrays and rendered Images alike, with the tool's gaze rule."""
import json
import math

import numpy as np
import pytest

import fovea

SIZE = (48, 40)


@pytest.fixture(scope="module")
def pair(cornell, tmp_path_factory):
    d = tmp_path_factory.mktemp("compare")
    ref = cornell.render("pt", size=SIZE, spp=16, seed=7)
    test = cornell.render("fpm", size=SIZE, params={"photons": 3000}, gaze=(0.35, 0.45))
    ref.write(d / "ref.pfm")
    ref.write(d / "ref.png")
    test.write(d / "test.png")  # its metadata records the gaze and that fpm is foveated
    test.write(d / "test.pfm")
    return d, ref, test


def same(py, tool):
    """A dict's numbers against the tool's JSON (null: nan or inf; %.9g and %.6g text)."""
    for r in ("fovea", "transition", "periphery", "all"):
        a, b = py["regions"][r], tool["regions"][r]
        assert a["pixels"] == b["pixels"] and a["nonfinite"] == b["nonfinite"]
        for k in ("mse", "psnr", "e", "ssim", "flip"):
            if b[k] is None:
                assert not math.isfinite(a[k]), (r, k)
            else:
                assert a[k] == pytest.approx(b[k], rel=1e-7, abs=1e-12), (r, k)
    assert py["size"] == tool["size"]
    assert py["gaze"] == pytest.approx(tool["gaze"], abs=1e-6)
    assert py["fovea_radius_px"] == pytest.approx(tool["fovea_radius_px"], rel=1e-5)
    assert py["transition_radius_px"] == pytest.approx(tool["transition_radius_px"], rel=1e-5)
    assert py["nonfinite_pixels"] == tool["nonfinite_pixels"]


def test_same_numbers_as_the_tool(cli, pair):
    d, ref, test = pair
    tool = json.loads(cli("compare", d / "ref.png", d / "test.png", "--json").stdout)
    assert tool["gaze"] == [0.35, 0.45]  # from test.png's metadata
    py = fovea.compare(str(d / "ref.png"), str(d / "test.png"))
    same(py, tool)
    assert py["ref"] == str(d / "ref.png")
    # options as the tool's flags
    tool = json.loads(cli("compare", d / "ref.pfm", d / "test.pfm", "--json", "--gaze", "0.6,0.4", "--linear",
                          "--fovea-frac", "0.2", "--exposure", "2").stdout)
    same(fovea.compare(d / "ref.pfm", d / "test.pfm", gaze=(0.6, 0.4), linear=True, fovea_frac=0.2, exposure=2), tool)


def test_arrays_and_images_give_the_file_numbers(cli, pair):
    d, ref, test = pair
    tool = json.loads(cli("compare", d / "ref.pfm", d / "test.pfm", "--json", "--gaze", "0.35,0.45").stdout)
    same(fovea.compare(ref.rgb, test.rgb, gaze=(0.35, 0.45)), tool)
    same(fovea.compare(ref, test), tool)  # the gaze from test's metadata
    m = fovea.compare(ref, test, flip_map=True)["flip_map"]
    assert m.shape == (SIZE[1], SIZE[0]) and m.mean() == pytest.approx(tool["regions"]["all"]["flip"], rel=1e-5)


def test_identical_images():
    rgb = np.full((8, 8, 3), 0.25, dtype=np.float32)
    r = fovea.compare(rgb, rgb)["regions"]["all"]
    assert r["mse"] == 0 and r["psnr"] == math.inf and r["ssim"] == pytest.approx(1) and r["pixels"] == 64


def test_refusals(pair):
    d, ref, test = pair
    with pytest.raises(fovea.FoveaError, match="size mismatch"):
        fovea.compare(ref.rgb, test.rgb[:-1])
    other = fovea.Image(test.rgb, metadata=dict(test.metadata, gaze="0.9,0.9"))
    with pytest.raises(fovea.FoveaError, match="allow_gaze_mismatch"):
        fovea.compare(test, other)
    assert fovea.compare(test, other, allow_gaze_mismatch=True)["gaze"] == pytest.approx([0.9, 0.9])
    with pytest.raises(fovea.FoveaError, match="expected X,Y with both in"):
        fovea.compare(ref, test, gaze=(1.5, 0))
    with pytest.raises(TypeError):
        fovea.compare(ref, test, fovea_degs=3)
