"""``physcam mtf``: the vendor-style table and chart, one field's report, and bad input as one line."""

from __future__ import annotations

import json
import math

import pytest

from physcam.cli import main

pytestmark = pytest.mark.slow


def test_vendor_chart_table_text_chart_and_png(tmp_path, capsys):
    out = tmp_path / "chart.png"
    rc = main(["mtf", "dgauss_50mm", "--fstop", "4", "--focus", "3m", "--sensor", "FF", "-o", str(out)])
    text = capsys.readouterr().out
    assert rc == 0
    lines = text.splitlines()
    head = next(i for i, ln in enumerate(lines) if "height mm" in ln)
    assert lines[head].split() == ["height", "mm", "field", "deg", "10", "S", "10", "T", "20", "S", "20", "T", "40", "S",
                                   "40", "T"]
    rows = [ln.split() for ln in lines[head + 1:head + 16]]
    assert len(rows) == 15
    # 15 image heights from the centre to the full-frame corner, hypot(36, 24) / 2 = 21.63 mm
    assert float(rows[0][0]) == 0.0 and float(rows[-1][0]) == pytest.approx(math.hypot(36, 24) / 2, abs=0.01)
    # on axis sagittal and tangential are the same; contrast falls with frequency
    s10, t10, s20, t20, s40, t40 = (float(v) for v in rows[0][2:])
    assert s10 == t10 and s20 == t20 and s40 == t40 and 1 > s10 > s20 > s40 > 0
    assert "image height (mm)" in text and "upper case sagittal" in text  # the chart drawn in characters
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # no overwrite without --force
    assert main(["mtf", "dgauss_50mm", "--fstop", "4", "--focus", "3m", "-o", str(out)]) == 2


def test_chart_json_and_a_named_sensor(capsys):
    rc = main(["mtf", "dgauss_50mm", "--fstop", "8", "--sensor", "ALEXA 35", "--fields", "3", "--frequency", "20",
               "--wavelength", "550", "--json"])
    assert rc == 0
    d = json.loads(capsys.readouterr().out)
    assert d["frequencies_lpmm"] == [20.0] and d["wavelengths_nm"] == [550.0] and len(d["rows"]) == 3
    assert d["rows"][-1]["image_height_mm"] == pytest.approx(math.hypot(27.99, 19.22) / 2)
    assert d["focus_from_film_mm"] is None and d["fstop"] == 8.0
    assert all(0 <= r["sagittal"]["20"] <= 1 and 0 <= r["tangential"]["20"] <= 1 for r in d["rows"])


def test_one_field_report(capsys):
    assert main(["mtf", "dgauss_50mm", "--fstop", "8", "--field", "14", "--wavelength", "587.5618", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert set(d) == {"schema", "version", "units", "wavefront", "psf", "mtf", "points"} \
        and d["schema"] == "physcam.mtf_field"
    assert d["wavefront"]["field_deg"] == 14.0 and 0 < d["psf"]["strehl"] < 1
    assert d["wavefront"]["zernike_ordering"].startswith("Noll")
    assert main(["mtf", "dgauss_50mm", "--fstop", "8", "--field", "14"]) == 0
    text = capsys.readouterr().out
    assert "Strehl ratio" in text and "RMS" in text and "Zernike (Noll" in text


def _csv_rows(capsys, argv):
    import csv
    import io

    capsys.readouterr()
    assert main([*argv, "--csv"]) == 0
    return list(csv.DictReader(io.StringIO(capsys.readouterr().out)))


def test_csv_round_trips_to_the_json(capsys):
    """--csv prints one row per image height and frequency (one per frequency with --field); parsed back
    with the csv module, every cell is the JSON's number (repr: exact), and the rows are the JSON's rows."""
    chart = ["mtf", "dgauss_50mm", "--fstop", "8", "--fields", "3", "--pupil-samples", "32", "--frequency", "10",
             "--frequency", "30", "--wavelength", "587.5618"]
    table = _csv_rows(capsys, chart)
    assert main([*chart, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert len(table) == 3 * 2 and list(table[0]) == ["image_height_mm", "field_deg", "frequency_lpmm", "sagittal",
                                                       "tangential", "pupil_samples"]
    for row, (r, f) in zip(table, [(r, f) for r in d["rows"] for f in d["frequencies_lpmm"]]):
        assert float(row["image_height_mm"]) == r["image_height_mm"] and float(row["field_deg"]) == r["field_deg"]
        assert float(row["frequency_lpmm"]) == f and int(row["pupil_samples"]) == r["pupil_samples"]
        assert float(row["sagittal"]) == r["sagittal"][f"{f:g}"] and float(row["tangential"]) == r["tangential"][f"{f:g}"]
    field = ["mtf", "dgauss_50mm", "--fstop", "8", "--field", "14", "--pupil-samples", "32", "--wavelength", "587.5618"]
    table = _csv_rows(capsys, field)
    assert main([*field, "--json"]) == 0
    m = json.loads(capsys.readouterr().out)["mtf"]
    assert [float(r["frequency_lpmm"]) for r in table] == m["frequencies_lpmm"] == [10.0, 20.0, 40.0]
    assert [float(r["sagittal"]) for r in table] == m["sagittal"]
    assert [float(r["tangential"]) for r in table] == m["tangential"]
    assert [float(r["diffraction_limit_tangential"]) for r in table] == m["diffraction_limit_tangential"]
    assert all(float(r["field_deg"]) == 14.0 for r in table)


@pytest.mark.parametrize("argv", [
    ["--fields", "1"],
    ["--pupil-samples", "8"],
    ["--force"],
    ["--fstop", "1"],
    ["--field", "60"],
    ["--field", "5", "--fields", "3"],
    ["--wavelength", "550", "--weight", "1", "--weight", "2"],
    ["--max-height", "80"],
    ["--frequency", "0.01", "--pupil-samples", "16"],
])
def test_bad_input_is_one_line(argv, capsys):
    rc = main(["mtf", "dgauss_50mm", *argv])
    err = capsys.readouterr().err
    assert rc == 2 and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1 and err.startswith("physcam: error:")


def test_one_field_does_not_claim_a_defaulted_sensor(capsys):
    # one field's MTF does not use the sensor: no "no --sensor given" note (the chart, which takes
    # its corner from the sensor, and a hyperfocal focus, which takes its CoC, still say it)
    from physcam.cli import main

    assert main(["mtf", "dgauss_50mm", "--field", "5", "--fstop", "4", "--frequency", "20", "--json"]) == 0
    assert "no --sensor given" not in capsys.readouterr().err
    assert main(["mtf", "dgauss_50mm", "--field", "5", "--fstop", "4", "--frequency", "20", "--focus", "hyperfocal",
                 "--json"]) == 0
    assert "no --sensor given" in capsys.readouterr().err
