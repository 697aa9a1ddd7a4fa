"""fovea.bench runs a scenario through the library's harness and returns its JSON report: the
report's errors are those of the same frames rendered and compared through the package."""
import json

import pytest

import fovea

TINY = {"name": "py-tiny", "scene": "cornell", "size": [24, 20], "repeats": 1, "seed": 5,
        "reference": {"method": "pt", "params": {"spp": 8}},
        "methods": [{"label": "pt-1", "method": "pt", "params": {"spp": 1}},
                    {"label": "pt-2", "method": "pt", "params": {"spp": 2}}]}


def test_report_of_a_tiny_scenario(tmp_path):
    lines = []
    rep = fovea.bench(TINY, out_dir=tmp_path, threads=1, status=lines.append)
    for key in ("scenario", "provenance", "size", "reference", "baseline", "results", "eye", "mode"):
        assert key in rep
    assert rep["scenario"] == "py-tiny" and rep["mode"] == "default" and rep["size"] == [24, 20]
    assert [r["method"] for r in rep["results"]] == ["pt-1", "pt-2"]
    assert any("py-tiny" in line for line in lines)
    assert json.loads((tmp_path / "py-tiny.json").read_text()) == rep  # the file the run wrote
    for r in rep["results"]:
        assert set(r["error"]) == {"fovea", "transition", "periphery", "all"}
        assert r["ms_per_frame"]["median"] > 0
    # The same frames through the package: each method at the scenario's seed, the reference at
    # the seed of its own stream (which the report records), compared with the bench's regions.
    with fovea.Scene("cornell") as s:
        ref = s.render("pt", size=(24, 20), spp=8, seed=int(rep["reference"]["seed"]))
        for spp, row in ((1, rep["results"][0]), (2, rep["results"][1])):
            img = s.render("pt", size=(24, 20), spp=spp, seed=5)
            got = fovea.compare(ref, img, gaze=(0.5, 0.5))["regions"]
            for region in ("fovea", "transition", "periphery", "all"):
                assert got[region]["pixels"] == row["error"][region]["pixels"]
                for k in ("mse", "e", "ssim", "flip"):
                    assert got[region][k] == pytest.approx(row["error"][region][k], rel=1e-6), (spp, region, k)
    # falling error with samples
    assert rep["results"][1]["error"]["all"]["mse"] < rep["results"][0]["error"]["all"]["mse"]


def test_named_scenario_quick_mode_check_only_through_errors(tmp_path):
    with pytest.raises(fovea.FoveaError, match="unknown scenario 'no-such-scenario'"):
        fovea.bench("no-such-scenario")
    assert fovea.find_scenario("pt-cornell").endswith("pt-cornell.json")
    bad = dict(TINY, methods=[{"method": "no-such-method"}])
    with pytest.raises(fovea.FoveaError) as e:
        fovea.bench(bad, out_dir=tmp_path / "bad")
    assert "no-such-method" in e.value.message and e.value.status == fovea.Status.INVALID
    assert not (tmp_path / "bad").exists()  # a refused scenario writes nothing
    with pytest.raises(fovea.FoveaError, match="mode"):
        fovea.bench(TINY, mode="fast")
