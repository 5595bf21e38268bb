"""Feet on every plot that shows scene distances (issue 15): ``--units ft`` and the user config's
``units = "ft"`` reach the focus marks, light and object distances of every figure; image-side
millimetres (film coordinates, spot and bokeh sizes, lp/mm) stay metric.

Each figure is drawn for real (matplotlib, Agg) in metres and in feet; its tick labels and title
text in feet must equal the metric values converted. The feet and inches expected are worked here
independently of :mod:`physcam.units`: 1 ft = 304.8 mm and 1 in = 25.4 mm exactly (the
international yard and pound, 1959), to the nearest 1/8 inch below 10 ft and the nearest inch
beyond, as marks are written on a lens ring. Through the command line the figures are written as
SVG with their text kept as text (``svg.fonttype: none``), and the text is read back.
"""

from __future__ import annotations

import html
import math
import re
from fractions import Fraction

import matplotlib
import numpy as np
import pytest

from physcam.cli import main
from physcam.figures import figure_style
from physcam.lens.library import load_lens

MM_PER_INCH = Fraction(254, 10)
MM_PER_FOOT = Fraction(3048, 10)


def feet_inches(mm: float) -> str:
    """``mm`` as feet and inches: to 1/8 inch below 10 ft, whole inches beyond (worked with exact fractions)."""
    if math.isinf(mm):
        return "∞"
    step = 8 if Fraction(mm) < 10 * MM_PER_FOOT else 1
    n = round(Fraction(mm) / MM_PER_INCH * step)  # whole steps of 1/step inch
    inches, part = divmod(n, step)
    ft, inch = divmod(inches, 12)
    return f"{ft}' {inch}" + (f" {Fraction(part, step)}" if part else "") + '"'


def test_the_worked_conversions():
    # by hand: 2 m = 78.740 in -> 78 6/8 = 6' 6 3/4"; 1 m = 39.370 in -> 39 3/8; 3 m = 118.110 in -> 118 1/8;
    # 5 m = 196.85 in -> 197 in = 16' 5" (beyond 10 ft: whole inches)
    assert [feet_inches(v) for v in (2000.0, 1000.0, 3000.0, 5000.0, 304.8)] == \
        ['6\' 6 3/4"', '3\' 3 3/8"', '9\' 10 1/8"', '16\' 5"', '1\' 0"']


@pytest.fixture(scope="module")
def dgauss():
    return load_lens("dgauss_50mm")


def _xticks(fig, ax=None):
    fig.canvas.draw()
    ax = ax or fig.axes[0]
    return list(ax.get_xticks()), [t.get_text() for t in ax.get_xticklabels()]


def _metric_to_feet(labels):
    """Metric tick labels (metres, or ∞) converted to feet and inches."""
    return [feet_inches(math.inf if lab == "∞" else float(lab) * 1000.0) for lab in labels]


def test_breathing_real_focus_axis_in_feet(dgauss):
    from physcam.analysis.framing.breathing_real import real_breathing

    res = real_breathing(dgauss, [math.inf, 2000.0, 1000.0], sensor_width_mm=36.0, sensor_height_mm=24.0)
    xm, lm = _xticks(res.plot(units="m"))
    xf, lf = _xticks(res.plot(units="ft"))
    assert lm == ["1", "2", "∞"]
    assert lf == _metric_to_feet(lm) == ['3\' 3 3/8"', '6\' 6 3/4"', "∞"]
    assert xf[:2] == pytest.approx([1000.0 / 304.8, 2000.0 / 304.8], rel=1e-12)
    assert xm[:2] == pytest.approx([1.0, 2.0], rel=1e-12)
    assert "feet and inches" in res.plot(units="ft").axes[0].get_xlabel()


def test_distortion_across_focus_axis_in_feet(dgauss):
    from physcam.analysis.distortion.across_focus import distortion_across_focus

    tab = distortion_across_focus(dgauss, [1000.0, 2000.0, 5000.0, math.inf], sensor_width_mm=36.0,
                                  sensor_height_mm=24.0, width_px=64, height_px=43)
    _, lm = _xticks(tab.plot(units="m"))
    xf, lf = _xticks(tab.plot(units="ft"))
    assert lm == ["1", "2", "5"]
    assert lf == _metric_to_feet(lm) == ['3\' 3 3/8"', '6\' 6 3/4"', '16\' 5"']
    assert xf == pytest.approx([v / 304.8 for v in (1000.0, 2000.0, 5000.0)], rel=1e-12)
    assert tab.plot(units="ft").axes[0].get_xlabel() == "focus from the film plane (feet and inches)"


def test_mtf_chart_title_focus_in_feet(dgauss):
    from physcam.analysis.image_quality.mtf import mtf_chart
    from physcam.optics.state import camera_state

    chart = mtf_chart(camera_state(dgauss, focus_mm=3000.0, fstop=8.0), n_fields=2, max_image_height_mm=5.0,
                      frequencies=(10.0,), wavelengths_nm=(587.5618,), pupil_samples=16)
    tm = chart.plot(units="m").axes[0].get_title()
    tf = chart.plot(units="ft").axes[0].get_title()
    assert "focus 3.000 m," in tm
    assert f"focus {feet_inches(3000.0)}," in tf and tf.replace(feet_inches(3000.0), "3.000 m") == tm
    # image heights stay in mm
    assert chart.plot(units="ft").axes[0].get_xlabel() == "image height (mm from the centre)"


def test_distortion_fit_residual_title_in_feet(dgauss):
    from physcam.analysis.distortion.models import fit_brown_conrady, samples_from_field
    from physcam.analysis.distortion.stmap import distortion_field
    from physcam.optics.state import camera_state

    field = distortion_field(camera_state(dgauss, focus_mm=2000.0, sensor_mm=(36.0, 24.0)), width_px=64,
                             height_px=43, maps=False)
    fit = fit_brown_conrady(samples_from_field(field), "D-U")
    assert "at focus 2.000 m\n" in fit.plot_residual(units="m").axes[0].get_title()
    assert f"at focus {feet_inches(2000.0)}\n" in fit.plot_residual(units="ft").axes[0].get_title()


def test_dof_zone_marks_and_title_in_feet():
    from physcam.onset.dof_plot import dof_zone_figure
    from physcam.onset.report import solve_lens_report
    from physcam.optics.sensors import find_sensor

    r = solve_lens_report(focal_length_mm=50.0, sensor=find_sensor("S35"), fstop=2.8, focus_mm=3000.0)
    fm, ff = dof_zone_figure(r, units="m"), dof_zone_figure(r, units="ft")
    marks = {"near": r.dof.near_from_film_mm, "focus": r.focus_from_film_mm,
             "hyperfocal": r.dof.hyperfocal_from_film_mm, "far": r.dof.far_from_film_mm}

    def texts(fig):
        return {t.get_text().split(" ", 1)[0]: t.get_text().split(" ", 1)[1] for t in fig.axes[0].texts if " " in t.get_text()}

    tm, tf = texts(fm), texts(ff)
    for name, mm in marks.items():
        if name in tm:
            assert tm[name] == f"{mm / 1000:.3f} m"
            assert tf[name] == feet_inches(mm), name
    assert "near" in tf and "far" in tf
    assert f"focus {feet_inches(3000.0)}" in ff.axes[0].get_title()
    assert "(ft, log scale)" in ff.axes[0].get_xlabel()


def test_lens_diagram_title_in_feet(dgauss):
    from physcam.analysis.lens_cards.diagram import lens_diagram
    from physcam.optics.state import camera_state

    d = lens_diagram(camera_state(dgauss, focus_mm=2000.0, fstop=4.0))
    assert "focus 2.000 m," in d.figure(units="m").axes[0].get_title()
    assert f"focus {feet_inches(2000.0)}," in d.figure(units="ft").axes[0].get_title()


def test_lens_breathing_plot_in_feet(dgauss):
    from physcam.analysis.framing.breathing_plot import breathing_figure
    from physcam.optics.focusing import breathing_table

    rows = breathing_table(dgauss, [math.inf, 2000.0, 1000.0], sensor_width_mm=36.0)
    xm, lm = _xticks(breathing_figure(rows, units="m"))
    xf, lf = _xticks(breathing_figure(rows, units="ft"))
    assert lm == ["∞", "2", "1"] and lf == _metric_to_feet(lm)
    assert xf == pytest.approx([0.0, 304.8 / 2000.0, 304.8 / 1000.0], rel=1e-12)  # 1 / mark in 1/ft


def test_compare_figures_in_feet():
    from physcam.cli.compare import _figure, compare_figure
    from physcam.optics.sensors import find_sensor

    # physcam compare blender's figure (no Blender needed to draw it: two images and the distances)
    res = {"lens": "dgauss", "crop_mm": 2.0, "fstop": 2.8, "light_from_film_mm": 700.0, "focus_from_film_mm": 2000.0,
           "images": {"physcam": np.ones((8, 8)), "cycles": np.ones((8, 8))},
           "measured": {"equivalent_diameter_mm": {"physcam": 0.5, "cycles": 0.5}}}
    assert _figure(res, units="m")._suptitle.get_text() == "dgauss: light 700.0 mm, focus 2.000 m, f/2.8"
    assert _figure(res, units="ft")._suptitle.get_text() == \
        f"dgauss: light {feet_inches(700.0)}, focus {feet_inches(2000.0)}, f/2.8"
    # physcam compare LENS_A LENS_B: breathing against 1 / mark, the focus and light in the title
    rows = [{"name": "A", "fstop": 2.8, "focus_from_film_mm": 2000.0, "bokeh_light_from_film_mm": 4000.0,
             "bokeh_diameter_mm": 0.1}]
    curves = [{"breathing": ([math.inf, 2000.0, 1000.0], [0.0, -1.0, -2.0]), "distortion": ([0.0, 10.0], [0.0, -1.0]),
               "illumination": ([0.0, 10.0], [1.0, 0.8])}]
    fig = compare_figure(rows, curves, sensor=find_sensor("S35"), units="ft")
    ax_b = fig.axes[0]
    assert list(ax_b.lines[0].get_xdata()) == pytest.approx([0.0, 304.8 / 2000.0, 304.8 / 1000.0], rel=1e-12)
    title = fig._suptitle.get_text()
    assert title.startswith(f"focus {feet_inches(2000.0)} (A)") and f"light at {feet_inches(4000.0)}" in title


# ---- through the command line and the user config ------------------------------------------------
def _svg_text(path) -> str:
    """The text of an SVG written with svg.fonttype none (its <text> elements), unescaped."""
    return html.unescape(" ".join(re.findall(r"<text[^>]*>(.*?)</text>", path.read_text(encoding="utf-8"), re.S)))


PLOTS = [  # argv (-o FILE.svg added), what the figure must say in feet
    (["breathing-real", "dgauss_50mm", "--focus", "inf", "--focus", "2m", "--focus", "1m"],
     [feet_inches(2000.0), feet_inches(1000.0), "feet and inches"]),
    (["distortion", "dgauss_50mm", "--resolution", "64x43", "--across-focus", "1m,2m,5m,inf"],
     [feet_inches(1000.0), feet_inches(5000.0), "feet and inches"]),
    (["mtf", "dgauss_50mm", "--fstop", "8", "--focus", "3m", "--fields", "2", "--max-height", "5",
      "--pupil-samples", "16", "--frequency", "10", "--wavelength", "587.5618"], [f"focus {feet_inches(3000.0)}"]),
    (["lens", "diagram", "dgauss_50mm", "--focus", "2m"], [f"focus {feet_inches(2000.0)}"]),
    (["lens", "breathing", "dgauss_50mm", "--focus", "1m", "2m", "inf"], [feet_inches(1000.0), feet_inches(2000.0)]),
    (["bokeh", "dgauss_50mm", "--rays", "2000", "--pixels", "16", "--focus", "2m", "--light", "1m"],
     [f"light at {feet_inches(1000.0)}, focus {feet_inches(2000.0)}"]),
    (["dof-table", "--focal", "35", "--fstops", "2.8", "--focus", "2m"], [feet_inches(2000.0), "in feet"]),
]


def _run_plot(tmp_path, argv, extra=()):
    out = tmp_path / f"{argv[0]}-{len(list(tmp_path.iterdir()))}.svg"
    with figure_style(), matplotlib.rc_context({"svg.fonttype": "none"}):  # text kept as text
        assert main([*argv, "-o", str(out), *extra]) == 0
    return _svg_text(out)


@pytest.mark.slow
@pytest.mark.parametrize("argv, says", PLOTS, ids=[" ".join(a[:2]) for a, _ in PLOTS])
def test_units_ft_reaches_every_plot(tmp_path, capsys, argv, says):
    text = _run_plot(tmp_path, argv, ["--units", "ft"])
    for s in says:
        assert s in text, f"physcam {' '.join(argv)} --units ft: {s!r} not on the figure"
    metric = _run_plot(tmp_path, argv, ["--units", "m"])
    assert feet_inches(2000.0 if "2m" in argv else 3000.0) not in metric


@pytest.mark.slow
def test_report_plot_in_feet(tmp_path, capsys):
    out = tmp_path / "dof.svg"
    with figure_style(), matplotlib.rc_context({"svg.fonttype": "none"}):  # text kept as text
        assert main(["report", "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--units", "ft",
                     "--plot", str(out)]) == 0
    assert f"focus {feet_inches(3000.0)}" in _svg_text(out)


@pytest.mark.slow
def test_the_user_configs_units_reach_the_plots(tmp_path, capsys, monkeypatch):
    cfg = tmp_path / "config.toml"
    cfg.write_text('units = "ft"\n')
    monkeypatch.setenv("PHYSCAM_CONFIG", str(cfg))
    for argv, says in (PLOTS[0], PLOTS[1], PLOTS[3]):
        text = _run_plot(tmp_path, argv)
        assert all(s in text for s in says), argv


def test_the_phone_pages_figures_in_feet():
    """physcam serve draws the DOF chart and the lens diagram in feet when the page asks (units=ft)."""
    from physcam.cli.serve import cli_backend
    from physcam.serve import Limits, asgi_get, create_app

    app = create_app(cli_backend(), Limits(rate=1000.0, burst=1000))
    q = "focal=50&fstop=2.8&focus=3m&sensor=S35"
    status, _, body = asgi_get(app, f"/api/dof.svg?{q}&units=ft")
    assert status == 200 and f"focus {feet_inches(3000.0)}" in html.unescape(body.decode())
    status, _, body = asgi_get(app, f"/api/dof.svg?{q}")
    assert status == 200 and "focus 3.000 m" in html.unescape(body.decode())
    # (with units=ft a bare 2000 would be feet: physcam's one rule for a bare focus)
    status, _, body = asgi_get(app, "/api/lens/dgauss_50mm/diagram.svg?fstop=4&focus=2000mm&units=ft")
    assert status == 200 and f"focus {feet_inches(2000.0)}" in html.unescape(body.decode())
