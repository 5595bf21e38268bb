"""physcam draws in its own style without changing the caller's matplotlib settings.

A pipeline TD who draws a physcam chart in a notebook keeps their own ``matplotlib.rcParams``:
each figure producer is called with distinctive settings in place (a 13 pt font, top spines on,
a two-colour cycle, a red background), and afterwards every rcParams key must be as it was. The
figure itself must still be physcam's: drawn under those settings it gives the same pixels as
drawn under matplotlib's defaults, both through :func:`physcam.figures.figure_bytes` and when the
caller saves the returned figure with matplotlib's own ``savefig``. The command line's figures
(tests/test_figures_style.py, every command that draws) are run under the same settings there.
"""

from __future__ import annotations

import io
import math

import matplotlib
import numpy as np
import pytest
from cycler import cycler
from matplotlib.image import imread

from physcam.figures import PALETTE, STYLE, figure_bytes, figure_style, styled

#: Caller settings, each distinct from STYLE and from matplotlib's default: none reaches physcam's figures.
SENTINEL = {
    "font.size": 13.0,
    "font.family": "serif",
    "font.sans-serif": ["DejaVu Sans Mono"],  # resolved when a figure is drawn, not when it is made
    "figure.dpi": 200.0,  # not in STYLE: physcam draws from matplotlib's defaults plus STYLE
    "axes.unicode_minus": False,
    "axes.titlesize": 15.0,
    "axes.labelsize": 14.0,
    "xtick.labelsize": 12.0,
    "ytick.labelsize": 12.0,
    "legend.fontsize": 11.0,
    "axes.spines.top": True,
    "axes.spines.right": True,
    "axes.grid": True,
    "grid.alpha": 0.9,
    "lines.linewidth": 3.0,
    "axes.prop_cycle": cycler(color=["#123456", "#654321"]),
    "figure.facecolor": "red",
    "savefig.facecolor": "red",
}


#: SENTINEL's settings that matplotlib reads only when a figure is drawn (the tick formatter's minus
#: sign): a figure physcam returns and the caller saves themselves takes them from the caller, so the
#: comparison of such a save sets them back to matplotlib's defaults.
READ_WHEN_DRAWN = {"axes.unicode_minus": True}


def changed_keys(before: dict, after: dict) -> list[str]:
    return sorted(k for k in before.keys() | after.keys() if before.get(k, "<absent>") != after.get(k, "<absent>"))


def pixels(data: bytes) -> np.ndarray:
    return imread(io.BytesIO(data), format="png")


def caller_png(fig) -> bytes:
    """``fig`` saved as a caller would, with matplotlib's own savefig (the caller's rcParams in force)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=60, facecolor="white")
    return buf.getvalue()


@pytest.fixture(scope="module")
def dgauss():
    from physcam.lens.library import load_lens

    return load_lens("dgauss_50mm")


def _dof_zone(lens):
    from physcam.onset.dof_plot import dof_zone_figure
    from physcam.onset.report import solve_lens_report
    from physcam.optics.sensors import find_sensor

    return dof_zone_figure(solve_lens_report(focal_length_mm=50.0, sensor=find_sensor("S35"), fstop=2.8,
                                             focus_mm=3000.0))


def _diagram(lens):
    from physcam.analysis.lens_cards.diagram import lens_diagram
    from physcam.optics.state import camera_state

    return lens_diagram(camera_state(lens, focus_mm=2000.0, fstop=4.0)).figure()


def _breathing(lens):
    from physcam.analysis.framing.breathing_plot import breathing_figure
    from physcam.optics.focusing import breathing_table

    return breathing_figure(breathing_table(lens, [math.inf, 2000.0, 1000.0], sensor_width_mm=36.0))


def _real_breathing(lens):
    from physcam.analysis.framing.breathing_real import real_breathing

    return real_breathing(lens, [math.inf, 2000.0, 1000.0], sensor_width_mm=36.0, sensor_height_mm=24.0).plot()


def _mtf_chart(lens):
    from physcam.analysis.image_quality.mtf import mtf_chart
    from physcam.optics.state import camera_state

    return mtf_chart(camera_state(lens, focus_mm=3000.0, fstop=8.0), n_fields=2, max_image_height_mm=5.0,
                     frequencies=(10.0,), wavelengths_nm=(587.5618,), pupil_samples=16).plot()


def _spot(lens):
    from physcam.analysis.image_quality.spot import spot_diagram

    return spot_diagram(lens, (0.0, 5.0), rings=8, refine=2).plot()


def _compare(lens):
    from physcam.cli.compare import compare_figure
    from physcam.optics.sensors import find_sensor

    rows = [{"name": "A", "fstop": 2.8, "focus_from_film_mm": 2000.0, "bokeh_light_from_film_mm": 4000.0,
             "bokeh_diameter_mm": 0.1}]
    curves = [{"breathing": ([math.inf, 2000.0, 1000.0], [0.0, -1.0, -2.0]), "distortion": ([0.0, 10.0], [0.0, -1.0]),
               "illumination": ([0.0, 10.0], [1.0, 0.8])}]
    return compare_figure(rows, curves, sensor=find_sensor("S35"))


def _lens_card(lens):
    from physcam.analysis.lens_cards.card import lens_card

    return lens_card(lens, quality="draft").figure(dpi=30)


#: Public functions that return a drawn physcam figure, each made small.
PRODUCERS = {"dof zone": _dof_zone, "lens diagram": _diagram, "breathing": _breathing,
             "real breathing": _real_breathing, "mtf chart": _mtf_chart, "spot": _spot, "compare": _compare,
             "lens card": _lens_card}


@pytest.mark.parametrize("make", list(PRODUCERS.values()), ids=list(PRODUCERS))
def test_a_figure_leaves_the_callers_rcparams_and_keeps_its_style(make, dgauss):
    with matplotlib.rc_context(SENTINEL):
        before = dict(matplotlib.rcParams)
        fig = make(dgauss)
        assert changed_keys(before, dict(matplotlib.rcParams)) == []
        with matplotlib.rc_context(READ_WHEN_DRAWN):  # the caller's own draw reads these: theirs by right
            theirs = caller_png(fig)  # drawn for the first time here, under the caller's settings
        ours = figure_bytes(fig, "png", dpi=60)
        assert changed_keys(before, dict(matplotlib.rcParams)) == []
    with matplotlib.rc_context():
        matplotlib.rcdefaults()
        reference = figure_bytes(make(dgauss), "png", dpi=60)
    assert np.array_equal(pixels(ours), pixels(reference))
    assert np.array_equal(pixels(theirs), pixels(reference))


def test_the_style_is_physcams_under_the_callers_settings():
    """Artists made inside :func:`figure_style` take STYLE and PALETTE, not the caller's settings."""
    from physcam.figures import new_figure

    with matplotlib.rc_context(SENTINEL):
        with figure_style():
            fig = new_figure(figsize=(3.0, 2.0))
            ax = fig.add_subplot(1, 1, 1)
            (line,) = ax.plot([0, 1], [0, 1])
            ax.set_title("t")
            ax.set_xlabel("x (mm)")
        assert matplotlib.rcParams["font.size"] == 13.0
    assert ax.title.get_fontsize() == STYLE["axes.titlesize"]
    assert ax.xaxis.label.get_fontsize() == STYLE["axes.labelsize"]
    assert not ax.spines["top"].get_visible() and not ax.spines["right"].get_visible()
    assert line.get_color() == PALETTE[0] and line.get_linewidth() == STYLE["lines.linewidth"]
    assert matplotlib.colors.to_hex(fig.get_facecolor()) == "#ffffff"


def test_styled_keeps_the_function_and_restores_on_error():
    def draw(x: int) -> int:
        """Doc."""
        raise ValueError(x)

    wrapped = styled(draw)
    assert wrapped.__doc__ == "Doc." and wrapped.__name__ == "draw" and wrapped.__wrapped__ is draw
    with matplotlib.rc_context(SENTINEL):
        before = dict(matplotlib.rcParams)
        with pytest.raises(ValueError):
            wrapped(1)
        assert changed_keys(before, dict(matplotlib.rcParams)) == []


def test_threads_drawing_at_once_leave_the_callers_rcparams(dgauss):
    """rcParams is one dict for every thread: physcam's drawings take turns, so none restores
    another's settings in the middle of its figure, and the caller's come back at the end."""
    import threading

    figs, errors = [], []

    def work():
        try:
            for _ in range(3):
                figs.append(_dof_zone(dgauss))
        except Exception as exc:  # pragma: no cover - reported below
            errors.append(exc)

    with matplotlib.rc_context(SENTINEL):
        before = dict(matplotlib.rcParams)
        threads = [threading.Thread(target=work) for _ in range(3)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert errors == [] and changed_keys(before, dict(matplotlib.rcParams)) == []
    assert len(figs) == 9
    assert {f.axes[0].xaxis.label.get_fontsize() for f in figs} == {STYLE["axes.labelsize"]}
    assert {matplotlib.colors.to_hex(f.get_facecolor()) for f in figs} == {"#ffffff"}


def test_physcams_reset_is_matplotlibs_rcdefaults():
    """figures._rcdefaults (issue 47: without the style library rcdefaults imports) sets every setting
    as matplotlib.rcdefaults() does, from caller settings that include those rcdefaults keeps."""
    from physcam import figures

    caller = {**SENTINEL, "interactive": True, "figure.max_open_warning": 7, "savefig.directory": "/tmp/x",
              "webagg.port": 9999, "toolbar": "None", "timezone": "Europe/Paris"}
    with matplotlib.rc_context(caller):
        figures._rcdefaults(matplotlib)
        ours = dict(matplotlib.rcParams)
    with matplotlib.rc_context(caller):
        matplotlib.rcdefaults()
        theirs = dict(matplotlib.rcParams)
    assert changed_keys(ours, theirs) == []
    assert ours["interactive"] is True and ours["figure.max_open_warning"] == 7  # kept, as rcdefaults keeps them
