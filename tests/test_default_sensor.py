"""One default sensor (issue 15): every public function's default sensor is the CLI's.

The command line defaults to Super 35 (``physcam.cli._common.resolve_sensor`` without --sensor);
the Python API's defaults (``sensor_width_mm``/``sensor_height_mm``, ``sensor_mm``, the MTF chart's
``max_image_height_mm``) are read here from the signatures with :func:`inspect.signature`, for every
public function and class of the library, so the two cannot drift apart again.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import inspect
import math
from pathlib import Path

import pytest

from _public_api import public_objects
from physcam.cli._common import DEFAULT_SENSOR, resolve_sensor
from physcam.data import default_sensor

SKIP_MODULES = (".cli", "__main__", ".kernels", ".serve")
#: A parameter that is one side of the sensor, its (width, height), or the reach of a chart to its corner.
SENSOR_PARAMS = {"sensor_width_mm": "width", "sensor_height_mm": "height", "sensor_mm": "both",
                 "max_image_height_mm": "half_diagonal"}
REFERENCE = Path(__file__).resolve().parent / "data" / "sensor_formats.csv"


def _cli_default_sensor():
    """The sensor the command line takes when none is given (conftest: an empty user config)."""
    return resolve_sensor(argparse.Namespace(), quiet=True)


def _signatures():
    """(qualified name, signature) of every public function and class (``__all__``) of the library."""
    out = []
    for mod, name, obj in public_objects(SKIP_MODULES):
        if not (inspect.isfunction(obj) or inspect.isclass(obj)):
            continue
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):
            continue
        out.append((f"{mod}.{name}", sig))
    return out


def _sensor_defaults():
    found = []
    for qual, sig in _signatures():
        for p in sig.parameters.values():
            if p.name in SENSOR_PARAMS and p.default is not p.empty and p.default is not None:
                found.append((qual, p.name, p.default))
    return found


def test_the_cli_and_the_api_name_one_constant():
    assert DEFAULT_SENSOR is default_sensor.DEFAULT_SENSOR == "Super 35"
    s = _cli_default_sensor()
    assert (s.width_mm, s.height_mm) == default_sensor.DEFAULT_SENSOR_MM
    assert default_sensor.DEFAULT_SENSOR_LABEL == f"Super 35 ({s.width_mm:g} x {s.height_mm:g} mm)"


def test_the_default_gate_is_super_35_full_aperture_as_published():
    # SMPTE 59 / Nuke's Film/Super35: 0.980 x 0.735 in = 24.892 x 18.669 mm; the shared reference
    # table lists the same gate
    w, h = default_sensor.DEFAULT_SENSOR_MM
    assert w == pytest.approx(0.980 * 25.4, abs=0.01) and h == pytest.approx(0.735 * 25.4, abs=0.01)
    rows = {r["format"]: r for r in csv.DictReader(REFERENCE.read_text(encoding="utf-8").splitlines())}
    ref = rows["Super 35 4-perf full aperture (Silent)"]
    assert (w, h) == (float(ref["width_mm"]), float(ref["height_mm"]))
    assert 2 * default_sensor.DEFAULT_SENSOR_HALF_DIAGONAL_MM == pytest.approx(float(ref["diagonal_mm"]), abs=5e-4)


def test_every_public_default_sensor_is_the_clis():
    s = _cli_default_sensor()
    want = {"width": s.width_mm, "height": s.height_mm, "both": (s.width_mm, s.height_mm),
            "half_diagonal": math.hypot(s.width_mm, s.height_mm) / 2}
    found = _sensor_defaults()
    from physcam.usd.spec import CameraSpec  # (its numbers' defaults are CameraSpec.of's, issue 43)

    found += [("physcam.usd.spec.CameraSpec", p.name, p.default) for p in
              inspect.signature(CameraSpec.of).parameters.values() if p.name in SENSOR_PARAMS]
    names = {q for q, _, _ in found}
    # the analyses, the breathing table, the MTF chart, the characterization grid and the USD kit
    # (the ray analyses that take a camera read its sensor, else the default: test_a_camera_without_a_sensor...)
    for must in ("physcam.analysis.distortion.field.real_distortion",
                 "physcam.analysis.framing.breathing_real.real_breathing", "physcam.analysis.image_quality.mtf.mtf_chart",
                 "physcam.optics.focusing.breathing_table", "physcam.characterize.grid.Grid",
                 "physcam.usd.spec.CameraSpec", "physcam.usd.kit.write_vendor_lens"):
        assert must in names, f"{must} has no sensor default (or is no longer public)"
    wrong = []
    for qual, name, value in found:
        expected = want[SENSOR_PARAMS[name]]
        got = tuple(value) if isinstance(value, (tuple, list)) else value
        if got != pytest.approx(expected, abs=1e-12):
            wrong.append(f"{qual}({name}={value!r}): the CLI's default is {s.name} ({expected})")
    assert not wrong, "defaults that differ from the CLI's sensor:\n" + "\n".join(wrong)


@pytest.mark.parametrize("analysis", ["illumination.relative_illumination", "colour.chromatic_aberration",
                                      "ghosts.ghost_analysis"])
def test_a_camera_without_a_sensor_is_analysed_on_the_clis_sensor(analysis):
    """Issue 43: relative illumination, colour and ghosts take the camera and nothing else about it; a
    camera built without a sensor is analysed on the CLI's default sensor (its fields reach that sensor's
    corner), exactly as with that sensor given."""
    import importlib

    from physcam.lens.library import load_lens
    from physcam.optics.state import camera_state

    module, _, name = analysis.rpartition(".")
    fn = getattr(importlib.import_module(f"physcam.analysis.image_quality.{module}"), name)
    kw = {"relative_illumination": dict(n_fields=3, grid=16), "ghost_analysis": dict(rank_rays=200)}.get(name, {})
    lens = load_lens("dgauss_50mm")
    bare = _flat(fn(camera_state(lens), **kw).to_dict())
    given = _flat(fn(camera_state(lens, sensor=_cli_default_sensor()), **kw).to_dict())
    assert bare.keys() == given.keys()
    for key, value in bare.items():  # the tracer's backends (numpy, then numba once compiled) differ by 1e-15
        assert given[key] == (pytest.approx(value, rel=1e-9, abs=1e-12) if isinstance(value, float) else value), key


def _flat(doc, path=""):
    """A JSON-like document as {path: leaf}."""
    if isinstance(doc, dict):
        return {k: v for key, item in doc.items() for k, v in _flat(item, f"{path}.{key}").items()}
    if isinstance(doc, (list, tuple)):
        return {k: v for i, item in enumerate(doc) for k, v in _flat(item, f"{path}[{i}]").items()}
    return {path: doc}


def test_dataclass_defaults_are_the_clis_too():
    from physcam.characterize.grid import Grid
    from physcam.usd.author import CameraSpec

    s = _cli_default_sensor()
    spec = CameraSpec()
    assert (spec.sensor_width_mm, spec.sensor_height_mm) == (s.width_mm, s.height_mm)
    assert Grid(focus_mm=(1000.0,), fstops=(2.8,)).sensor_mm == (s.width_mm, s.height_mm)
    assert {f.name for f in dataclasses.fields(Grid)} >= {"sensor_mm"}


def test_the_docs_python_example_runs():
    """docs/cli.md's Python example of the default sensor (its ``>>>`` lines) gives what it shows."""
    import doctest

    res = doctest.testfile(str(Path(__file__).resolve().parents[1] / "docs" / "cli.md"), module_relative=False,
                           optionflags=doctest.ELLIPSIS)
    assert res.attempted >= 5 and res.failed == 0
