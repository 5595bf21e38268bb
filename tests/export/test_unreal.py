"""The Unreal lens file (.ulens exchange JSON): every field Unreal's importer reads, breathing against the
breathing table's independent formula, nodal offsets against technical_planes, and a file round trip."""

from __future__ import annotations

import json
import math

import pytest

from physcam.errors import ExportError, InputError
from physcam.export.unreal import INFINITY_FOCUS_CM, read_unreal_lens_file, unreal_lens_file, write_unreal_lens_file
from physcam.lens.library import load_lens
from physcam.optics.focusing import breathing_table, technical_planes

W_MM, H_MM, W_PX, H_PX = 36.0, 24.0, 4096, 2731

# The exchange structs of Unreal's Camera Calibration editor (FLensFileExchange and its members), field
# names as FJsonObjectConverter writes them (first letter lower case); type per field.
SCHEMA = {
    "metadata": {"type": str, "version": str, "lensInfo": dict, "name": str, "nodalOffsetCoordinateSystem": str,
                 "fxFyUnits": str, "cxCyUnits": str, "userMetadata": list},
    "sensorDimensions": {"width": float, "height": float, "units": str},
    "imageDimensions": {"width": int, "height": int},
}
TABLE_HEADERS = {
    "FocalLengthTable": ["FocusEncoder", "ZoomEncoder", "Fx", "Fy"],
    "ImageCenterTable": ["FocusEncoder", "ZoomEncoder", "Cx", "Cy"],
    "DistortionTable": ["FocusEncoder", "ZoomEncoder", "K1", "K2", "K3", "P1", "P2"],
    "NodalOffsetTable": ["FocusEncoder", "ZoomEncoder", "Qx", "Qy", "Qz", "Qw", "Tx", "Ty", "Tz"],
}


def _unreal_parse(table):
    """What Unreal's FLensFileParameterTableImporter does: header split on ',' (whitespace trimmed),
    data rows split on ';', values on ',' and parsed as floats."""
    header = [t.strip() for t in table["header"].split(",") if t.strip()]
    rows = [[float(t) for t in r.split(",") if t.strip()] for r in table["data"].split(";") if r.strip()]
    return header, rows


@pytest.fixture(scope="module", params=["dgauss_50mm", "zuiko_18mm_f3_5"])
def lens_file(request):
    lens = load_lens(request.param)
    return lens, unreal_lens_file(lens, W_MM, H_MM, image_width_px=W_PX, image_height_px=H_PX)


def test_every_documented_field_is_there_with_its_type(lens_file):
    lens, d = lens_file
    for block, fields in SCHEMA.items():
        for name, typ in fields.items():
            assert isinstance(d[block][name], typ), (block, name)
    m = d["metadata"]
    assert (m["type"], m["version"]) == ("LensFile", "0.0.0")
    assert m["lensInfo"] == {"serialNumber": "", "modelName": lens.name, "distortionModel": "Spherical"}
    assert (m["nodalOffsetCoordinateSystem"], m["fxFyUnits"], m["cxCyUnits"]) == ("OpenCV", "Normalized", "Normalized")
    assert all(set(e) == {"name", "value"} and isinstance(e["value"], str) for e in m["userMetadata"])
    assert d["sensorDimensions"] == {"width": 36.0, "height": 24.0, "units": "Millimeters"}
    assert d["imageDimensions"] == {"width": 4096, "height": 2731}
    tables = {t["parameterName"]: t for t in d["cameraParameterTables"]}
    assert set(tables) == set(TABLE_HEADERS)
    n = None
    for name, table in tables.items():
        assert set(table) == {"parameterName", "header", "data"}
        assert isinstance(table["header"], str) and isinstance(table["data"], str)
        assert "e" not in table["data"].lower()  # plain decimals
        header, rows = _unreal_parse(table)
        assert header == TABLE_HEADERS[name]
        assert all(len(r) == len(header) for r in rows)
        n = len(rows) if n is None else n
        assert len(rows) == n
    (enc,) = d["encoderTables"]
    assert enc["parameterName"] == "Focus" and _unreal_parse(enc)[0] == ["FocusEncoder", "FocusCM"]
    assert all(a == b for a, b in _unreal_parse(enc)[1])
    json.dumps(d, allow_nan=False)


def test_breathing_normalised_focal_length_matches_the_breathing_table(lens_file):
    lens, d = lens_file
    rows = breathing_table(lens, sensor_width_mm=W_MM)  # the default marks, infinity to the closest focus
    tables = {t["parameterName"]: _unreal_parse(t)[1] for t in d["cameraParameterTables"]}
    fl = tables["FocalLengthTable"]
    assert len(fl) == len(rows)
    for r, row in zip(rows, fl):
        m = r.focus_from_film_mm
        assert row[0] == pytest.approx(INFINITY_FOCUS_CM if math.isinf(m) else m / 10.0, abs=1e-9)
        # Fx = f_pin / sensor width; f_pin = (w/2) / tan(paraxial half field) of the breathing table
        assert row[2] == pytest.approx(r.breathing_focal_length_mm / W_MM, abs=1e-10)
        assert row[3] == pytest.approx(r.breathing_focal_length_mm / H_MM, abs=1e-10)  # spherical: f_pin_y = f_pin_x
    assert fl[-1][2] > fl[0][2]  # focusing closer frames tighter (both lenses breathe in)
    assert all(r[2:] == [0.5, 0.5] for r in tables["ImageCenterTable"])
    assert all(r[5:] == [0.0, 0.0] for r in tables["DistortionTable"])


def test_nodal_offset_is_the_entrance_pupil_in_front_of_the_film(lens_file):
    lens, d = lens_file
    tables = {t["parameterName"]: _unreal_parse(t)[1] for t in d["cameraParameterTables"]}
    marks = [r.focus_from_film_mm for r in breathing_table(lens, sensor_width_mm=W_MM)]
    for m, row in zip(marks, tables["NodalOffsetTable"]):
        assert row[2:6] == [0.0, 0.0, 0.0, 1.0]  # identity quaternion (x, y, z, w)
        assert row[6:8] == [0.0, 0.0]
        # OpenCV axes: +z forward toward the scene; Unreal units are cm
        assert row[8] == pytest.approx(technical_planes(lens, m).entrance_pupil_from_film_mm / 10.0, abs=1e-10)


def test_distortion_at_infinity_is_the_opencv_fit():
    from physcam.export.opencv_distortion import fit_opencv_pinhole

    lens = load_lens("dgauss_50mm")
    d = unreal_lens_file(lens, W_MM, H_MM, image_width_px=W_PX, image_height_px=H_PX, focus_marks_mm=[2000.0, math.inf])
    rows = {t["parameterName"]: _unreal_parse(t)[1] for t in d["cameraParameterTables"]}["DistortionTable"]
    assert [r[0] for r in rows] == [INFINITY_FOCUS_CM, 200.0]  # infinity first, then nearer
    cam = fit_opencv_pinhole(lens, W_MM, H_MM, W_PX, H_PX)
    assert rows[0][2:5] == pytest.approx([cam.k1, cam.k2, cam.k3], abs=1e-11)
    assert d["physcam"]["marks"][0]["focus_from_film_mm"] is None


def test_write_read_round_trip_and_no_clobber(tmp_path):
    lens = load_lens("dgauss_50mm")
    path = tmp_path / "dgauss.ulens"
    data = write_unreal_lens_file(path, lens, W_MM, H_MM, image_width_px=2048, image_height_px=1366,
                                  focus_marks_mm=[math.inf, 3000.0])
    back = read_unreal_lens_file(path)
    assert back["_json"] == json.loads(json.dumps(data))
    for t in data["cameraParameterTables"]:
        assert back[t["parameterName"]] == _unreal_parse(t)
    with pytest.raises(ExportError):
        write_unreal_lens_file(path, lens, W_MM, H_MM, image_width_px=2048, image_height_px=1366)
    write_unreal_lens_file(path, lens, W_MM, H_MM, image_width_px=2048, image_height_px=1366,
                           focus_marks_mm=[math.inf], force=True)
    assert len(read_unreal_lens_file(path)["FocalLengthTable"][1]) == 1


@pytest.mark.parametrize("marks", [[], [0.0], [-5.0], [float("nan")]])
def test_bad_marks(marks):
    with pytest.raises(InputError):
        unreal_lens_file(load_lens("dgauss_50mm"), W_MM, H_MM, image_width_px=W_PX, image_height_px=H_PX,
                         focus_marks_mm=marks)
