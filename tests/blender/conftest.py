"""Shared fixtures of the Blender tests: one extension zip per test session (building it solves
every bundled lens's focus table, the slowest step)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def extension_zip(tmp_path_factory):
    """``physcam export blender-extension`` of every bundled lens, built once per session."""
    from physcam.cli import main

    out = tmp_path_factory.mktemp("ext")
    assert main(["export", "blender-extension", "-o", str(out)]) == 0
    (zp,) = out.glob("physcam-*.zip")
    return zp
