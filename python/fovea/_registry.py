"""fovea — the rendering methods of the registry and their parameters (include/fovea/technique.h).

Everything here is read from the library's own description of its methods, `fv_methods_json`
(what `fovea methods --json` prints): one place per method, typed parameters with their defaults
and ranges, the family, the baseline its paper measures it against, its warm-up frames.
"""
import dataclasses
import json

from . import _capi
from ._errors import FoveaError


@dataclasses.dataclass(frozen=True)
class Param:
    """One parameter: ``key``; ``type`` "int", "float", "bool", "choice" or "string"; ``default``
    as a Python value (None when the method derives it: ``default_note`` says how); ``min`` and
    ``max`` (None when unbounded), ``min_open``/``max_open`` when an end is excluded; ``choices`` (a
    tuple of the accepted values, else None); ``help``, what it means."""

    key: str
    type: str
    default: object = None
    default_note: str = None
    min: float = None
    max: float = None
    min_open: bool = False
    max_open: bool = False
    choices: tuple = None
    help: str = ""

    def accepts(self, value):
        """Whether value lies within the declared range or choices (other parameters may narrow
        it further; the library has the last word)."""
        if self.choices is not None:
            return value in self.choices or str(value) in [str(c) for c in self.choices]
        if self.type in ("int", "float"):
            v = float(value)
            lo_ok = self.min is None or (v > self.min if self.min_open else v >= self.min)
            hi_ok = self.max is None or (v < self.max if self.max_open else v <= self.max)
            return lo_ok and hi_ok
        return True


@dataclasses.dataclass(frozen=True)
class Method:
    """A method of the registry, as `fovea methods NAME` describes it."""

    name: str
    summary: str
    family: str              # "path tracing", "photon mapping", ...
    foveated: bool           # its image depends on the gaze
    baseline: str            # the method its paper measures it against (None: the reference, pt)
    spp_param: str           # the key spp= sets (None: the method has no samples-per-pixel notion)
    devices: tuple           # ("cpu", ...) where it runs
    warmup_frames: int       # an MPI block of a sequence starts with these (docs/distributed.md)
    still_warmup_frames: int # frames rendered before a converged still (render(warmup=None))
    main_parameter: dict     # {"key", "steps", "default_step", "progressive"} or None
    params: tuple            # of Param

    def param(self, key):
        for p in self.params:
            if p.key == key:
                return p
        raise FoveaError(f"method {self.name} has no parameter '{key}' (it has: {', '.join(p.key for p in self.params)})")


def _param(d):
    ch = d.get("choices")
    return Param(key=d["key"], type=d["type"], default=d.get("default"), default_note=d.get("default_note"), min=d.get("min"),
                 max=d.get("max"), min_open=bool(d.get("min_open")), max_open=bool(d.get("max_open")),
                 choices=tuple(ch) if ch is not None else None, help=d.get("help") or "")


def _method(d):
    return Method(name=d["name"], summary=d["summary"], family=d["family"], foveated=bool(d["foveated"]), baseline=d.get("baseline"),
                  spp_param=d.get("spp_param"), devices=tuple(d["devices"]), warmup_frames=int(d["warmup_frames"]),
                  still_warmup_frames=int(d["still_warmup_frames"]), main_parameter=d.get("main_parameter"),
                  params=tuple(_param(p) for p in d["parameters"]))


def methods():
    """Every method of the registry, in its order (that of `fovea methods --json`)."""
    return [_method(d) for d in json.loads(_capi.methods_json())["methods"]]


def families():
    """{family: [method names]}, in the registry's order."""
    return {f["name"]: list(f["methods"]) for f in json.loads(_capi.methods_json())["families"]}


def method(name):
    """The method called name; FoveaError naming the known ones for an unknown name."""
    if not isinstance(name, str):
        raise TypeError(f"method: expected a str, not {type(name).__name__}")
    if "\0" in name:
        raise FoveaError(f"unknown method {name!r}")
    return _method(json.loads(_capi.methods_json(name))["methods"][0])


def scenes():
    """The built-in scenes: {name: one-line summary}, in the order of `fovea scenes`."""
    lib = _capi.lib
    return {_capi.text(lib.fv_builtin_name(i)): _capi.text(lib.fv_builtin_summary(i)) for i in range(lib.fv_builtin_count())}
