"""fovea — the rendering methods of the registry and their parameters (include/fovea/technique.h).

What a method takes is read from its parameter help, lines "key=type (default): meaning", by
:func:`parse_params_help` alone: the one place to switch when the library describes its
parameters in structured form (a JSON list of methods), so nothing else here depends on the help
text's layout.
"""
import dataclasses
import re

from . import _capi
from ._errors import FoveaError

DEVICES = (("portable", 1), ("cuda", 2))  # fv_device values besides the CPU, which every method has


@dataclasses.dataclass(frozen=True)
class Param:
    """One parameter: ``key``, ``type`` as the help gives it ("int", "float", "bool", or the choices
    "grid|random"), ``choices`` (a tuple, for a choice), ``default`` as text ("16", "Eq. 8",
    None when the help gives none) and ``help`` (the meaning; shared by keys listed together)."""

    key: str
    type: str
    default: str = None
    help: str = ""
    choices: tuple = None


@dataclasses.dataclass(frozen=True)
class Method:
    """A method of the registry, as `fovea methods` lists it."""

    name: str
    summary: str
    foveated: bool     # its image depends on the gaze
    spp_param: str     # the key spp= sets (None: the method has no samples-per-pixel notion)
    devices: tuple     # ("cpu", ...) where it runs
    params: tuple      # of Param
    params_help: str   # the registry's help text, as it is

    def param(self, key):
        for p in self.params:
            if p.key == key:
                return p
        raise FoveaError(f"method {self.name} has no parameter '{key}' (it has: {', '.join(p.key for p in self.params)})")


def _split_top(s, sep):
    """s split at sep where it is outside parentheses."""
    out, depth, start, i = [], 0, 0, 0
    while i < len(s):
        c = s[i]
        if c == "(":
            depth += 1
        elif c == ")":
            depth = max(0, depth - 1)
        elif depth == 0 and s.startswith(sep, i):
            out.append(s[start:i])
            start = i + len(sep)
            i = start
            continue
        i += 1
    out.append(s[start:])
    return out


_ENTRY = re.compile(r"^\s*([a-z0-9_-]+)=([^\s(]+)\s*(?:\((.*)\))?\s*$")


def parse_params_help(text):
    """Params from help lines "key=type (default): meaning"; several keys may share a line
    ("a=int (1), b=float (0.2): ..."). A line that does not read so is skipped, not guessed."""
    params = []
    for line in (text or "").splitlines():
        parts = _split_top(line, ": ")
        head, meaning = parts[0], ": ".join(parts[1:]).strip()
        for entry in _split_top(head, ", "):
            m = _ENTRY.match(entry)
            if not m:
                continue
            key, typ, default = m.group(1), m.group(2), m.group(3)
            choices = tuple(typ.split("|")) if "|" in typ else None
            params.append(Param(key, typ, default, meaning, choices))
    return tuple(params)


def _method(i):
    lib = _capi.lib
    devices = ("cpu",) + tuple(name for name, bit in DEVICES if lib.fv_technique_has_device(i, bit))
    help_text = _capi.text(lib.fv_technique_params_help(i))
    spp = lib.fv_technique_spp_param(i)
    return Method(name=_capi.text(lib.fv_technique_name(i)), summary=_capi.text(lib.fv_technique_summary(i)),
                  foveated=bool(lib.fv_technique_foveated(i)), spp_param=_capi.text(spp) if spp else None,
                  devices=devices, params=parse_params_help(help_text), params_help=help_text)


def methods():
    """Every method of the registry, in its order (that of `fovea methods`)."""
    return [_method(i) for i in range(_capi.lib.fv_technique_count())]


def method(name):
    """The method called name; FoveaError for an unknown name."""
    if not isinstance(name, str):
        raise TypeError(f"method: expected a str, not {type(name).__name__}")
    i = _capi.lib.fv_technique_index(name.encode()) if "\0" not in name else -1
    if i < 0:
        known = ", ".join(_capi.text(_capi.lib.fv_technique_name(k)) for k in range(_capi.lib.fv_technique_count()))
        raise FoveaError(f"unknown method '{name}' (known: {known})")
    return _method(i)


def scenes():
    """The built-in scenes: {name: one-line summary}, in the order of `fovea scenes`."""
    lib = _capi.lib
    return {_capi.text(lib.fv_builtin_name(i)): _capi.text(lib.fv_builtin_summary(i)) for i in range(lib.fv_builtin_count())}
