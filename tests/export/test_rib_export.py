"""`physcam export rib` (issue 13, part 1): every RIB physcam writes is read back by the tests' own
RIB reader (tests/export/_rib.py) and each number is checked against the lens report, worked
independently where it can be: the thin lens's image distance and field of view by hand
(tests/_thin_lens.py), the screen window from the sensor, the shutter curve by evaluating its
Bezier segments, the front anamorphic's dofaspect from its entrance pupils."""

from __future__ import annotations

import json
import math

import pytest

from _rib import RibError, params, parse, request, tokens
from _thin_lens import image_distance_at_mark
from physcam.cli import main

#: (label, argv after `export rib -o FILE`, what the test knows by hand)
CASES = {
    "spherical": (["--focal", "40", "--fstop", "2.8", "--focus", "2.5m", "--sensor", "ALEXA 35"],
                  dict(f=40.0, N=2.8, D=2500.0, w=27.99, h=19.22, sq=1.0)),
    "spherical_metres": (["--focal", "50", "--fstop", "2", "--focus", "3m", "--sensor-width", "36",
                          "--sensor-height", "24", "--meters-per-unit", "1", "--shutter-angle", "172.8",
                          "--blades", "9", "--blade-angle", "20", "--roundness", "0.3", "--density", "-0.4",
                          "--shutter-opening", "0.1,0.8"],
                         dict(f=50.0, N=2.0, D=3000.0, w=36.0, h=24.0, sq=1.0, mpu=1.0, angle=172.8,
                              aperture=(9, 20.0, 0.3, -0.4), opening=(0.1, 0.8))),
    "anamorphic": (["--focal", "75", "--fstop", "2.8", "--focus", "4m", "--sensor", "35mm anamorphic",
                    "--squeeze", "2", "--resolution", "2200"],
                   dict(f=75.0, N=2.8, D=4000.0, w=None, h=None, sq=2.0, xres=2200)),
    "shift": (["--focal", "24", "--fstop", "4", "--focus", "5m", "--sensor-width", "36", "--sensor-height", "24",
               "--shift-x=3", "--shift-y=-2", "--meters-per-unit", "0.0254"],
              dict(f=24.0, N=4.0, D=5000.0, w=36.0, h=24.0, sq=1.0, mpu=0.0254, shift=(3.0, -2.0))),
    "portrait": (["--focal", "35", "--fstop", "5.6", "--focus", "2m", "--sensor-width", "24", "--sensor-height", "36"],
                 dict(f=35.0, N=5.6, D=2000.0, w=24.0, h=36.0, sq=1.0)),
    "legacy": (["--focal", "50", "--fstop", "2", "--focus", "3m", "--sensor-width", "36", "--sensor-height", "24",
                "--legacy", "--blades", "6", "--shutter-opening", "0.25,0.75", "--shift-x=-1.5"],
               dict(f=50.0, N=2.0, D=3000.0, w=36.0, h=24.0, sq=1.0, legacy=True, aperture=(6, 0.0, 0.0, 0.0),
                    opening=(0.25, 0.75), shift=(-1.5, 0.0))),
    "legacy_anamorphic_rear": (["--lens", "navarro_anamorphic_2x", "--focus", "3m", "--sensor", "35mm anamorphic",
                                "--legacy"], dict(legacy=True)),
    "lens": (["--lens", "dgauss_50mm", "--fstop", "4", "--focus", "2m", "--sensor", "ALEXA 35",
              "--meters-per-unit", "1"], dict(mpu=1.0)),
    "lens_front_anamorphic": (["--lens", "neil_front_anamorphic_2x", "--focus", "3m", "--sensor", "35mm anamorphic"],
                              dict()),
}


def _write(tmp_path, capsys, label):
    argv, known = CASES[label]
    out = tmp_path / f"{label}.rib"
    rc = main(["export", "rib", "-o", str(out), *argv, "--json"])
    o, e = capsys.readouterr()
    assert rc == 0, e
    return out.read_text(), json.loads(o), known


def _report(label):
    """The lens report of a case, solved through the CLI's own argument path."""
    from physcam.cli import build_parser
    from physcam.cli.report import solve_from_args

    argv, _ = CASES[label]
    args = build_parser().parse_args(["export", "rib", "-o", "x.rib", *argv])
    return solve_from_args(args)


def _bezier(p0, p1, p2, p3, t):
    u = 1.0 - t
    return tuple(u ** 3 * a + 3 * u * u * t * b + 3 * u * t * t * c + t ** 3 * d for a, b, c, d in zip(p0, p1, p2, p3))


@pytest.mark.parametrize("label", list(CASES))
def test_every_rib_reads_back_and_agrees_with_the_report(tmp_path, capsys, label):
    text, js, known = _write(tmp_path, capsys, label)
    reqs = parse(text)
    report = _report(label)
    mpu = known.get("mpu", 0.01)
    mm = 1000.0 * mpu  # millimetres per scene unit
    legacy = known.get("legacy", False)
    sq = report.squeeze
    w, h = report.sensor.width_mm, report.sensor.height_mm
    if known.get("w"):
        assert (w, h) == (known["w"], known["h"])

    # Format: the squeezed plate's pixels, pixel aspect = squeeze (RI Spec: frame aspect = xres * pa / yres)
    xres, yres, pa = request(reqs, "Format")
    assert xres == known.get("xres", 2048) and yres == round(xres * h / w)
    assert pa == pytest.approx(report.pinhole[1], rel=1e-12)
    if "sq" in known:
        assert pa == known["sq"]

    # ScreenWindow: the shorter side spans -1..1 (RI Spec default), the longer +-aspect, moved by the shift
    l, r, b, t = request(reqs, "ScreenWindow")
    aspect = w * pa / h
    assert (r - l) / (t - b) == pytest.approx(aspect, rel=1e-12)
    assert min(r - l, t - b) == pytest.approx(2.0, rel=1e-12)
    unit_mm = min(w * pa, h) / 2.0  # film mm per screen-window unit
    sx, sy = known.get("shift", (0.0, 0.0))
    assert ((l + r) / 2, (b + t) / 2) == pytest.approx((sx * pa / unit_mm, sy / unit_mm), abs=1e-12)
    # the raster's aspect matches the window's to the whole-pixel rounding of yres
    assert xres * pa / yres == pytest.approx(aspect, rel=1.0 / yres)

    near, far = request(reqs, "Clipping")
    assert (near * mm, far * mm) == pytest.approx((100.0, 1.0e7), rel=1e-12)
    angle = known.get("angle", 180.0)
    assert request(reqs, "Shutter") == pytest.approx([0.0, angle / 360.0], abs=1e-15)

    proj = request(reqs, "Projection")
    if legacy:
        assert proj[0] == "perspective" and [n for n, _ in reqs].count("DepthOfField") == 1
        fov = params(proj[1:])["fov"]
        fstop, focal_len, focal_dist = request(reqs, "DepthOfField")
        hider = request(reqs, "Hider")
        assert hider[0] == "hidden"
        hp = params(hider[1:])
        aperture, opening = hp["aperture"], hp["shutteropening"]
        dofaspect = None
        assert "PxrCamera" not in text
    else:
        assert proj[0] == "PxrCamera" and "DepthOfField" not in [n for n, _ in reqs]
        p = params(proj[1:])
        fov, fstop, focal_len, focal_dist = p["fov"], p["fStop"], p["focalLength"], p["focalDistance"]
        aperture = [p["apertureNSides"], p["apertureAngle"], p["apertureRoundness"], p["apertureDensity"]]
        opening = [p["shutterOpenTime"], p["shutterCloseTime"]]
        dofaspect = p["dofaspect"]
        # the shutter curve: Bezier (0,0)-(c1,c2)-(d1,d2)-(open,1) and (close,1)-(e1,e2)-(f1,f2)-(1,0) are the
        # straight ramps of seed 002 (RenderMan "Shutter"): every point lies on the line
        c1, c2, d1, d2, e1, e2, f1, f2 = p["shutteropening"]
        o, c = opening
        for tt in (0.1, 0.37, 0.5, 0.9):
            x, y = _bezier((0, 0), (c1, c2), (d1, d2), (o, 1), tt)
            assert y == pytest.approx(tt, abs=1e-12) and x == pytest.approx(o * tt, abs=1e-12)
            x, y = _bezier((c, 1), (e1, e2), (f1, f2), (1, 0), tt)
            assert y == pytest.approx(1 - tt, abs=1e-12) and x == pytest.approx(c + (1 - c) * tt, abs=1e-12)

    assert aperture == pytest.approx(list(known.get("aperture", (7, 0.0, 0.0, 0.0))), abs=0)
    assert opening == pytest.approx(list(known.get("opening", (0.0, 1.0))), abs=0)

    # field of view: the shorter side at the best-match pinhole; for a thin lens that pinhole is s' from
    # the film, worked by hand; a prescription's comes from the report
    f_pin = report.pinhole[0]
    if "f" in known:
        f_pin_hand = image_distance_at_mark(known["f"], known["D"])
        assert f_pin == pytest.approx(f_pin_hand, rel=1e-12)
        f_pin = f_pin_hand
    assert fov == pytest.approx(math.degrees(2 * math.atan(unit_mm / f_pin)), abs=1e-10)
    tan_half = math.tan(math.radians(fov) / 2)
    assert math.degrees(2 * math.atan((r - l) / 2 * tan_half)) == pytest.approx(report.hfov_focus_deg, abs=1e-9)
    assert math.degrees(2 * math.atan((t - b) / 2 * tan_half)) == pytest.approx(report.vfov_focus_deg, abs=1e-9)

    # depth of field: focalLength in scene units, focalLength / fStop the entrance pupil at this focus (f / N
    # for a thin lens; an internal-focus lens's iris seen through its focused front, tests/export/test_iris_rule.py),
    # focalDistance from the entrance pupil (a thin lens's pupil is on the lens, s' in front of the film)
    assert focal_len * mm == pytest.approx(f_pin, rel=1e-12)
    assert focal_len * mm / fstop == pytest.approx(report.aperture_diameter_mm, rel=1e-12)
    if "f" in known:
        assert focal_len * mm / fstop == pytest.approx(known["f"] / known["N"], rel=1e-12)
        assert focal_dist * mm == pytest.approx(known["D"] - f_pin_hand, rel=1e-12)
    else:
        assert focal_dist * mm == pytest.approx(report.focus_from_film_mm - report.entrance_pupil_from_film_mm,
                                                rel=1e-12)
    if dofaspect is not None:
        if "f" in known:
            assert dofaspect == pytest.approx(1.0 / sq, rel=1e-12)  # a thin (front) anamorphic narrows X
        else:
            assert dofaspect == pytest.approx(report.dof_aspect, rel=1e-12)

    # --json says what it wrote, with the same numbers
    assert js["written"] == str(tmp_path / f"{label}.rib") and js["meters_per_unit"] == mpu
    assert js["rib"]["Projection"]["fov"] == fov and js["form"] == ("legacy" if legacy else "PxrCamera")


def test_front_anamorphic_dofaspect_is_its_entrance_pupils_aspect(tmp_path, capsys):
    """The front anamorphic's dofaspect, computed here from the paraxial engine in both meridians."""
    from physcam.lens.library import load_lens
    from physcam.optics.focusing import focus
    from physcam.optics.paraxial import gaussian

    text, _, _ = _write(tmp_path, capsys, "lens_front_anamorphic")
    p = params(request(parse(text), "Projection")[1:])
    st = focus(load_lens("neil_front_anamorphic_2x"), 3000.0)
    gx = gaussian(st.prescription, axis="x", object_z=st.object_z, film_z=st.film_z)
    gy = gaussian(st.prescription, axis="y", object_z=st.object_z, film_z=st.film_z)
    assert p["dofaspect"] == pytest.approx(gx.entrance_pupil_diameter / gy.entrance_pupil_diameter, rel=1e-9)
    assert p["dofaspect"] == pytest.approx(0.5, abs=0.01)


def test_legacy_refuses_an_oval_blur(tmp_path, capsys):
    argv = ["export", "rib", "-o", str(tmp_path / "x.rib"), "--focal", "40", "--fstop", "2.8", "--focus", "3m",
            "--sensor", "35mm anamorphic", "--squeeze", "2", "--legacy"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "legacy RIB" in err and "dofaspect" in err
    assert not (tmp_path / "x.rib").exists()


def test_no_clobber_without_force(tmp_path, capsys):
    out = tmp_path / "cam.rib"
    argv = ["export", "rib", "-o", str(out), "--focal", "50", "--fstop", "2", "--focus", "3m"]
    assert main(argv) == 0
    first = out.read_text()
    assert main(argv[:-1] + ["4m"]) == 2
    assert "already exists" in capsys.readouterr().err and out.read_text() == first
    assert main(argv[:-1] + ["4m", "--force"]) == 0 and out.read_text() != first


@pytest.mark.parametrize("extra, words", [
    (["--focal", "50", "--fstop", "2"], "--focus"),
    (["--focal", "50", "--fstop", "2", "--focus", "3m", "--resolution", "3"], "resolution"),
    (["--focal", "50", "--fstop", "2", "--focus", "3m", "--blades", "5.5"], "blades"),
    (["--focal", "50", "--fstop", "2", "--focus", "3m", "--shutter-opening", "0.8,0.2"], "shutter opening"),
])
def test_refusals_are_one_line(tmp_path, capsys, extra, words):
    assert main(["export", "rib", "-o", str(tmp_path / "x.rib"), *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("physcam: error:") and err.count("\n") == 1 and words in err


@pytest.mark.parametrize("bad", ['##RenderMan RIB\nFormat 1 2 [3', '##RenderMan RIB\nShutter 0 ]',
                                 '##RenderMan RIB\nShutter 0 nan', '##RenderMan RIB\nProjection "x', 'Format 1 2 3'])
def test_the_test_reader_refuses_broken_rib(bad):
    with pytest.raises(RibError):
        parse(bad)


def test_the_test_reader_on_the_rispec_example():
    # RI Spec 3.2's RIB binding examples, comments and all
    reqs = parse('##RenderMan RIB\n# a comment\nScreenWindow -1 1 -1 1\nProjection "perspective" "fov" [45]\n'
                 'DepthOfField 22 45 1200\n')
    assert reqs == [("ScreenWindow", [-1.0, 1.0, -1.0, 1.0]), ("Projection", ["perspective", "fov", [45.0]]),
                    ("DepthOfField", [22.0, 45.0, 1200.0])]
    assert [k for k, _ in tokens('Hider "hidden" [1 2]')] == ["word", "string", "open", "number", "number", "close"]
