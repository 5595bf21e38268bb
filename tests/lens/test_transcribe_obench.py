"""scripts/transcribe_obench.py: an OpticalBench transcription read into a physcam lens draft.

The sample is made for this test (a cemented doublet, a stop, a singlet with an asphere, a cover
glass and one focus gap), in the layout of Bill Claff's files: tab-separated, padded rows, ``AS``
and ``CG`` rows, a distance name in the thickness column.
"""

import importlib.util
from pathlib import Path

import pytest

from physcam.lens.formats import loads_lens

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "transcribe_obench.py"
SAMPLE = "\n".join([
    "[descriptive data]", "title\tA test lens", "[constants]", "[variable distances]",
    "Focal Length\t50\tundefined\t\t", "F-Number\t4\tundefined", "d0\tInfinity\t500\t\t", "d5\t2.0\t6.5\t\t",
    "Bf\t40\t40",
    "[lens data]",
    "1\t30.0\t5.0\t1.51680\t20.0\t64.17",
    "2\t-25.0\t2.0\t1.80518\t20.0\t25.43",
    "3\t-90.0\t3.0\t\t20.0\t",
    "3AS\tAS\t3.0\t\t12.0",
    "4\t60.0\t3.0\t1.60000\t16.0\t50.00",
    "5\t-60.0\td5\t\t16.0",
    "6\tCG\t2.0\t1.51680\t30.0\t64.17",
    "7\tCG\t1.0\t\t30.0",
    "[aspherical data]",
    "4\t60.0\t-0.5\t1.0E-06\t-2.0E-09\t\t",
    "",
])


@pytest.fixture(scope="module")
def transcribe():
    spec = importlib.util.spec_from_file_location("transcribe_obench", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_a_transcription_becomes_a_lens(transcribe, tmp_path):
    path = tmp_path / "lens.txt"
    path.write_text(SAMPLE, encoding="utf-8")
    p = loads_lens(transcribe.draft(path, "Test", None), "physcam")
    p.validate()
    assert [s.kind for s in p.surfaces] == ["spherical", "spherical", "spherical", "stop", "aspheric", "spherical",
                                           "flat", "flat"]
    assert [s.thickness for s in p.surfaces] == [5.0, 2.0, 3.0, 3.0, 3.0, 2.0, 2.0, 1.0]
    assert [s.semi_diameter for s in p.surfaces] == [10.0, 10.0, 10.0, 6.0, 8.0, 8.0, 15.0, 15.0]
    asph = p.surfaces[4]
    assert asph.conic == -0.5 and tuple(asph.aspheric) == (1.0e-06, -2.0e-09)
    # 1.51680/64.17 is one glass type (517642, N-BK7 and its equivalents); 1.60000/50.00 is none
    assert (p.surfaces[0].medium.glass, p.surfaces[0].medium.catalog) == ("N-BK7", "SCHOTT")
    assert p.surfaces[4].medium.glass is None and p.surfaces[4].medium.nd == 1.6
    # d5 is the gap after the sixth row (0-based surface 5); the padded close column is 500 mm / 6.5 mm
    assert p.focus.close_distance == 500.0
    assert [(g.surface, g.thickness_infinity, g.thickness_close) for g in p.focus.gaps] == [(5, 2.0, 6.5)]


def test_odd_aspheres_are_refused(transcribe, tmp_path):
    path = tmp_path / "odd.txt"
    path.write_text(SAMPLE.replace("[constants]", "[constants]\nAsphericalOddCount\t1"), encoding="utf-8")
    with pytest.raises(SystemExit, match="not an even asphere"):
        transcribe.draft(path, "Test", None)
