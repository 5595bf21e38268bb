"""The report's diffraction figures worked by hand: the Airy disk 2.44 lambda N_w against the CoC and
the photosite pitch, and the f-stop past which it exceeds the CoC; the sensor table's pitches."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import pytest

from physcam.cli import main
from physcam.errors import InputError, SensorError
from physcam.lens.library import load_lens
from physcam.onset.report import REPORT_VERSION, solve_lens_report
from physcam.optics.sensors import custom_sensor, find_sensor, sensors

from _thin_lens import image_distance_at_mark

LAM = 550e-6  # mm


def test_thin_lens_airy_disk_against_coc_and_pitch():
    f, N, mark = 50.0, 8.0, 3000.0
    sensor = find_sensor("ALEXA 35")
    r = solve_lens_report(focal_length_mm=f, fstop=N, focus_mm=mark, sensor=sensor)
    s_img = image_distance_at_mark(f, mark)
    s_obj = mark - s_img
    m = f / (s_obj - f)  # = s' / s
    assert m == pytest.approx(s_img / s_obj)
    nw = N * (1 + m)
    airy = 2.44 * LAM * nw
    coc = math.hypot(27.99, 19.22) / 1500
    pitch = 27.99 / 4608
    d = r.to_dict()["diffraction"]
    assert d["working_f_number"] == pytest.approx(nw)
    assert d["airy_diameter_mm"] == pytest.approx(airy)  # 10.9 um
    assert d["airy_to_coc"] == pytest.approx(airy / coc)
    assert d["photosite_pitch_mm"] == pytest.approx(pitch, abs=1e-6)
    assert d["airy_in_photosites"] == pytest.approx(airy / pitch, rel=1e-4)
    assert d["fstop_airy_exceeds_coc"] == pytest.approx(coc / (2.44 * LAM * (1 + m)))  # f/16.6
    assert d["fstop_airy_exceeds_two_photosites"] == pytest.approx(2 * pitch / (2.44 * LAM * (1 + m)), rel=1e-4)
    assert d["exceeds_coc"] is False
    assert any(n.startswith("diffraction (550 nm): Airy disk 10.9 µm") and "past f/16.6" in n for n in r.notes)
    # past that f-stop it does
    past = solve_lens_report(focal_length_mm=f, fstop=17.0, focus_mm=mark, sensor=sensor)
    assert past.to_dict()["diffraction"]["exceeds_coc"] is True


def test_film_gate_has_no_pitch_and_json_keeps_version_one_keys():
    r = solve_lens_report(focal_length_mm=35.0, fstop=2.8, focus_mm=2000.0, sensor=find_sensor("S35"))
    d = r.to_dict()
    assert d["version"] == REPORT_VERSION == 3  # 2: diffraction; 3: signed magnification, infinite focus
    assert d["sensor"]["photosite_pitch_mm"] is None
    assert d["diffraction"]["airy_in_photosites"] is None and d["diffraction"]["fstop_airy_exceeds_two_photosites"] is None
    for key in ("schema", "units", "dof", "fov_deg", "pinhole", "notes", "entrance_pupil_from_film_mm"):
        assert key in d
    json.dumps(d, allow_nan=False)


def test_prescription_uses_its_own_working_fstop():
    # dgauss.50mm at 1 m: the paraxial working f-number of the lens, not N (1 + m) with equal pupils
    from physcam.optics.focusing import technical_planes

    lens = load_lens("dgauss_50mm")
    r = solve_lens_report(focal_length_mm=None, fstop=4.0, focus_mm=1000.0, sensor=find_sensor("FF"), lens=lens)
    planes = technical_planes(lens, 1000.0, fstop=4.0)
    d = r.to_dict()["diffraction"]
    assert d["working_f_number"] == pytest.approx(planes.working_f_number)
    assert d["airy_diameter_mm"] == pytest.approx(2.44 * LAM * planes.working_f_number)


def test_diffraction_wavelength_is_an_input():
    r = solve_lens_report(focal_length_mm=50.0, fstop=8.0, focus_mm=3000.0, sensor=find_sensor("FF"),
                          diffraction_wavelength_nm=650.0)
    assert r.to_dict()["diffraction"]["airy_diameter_mm"] == pytest.approx(2.44 * 650e-6 * r.working_f_number)
    with pytest.raises(InputError):
        solve_lens_report(focal_length_mm=50.0, fstop=8.0, focus_mm=3000.0, sensor=find_sensor("FF"),
                          diffraction_wavelength_nm=float("nan"))


def test_report_cli_json_carries_the_diffraction_block(capsys):
    assert main(["report", "--focal", "50", "--fstop", "11", "--focus", "3m", "--sensor", "VENICE 2", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["sensor"]["photosite_pitch_mm"] == pytest.approx(35.94 / 8640, abs=1e-6)
    assert d["diffraction"]["exceeds_coc"] is False and d["diffraction"]["airy_in_photosites"] > 3


def test_sensor_pitches_are_width_over_photosites():
    data = Path(__file__).resolve().parents[2] / "src" / "physcam" / "data"
    rows = {r["key"]: r for name in ("sensors.csv", "cameras.csv") for r in csv.DictReader((data / name).open())}
    with_pitch = 0
    for s in sensors():
        r = rows[s.key]
        if s.kind == "film":
            assert s.pitch_um is None and "film" in s.pitch_source
        if s.pitch_um is not None:
            with_pitch += not s.camera  # the sensors table's; the camera table's formats are counted apart
            assert s.pitch_um == pytest.approx(s.width_mm * 1000 / int(r["photosites_across"]), abs=6e-4)
            assert r["photosites_across"] in s.pitch_source  # the count and where it comes from
            assert 2.5 < s.pitch_um < 10.0  # cine and hybrid sensors: the LUMIX GH6's 2.995 um (17.3 mm / 5776) the finest
    assert with_pitch == 11
    assert find_sensor("ALEXA 35").pitch_um == pytest.approx(6.074)
    assert find_sensor("FF").pitch_um is None  # a format, not a camera


def test_custom_sensor_pitch():
    assert custom_sensor(36, 24, pitch_um=4.5).pitch_um == 4.5
    assert custom_sensor(36, 24).pitch_um is None
    with pytest.raises(SensorError):
        custom_sensor(36, 24, pitch_um=0.01)


def test_diffraction_formulas_answer_with_a_number_or_an_optics_error():
    """Issue 24 item 7 (review): a wavelength of 5e-324 nm raised ZeroDivisionError and huge inputs came
    back as inf. Hand values: 2.44 x 550e-6 mm x 8 = 0.010736 mm; 0.025 / (2.44 x 550e-6) = 18.629."""
    import pytest

    from physcam.errors import OpticsError
    from physcam.onset.report import airy_diameter_mm, fstop_airy_equals

    assert airy_diameter_mm(8.0, 550.0) == pytest.approx(0.010736, rel=1e-12)
    assert fstop_airy_equals(0.025, 550.0) == pytest.approx(0.025 / (2.44 * 550e-6), rel=1e-12)
    with pytest.raises(OpticsError):
        fstop_airy_equals(0.025, 5e-324)
    with pytest.raises(OpticsError):
        fstop_airy_equals(1e300, 1e-10)
    with pytest.raises(OpticsError):
        airy_diameter_mm(1e300, 1e300)
