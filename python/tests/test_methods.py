"""The registry as Python sees it: the same methods, families, baselines, typed parameters and
devices as `fovea methods --json` lists (both read fv_methods_json), and hand-checked facts."""
import json

import pytest

import fovea


def test_methods_match_the_tool(cli):
    doc = json.loads(cli("methods", "--json").stdout)
    ms = fovea.methods()
    assert [m.name for m in ms] == [d["name"] for d in doc["methods"]]
    for m, d in zip(ms, doc["methods"]):
        assert (m.summary, m.family, m.foveated, m.baseline) == (d["summary"], d["family"], d["foveated"], d["baseline"])
        assert m.devices == tuple(d["devices"])
        assert (m.warmup_frames, m.still_warmup_frames) == (d["warmup_frames"], d["still_warmup_frames"])
        assert [p.key for p in m.params] == [p["key"] for p in d["parameters"]]
        # the plain listing names the same methods, each at the start of a line
        assert any(line.split()[:1] == [m.name] for line in cli("methods").stdout.splitlines())
    assert fovea.families() == {f["name"]: f["methods"] for f in doc["families"]}


def test_method_facts():
    pt = fovea.method("pt")
    assert pt.spp_param == "spp" and not pt.foveated and pt.baseline is None
    spp = pt.param("spp")
    assert (spp.type, spp.default) == ("int", 16) and "samples per pixel" in spp.help
    assert spp.accepts(16) and not spp.accepts(0)
    fpm = fovea.method("fpm")
    assert fpm.foveated and fpm.baseline == "pm" and fpm.family == "photon mapping"
    assert fpm.param("eta_region").choices == ("fovea", "focus")
    assert fpm.param("eta_region").accepts("focus") and not fpm.param("eta_region").accepts("nope")
    assert fpm.still_warmup_frames == 0 and fovea.method("vpolar").still_warmup_frames == 16
    with pytest.raises(fovea.FoveaError, match="has no parameter 'nope'"):
        fpm.param("nope")
    assert "cornell" in fovea.scenes() and "furnace" in fovea.scenes()
    # every baseline is a registered method and following them ends at pt
    names = {m.name: m for m in fovea.methods()}
    for m in names.values():
        seen, cur = set(), m
        while cur.baseline is not None:
            assert cur.baseline in names and cur.name not in seen
            seen.add(cur.name)
            cur = names[cur.baseline]
        assert cur.name == "pt"


def test_unknown_method():
    with pytest.raises(fovea.FoveaError) as e:
        fovea.method("no-such")
    assert "unknown method 'no-such'" in e.value.message and "pt" in e.value.message
    assert e.value.status == fovea.Status.INVALID and e.value.exit_code == 2
