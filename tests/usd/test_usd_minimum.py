"""The oldest usd-core physcam supports is declared once and tested (issue 24 item 14): the ``usd``
extra's lower bound in pyproject.toml is the Makefile's USD_MIN, and ``make usd-min`` (run by
``make test``) runs tests/usd with exactly that wheel loaded. usd-core 24.8 to 25.5.1, once
declared as supported, crash in physcam (CreateExposureTimeAttr missing; validators not loadable)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _declared() -> str:
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    (spec,) = [d for d in extras["usd"] if d.startswith("usd-core")]
    m = re.fullmatch(r"usd-core>=([0-9][0-9.]*)", spec.replace(" ", ""))
    assert m, f"the usd extra names its minimum as usd-core>=X.Y, got {spec!r}"
    return m.group(1)


def _makefile_minimum() -> str:
    m = re.search(r"^USD_MIN\s*\?=\s*(\S+)\s*$", (ROOT / "Makefile").read_text(), flags=re.M)
    assert m, "the Makefile sets USD_MIN ?= X.Y (make usd-min)"
    return m.group(1)


def _version(text: str) -> tuple[int, int]:
    """usd-core's release as (year, month): 25.8 -> (25, 8), as pxr.Usd.GetVersion() gives (0, 25, 8)."""
    year, month = text.split(".")[:2]
    return int(year), int(month)


def test_pyproject_and_makefile_name_the_same_minimum():
    assert _declared() == _makefile_minimum()
    assert _version(_declared()) >= (25, 8)  # 25.5.1 and older crash (module notes)


def test_make_test_runs_the_minimum():
    text = (ROOT / "Makefile").read_text()
    test_recipe = re.search(r"^test:.*\n((?:\t.*\n)+)", text, flags=re.M).group(1)
    assert "usd-min" in test_recipe
    usd_min = re.search(r"^usd-min:.*\n((?:\t.*\n)+)", text, flags=re.M).group(1)
    assert "tests/usd" in usd_min and "--target" in usd_min and "PHYSCAM_USD_MIN=$(USD_MIN)" in usd_min


@pytest.mark.skipif("PHYSCAM_USD_MIN" not in os.environ, reason="checked in the make usd-min run")
def test_the_usd_min_run_loads_that_version():
    from pxr import Usd

    wanted = os.environ["PHYSCAM_USD_MIN"]
    assert wanted == _declared()
    assert tuple(Usd.GetVersion()[1:]) == _version(wanted), f"make usd-min loaded usd-core {Usd.GetVersion()}"
    import pxr

    assert Path(pxr.__file__).resolve().is_relative_to(Path(os.environ["PHYSCAM_USD_MIN_DIR"]).resolve())


def test_an_installed_minimum_is_the_one_loaded_first():
    """Where ``make usd-min`` has installed its wheel, that folder first on PYTHONPATH gives that release."""
    folder = ROOT / ".venv" / f"usd-min-{_makefile_minimum()}"
    if not (folder / ".installed").exists():
        pytest.skip(f"{folder} is installed by `make usd-min`")
    out = subprocess.run([sys.executable, "-c", "from pxr import Usd; print(*Usd.GetVersion()[1:])"],
                         env={**os.environ, "PYTHONPATH": str(folder)}, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert tuple(map(int, out.stdout.split())) == _version(_makefile_minimum())
