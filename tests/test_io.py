"""Atomic writes: no clobber without force, normal file modes, nothing left behind."""

import os
import stat

import pytest

from physcam import ExportError
from physcam.io import atomic_write


def test_new_file_gets_the_umask_mode_not_private(tmp_path):
    old = os.umask(0o022)
    try:
        p = atomic_write(tmp_path / "a.txt", "x")
    finally:
        os.umask(old)
    assert stat.S_IMODE(p.stat().st_mode) == 0o644


def test_force_keeps_the_replaced_files_mode(tmp_path):
    p = tmp_path / "a.txt"
    p.write_text("old")
    p.chmod(0o640)
    atomic_write(p, "new", force=True)
    assert p.read_text() == "new"
    assert stat.S_IMODE(p.stat().st_mode) == 0o640


def test_no_clobber_and_no_temporary_left(tmp_path):
    p = tmp_path / "a.txt"
    atomic_write(p, "one")
    with pytest.raises(ExportError, match="--force"):
        atomic_write(p, "two")
    assert p.read_text() == "one"
    assert sorted(f.name for f in tmp_path.iterdir()) == ["a.txt"]
