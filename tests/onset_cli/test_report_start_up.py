"""What `physcam report --lens` of a bundled lens loads (issue 43: a report at least 3x faster than
before the house was rebuilt; docs/performance.md, "The report of a prescription"). Each cut is
guarded here, in a fresh process: no other lens format's reader, no `physcam.cli.lens`, no camera
table for a gate's name, every dataclass on the path a `physcam._record.record` (shared methods, none
compiled per class), and no :mod:`dataclasses` (nor the :mod:`inspect` it imports)."""

import json
import subprocess
import sys

import pytest

CODE = """
import io, contextlib, json, sys
from physcam.cli import main
out = io.StringIO()
with contextlib.redirect_stdout(out):
    code = main(sys.argv[1:])
loaded = sorted(sys.modules)
import dataclasses, inspect
import physcam._record as record
from physcam.optics import sensors
classes = {c for m in list(sys.modules.values()) if getattr(m, "__name__", "").startswith("physcam")
           for c in vars(m).values() if inspect.isclass(c) and c.__module__ == m.__name__
           and dataclasses.is_dataclass(c)}
print(json.dumps({"code": code, "out": out.getvalue(), "modules": loaded,
                  "not_records": sorted(c.__qualname__ for c in classes if c.__eq__ is not record._eq),
                  "camera_table_read": sensors._index.cache_info().currsize > 0}))
"""


@pytest.mark.parametrize("args", [["--lens", "dgauss_50mm", "--fstop", "4", "--focus", "3m"],
                                  ["--lens", "zuiko_18mm_f3_5", "--fstop", "4", "--focus", "2m", "--json"]])
def test_a_bundled_lens_report_loads_only_what_it_uses(args):
    p = subprocess.run([sys.executable, "-W", "ignore", "-c", CODE, "report", *args], capture_output=True, text=True,
                       check=True)
    got = json.loads(p.stdout.strip().splitlines()[-1])
    assert got["code"] == 0 and ("focal length" in got["out"] or "\"focal_length_mm\"" in got["out"])
    readers = {"physcam.lens.formats." + m for m in ("zemax", "pbrt", "iset", "seedtoml")}
    assert not readers & set(got["modules"]), "a bundled TOML lens's report imports another format's reader"
    assert "physcam.lens.formats.physcam_toml" in got["modules"]  # the reader it does use (the check can fail)
    assert "physcam.cli.lens" not in got["modules"]
    assert not got["camera_table_read"], "the sensor name of a gate (Super 35) read the camera table"
    assert got["not_records"] == [], "dataclasses on the report's path built by dataclasses alone"
    # records need neither dataclasses nor what it imports (inspect, ast, dis, tokenize: 8 ms)
    assert not {"dataclasses", "inspect", "ast", "dis", "tokenize"} & set(got["modules"])
