"""fovea — running a benchmark scenario (include/fovea/bench.h, docs/bench.md) and getting its
report as a dict: the same harness, cache and reports as `fovea bench`, the report handed over by
the library (fv_bench_options.report) rather than read back from a file whose name would have to
be worked out here.
"""
import contextlib
import ctypes
import json
import os
import tempfile

from . import _capi, _convert, _loader
from ._errors import FoveaError, emit_warnings


def scenario_dirs():
    """Where a bare scenario name is looked up, in order, as `fovea bench` does: $FOVEA_BENCH_DIR,
    ./bench, the installed scenarios of this package's prefix, else the source tree's bench/."""
    dirs = []
    env = os.environ.get("FOVEA_BENCH_DIR")
    if env:
        dirs.append(env)
    dirs.append("bench")
    installed = _loader.installed_bench_dir()
    if installed:
        dirs.append(installed)
    else:
        src = _loader.source_bench_dir()
        if src:
            dirs.append(src)
    return dirs


def find_scenario(name):
    """The file of scenario ``name`` (a path, containing '/' or ending in .json, is returned as it is)."""
    if "/" in name or name.endswith(".json"):
        return name
    dirs = scenario_dirs()
    for d in dirs:
        p = os.path.join(d, name + ".json")
        if os.path.isfile(p):
            return p
    raise FoveaError(f"unknown scenario '{name}': no {name}.json in {', '.join(dirs)}")


def bench(scenario, *, mode="default", out_dir=None, cache_dir=None, threads=0, repeats=None, device=None, status=None,
          base_dir=None):
    """Runs a scenario and returns its JSON report as a dict (docs/bench.md lists its fields).

    ``scenario``: a name (bench/NAME.json, looked up as `fovea bench` does), a path, or the
    scenario itself as a dict (its relative scene and trace paths resolve against ``base_dir``,
    default the current folder). ``mode``: "default", "quick" or "full". ``out_dir``: where the
    reports, images and reference cache go; by default a temporary folder removed afterwards (the
    report's image paths then name files that are gone; pass ``cache_dir`` to keep references).
    ``status(line)`` receives the progress lines."""
    if mode not in _capi.BENCH_MODES:
        raise FoveaError(f"mode {mode!r}: expected default, quick or full")
    sink = _capi.WarningSink()
    got, raised = [], []

    def on_report(user, text):
        got.append(_capi.text(text))

    def on_status(user, line):
        if status is not None and not raised:
            try:
                status(_capi.text(line))
            except Exception as e:  # the run cannot be stopped from here: raised once it returns
                raised.append(e)

    report_fn, status_fn = _capi.LINE_FN(on_report), _capi.LINE_FN(on_status)
    opt = _capi.BenchOptions()
    opt.mode = _capi.BENCH_MODES[mode]
    opt.threads = _convert.integer(threads, "threads", 0, 256)
    opt.repeats = 0 if repeats is None else _convert.integer(repeats, "repeats", 1, 1000)
    opt.log = ctypes.pointer(sink.log)
    opt.status, opt.report = status_fn, report_fn
    opt.table = _capi.LINE_FN()
    opt.device = None if device is None else _convert.cstr(device, "device")
    opt.cache_dir = None if cache_dir is None else _convert.cstr(cache_dir, "cache_dir")
    if isinstance(scenario, dict):
        text = json.dumps(scenario).encode()
        label = _convert.cstr(str(scenario.get("name", "scenario")) + ".json", "scenario name")
        base = _convert.cstr(base_dir if base_dir is not None else os.getcwd(), "base_dir")
        what = f"fovea.bench({{...}}, mode={mode!r})"
        run = (_capi.lib.fv_bench_run_text, text, label, base)
    elif isinstance(scenario, (str, os.PathLike)):
        path = find_scenario(os.fspath(scenario))
        what = f"fovea.bench({os.fspath(scenario)!r}, mode={mode!r})"
        run = (_capi.lib.fv_bench_run, _convert.cstr(path, "scenario"))
    else:
        raise TypeError(f"scenario: expected a name, a path or a dict, not {type(scenario).__name__}")
    opt.command = what.encode()
    with tempfile.TemporaryDirectory(prefix="fovea-bench-") if out_dir is None else contextlib.nullcontext() as tmp:
        opt.out_dir = _convert.cstr(tmp if out_dir is None else out_dir, "out_dir")
        try:
            _capi.call(*run, ctypes.byref(opt))
        finally:
            emit_warnings(sink.messages)
    if raised:
        raise raised[0]
    if len(got) != 1:
        raise FoveaError("bench: the run finished without handing over its report", 4)
    return json.loads(got[0])

