"""An ARRI Meta Extract CSV saved with commas or semicolons is still ARRI (first-day walkthrough, round 9:
a comma-separated copy was told it "looks like a Sony VENICE per-frame CSV").

Oracle: the real tab-separated export in tests/data/camera-metadata/arri, converted here with Python's csv
module (no new file in the repository): the copy must be detected as ARRI and read into the same clip,
frame by frame, as the original.
"""

from __future__ import annotations

import csv
import dataclasses
from pathlib import Path

import pytest

from physcam.errors import MetadataError
from physcam.metadata import detect_file, load

ARRI = Path(__file__).resolve().parents[1] / "data" / "camera-metadata" / "arri" / "B001C001_180327_R1ZA.mov.csv"


def _copy(tmp_path, delimiter, rows=None):
    with open(ARRI, encoding="utf-8", newline="") as fh:
        table = list(csv.reader(fh, delimiter="\t"))
    table = table if rows is None else table[:rows]
    p = tmp_path / "clip.csv"
    with open(p, "w", encoding="utf-8", newline="") as fh:
        csv.writer(fh, delimiter=delimiter).writerows(table)
    return p, table


@pytest.mark.parametrize("delimiter", [",", ";"])
def test_a_copy_with_another_delimiter_is_the_same_clip(tmp_path, delimiter):
    p, _ = _copy(tmp_path, delimiter)
    assert detect_file(p) == ("arri", "frames")
    got, want = load(p), load(ARRI)
    assert len(got.frames) == 500
    assert dataclasses.replace(got, files=want.files) == want


def test_a_semicolon_copy_with_decimal_commas_is_the_same_clip(tmp_path):
    """A copy saved in a decimal-comma locale: semicolons between cells, "4,812" for 4.812 (the review of
    round 9: its first number was refused)."""
    import re

    with open(ARRI, encoding="utf-8", newline="") as fh:
        table = list(csv.reader(fh, delimiter="\t"))
    p = tmp_path / "clip.csv"
    with open(p, "w", encoding="utf-8", newline="") as fh:
        csv.writer(fh, delimiter=";").writerows(
            [table[0]] + [[re.sub(r"(\d)\.(\d)", r"\1,\2", c) for c in r] for r in table[1:]])
    assert "," in p.read_text(encoding="utf-8").splitlines()[1]  # the copy has decimal commas to read
    got, want = load(p), load(ARRI)
    assert dataclasses.replace(got, files=want.files) == want


@pytest.mark.parametrize("delimiter", [",", ";"])
def test_a_copy_without_its_timecode_is_named_arri(tmp_path, delimiter):
    """A header with ARRI's columns but no Master TC is said to be ARRI's, not another maker's."""
    _, table = _copy(tmp_path, delimiter, rows=3)
    keep = [i for i, c in enumerate(table[0]) if c != "Master TC"]
    p = tmp_path / "no_tc.csv"
    with open(p, "w", encoding="utf-8", newline="") as fh:
        csv.writer(fh, delimiter=delimiter).writerows([[r[i] for i in keep] for r in table])
    with pytest.raises(MetadataError, match="ARRI Meta Extract CSV but has no 'Master TC'"):
        detect_file(p)


#: the file whose opens the audit hook counts, then each open's mode; empty: the hook is idle
_OPENS: list = []
_HOOKED: list = []


def _count_opens(event, args):
    if event == "open" and _OPENS and str(args[0]) == _OPENS[0]:
        _OPENS.append(args[1])


@pytest.mark.parametrize("delimiter", ["\t", ";"])
def test_the_reader_opens_the_file_once_and_reads_its_header_once(tmp_path, delimiter):
    """Round 10: the reader opened the file twice, once for the first line to pick the delimiter and again for its
    rows (and each open twice, once more for the encoding). Python's audit hook sees every real open of the file
    (sys.addaudithook; a hook stays for the process, so it is added once and idles between tests)."""
    import sys

    from physcam.metadata import arri

    p, table = _copy(tmp_path, delimiter)
    if not _HOOKED:
        sys.addaudithook(_count_opens)
        _HOOKED.append(True)
    _OPENS[:] = [str(p)]
    try:
        clip = arri.read(p)
    finally:
        modes, _OPENS[:] = _OPENS[1:], []
    assert len(modes) == 1, modes  # one open: the header read once, for the delimiter and the columns
    assert len(clip.frames) == len(table) - 1 == 500


def test_a_file_the_reader_refuses_is_closed(tmp_path):
    # a blank first line: no delimiter gives AME's header, so the reader refuses it; the file it opened must
    # be closed then, not left to the garbage collector (a review's find: a ResourceWarning under -X dev)
    import gc
    import warnings

    from physcam.metadata import arri

    p = tmp_path / "clip.csv"
    p.write_text("\n" + ARRI.read_text(encoding="utf-8"), encoding="utf-8")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ResourceWarning)
        with pytest.raises(MetadataError):
            arri.read(p)
        gc.collect()
    assert not [w for w in caught if issubclass(w.category, ResourceWarning)]
