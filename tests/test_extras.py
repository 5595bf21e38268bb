"""physcam.extras names what pyproject.toml declares (issue 26): the missing-extra message must name an
install that really brings the package."""

import re
import tomllib
from pathlib import Path

import pytest

from physcam.errors import BackendError, InputError
from physcam.extras import EXTRAS, missing_modules

PYPROJECT = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())


def _name(requirement: str) -> str:
    return re.split(r"[<>=!~; ]", requirement, maxsplit=1)[0]


def test_every_extra_of_pyproject_is_in_the_table_with_its_packages():
    declared = PYPROJECT["project"]["optional-dependencies"]
    extras = {k: v for k, v in declared.items() if k not in ("all", "test")}
    assert set(extras) == set(EXTRAS)
    for extra, requirements in extras.items():
        assert sorted(_name(r) for r in requirements) == sorted(pkg for _, pkg in EXTRAS[extra]), extra
    assert set(re.search(r"\[(.*)\]", declared["all"][0]).group(1).split(",")) == set(EXTRAS)


def test_numba_is_not_a_core_dependency():
    assert not any(_name(r) in ("numba", "llvmlite") for r in PYPROJECT["project"]["dependencies"])


def test_missing_modules_answers_for_every_extra_and_refuses_an_unknown_one():
    for extra in EXTRAS:
        assert isinstance(missing_modules(extra), list)
    with pytest.raises(InputError, match="fast"):
        missing_modules("speed")


def test_the_numba_message_names_the_fast_extra_when_numba_is_missing(monkeypatch):
    # the message the core install gives (tests/test_installed.py runs it for real without numba)
    from physcam.trace import kernels

    monkeypatch.setattr(kernels, "_numba_kernel", None)
    monkeypatch.setattr(kernels, "_numba_error", "ModuleNotFoundError: No module named 'numba'")
    with pytest.raises(BackendError, match=r"pip install 'physcam\[fast\]'"):
        kernels.resolve_backend("numba")
