"""The registry as Python sees it: the same methods, summaries, parameters and devices as
`fovea methods` lists, and the help-line parser on hand-written lines."""
import pytest

import fovea


def test_methods_match_the_tool(cli):
    text = cli("methods").stdout
    blocks, cur = [], None
    for line in text.splitlines():
        if not line.startswith(" "):
            name, summary = line.split(None, 1)
            cur = {"name": name, "summary": summary.strip(), "params": [], "devices": None}
            blocks.append(cur)
        elif line.strip().startswith("--param "):
            cur["params"].append(line.strip()[len("--param "):])
        elif line.strip().startswith("devices: "):
            cur["devices"] = tuple(d.strip() for d in line.strip()[len("devices: "):].split("(")[0].split(","))
    ms = fovea.methods()
    assert [m.name for m in ms] == [b["name"] for b in blocks]
    for m, b in zip(ms, blocks):
        assert m.summary == b["summary"]
        assert m.params_help.splitlines() == b["params"]
        assert m.devices == (b["devices"] or ("cpu",))
        # every key the tool lists is a Param, in order
        keys = [p.key for p in m.params]
        for line in b["params"]:
            assert line.split("=", 1)[0] in keys, (m.name, line)


def test_method_facts():
    pt = fovea.method("pt")
    assert pt.spp_param == "spp" and not pt.foveated
    spp = pt.param("spp")
    assert (spp.type, spp.default, spp.help) == ("int", "16", "samples per pixel")
    fpm = fovea.method("fpm")
    assert fpm.foveated
    assert fpm.param("eta_region").choices == ("fovea", "focus")
    with pytest.raises(fovea.FoveaError, match="has no parameter 'nope'"):
        fpm.param("nope")
    assert "cornell" in fovea.scenes() and "furnace" in fovea.scenes()


def test_parse_params_help_by_hand():
    ps = fovea.parse_params_help(
        "spp=int (16): samples per pixel\n"
        "a=int (5), b=float (0.2), c=float: shared meaning: with a colon\n"
        "order=grid|random (grid): launch order\n"
        "radius=float (Eq. 8, scaled): gather radius\n"
        "not a parameter line\n")
    got = [(p.key, p.type, p.default, p.help, p.choices) for p in ps]
    assert got == [("spp", "int", "16", "samples per pixel", None),
                   ("a", "int", "5", "shared meaning: with a colon", None),
                   ("b", "float", "0.2", "shared meaning: with a colon", None),
                   ("c", "float", None, "shared meaning: with a colon", None),
                   ("order", "grid|random", "grid", "launch order", ("grid", "random")),
                   ("radius", "float", "Eq. 8, scaled", "gather radius", None)]
    assert fovea.parse_params_help("") == ()


def test_unknown_method():
    with pytest.raises(fovea.FoveaError) as e:
        fovea.method("no-such")
    assert "unknown method 'no-such'" in e.value.message and "pt" in e.value.message
    assert e.value.status == fovea.Status.INVALID and e.value.exit_code == 2
