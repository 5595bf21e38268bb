"""Every figure physcam makes keeps one style (issue 32 item 4): no text outside the figure (a cut-off
title or tick label) and a unit in every axis label with ticks (physcam.figures.figure_problems).

Each command that draws a figure is run once, small, with PHYSCAM_STRICT_FIGURES=1: then
physcam.figures checks every figure before it is written and raises on a problem (or on a figure
made outside physcam's style context). The checker itself is tested on figures made to break it.
Each run also starts from distinctive matplotlib settings of the caller's (a red background, a 13 pt
font: tests/test_figures_rcparams.py) and must leave every rcParams key as it found it, while the
figure it writes keeps physcam's white background.
"""

from __future__ import annotations

import matplotlib
import pytest
from matplotlib.image import imread
from test_figures_rcparams import SENTINEL, changed_keys

from physcam.cli import main
from physcam.figures import STRICT_ENV, figure_problems, figure_style, fit_title, new_figure

pytestmark = pytest.mark.slow

L = ["--lens", "dgauss_50mm"]
#: (name, argv) of every command that draws a figure, small enough to run in seconds.
FIGURE_RUNS = [
    ("report plot", ["report", "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--plot", "dof.png"]),
    ("report plot ft, lens", ["report", *L, "--fstop", "4", "--focus", "10ft", "--units", "ft", "--plot", "d.svg"]),
    ("dof-table card", ["dof-table", "--focal", "35", "--fstops", "2,4", "--focus", "1m,3m,inf", "-o", "c.png"]),
    ("lens diagram", ["lens", "diagram", *L, "-o", "diag.png"]),
    ("lens breathing", ["lens", "breathing", *L, "-o", "br.png"]),
    ("lens card", ["lens", "card", *L, "--draft", "--dpi", "30", "-o", "card.png"]),
    ("spot", ["spot", *L, "--rings", "6", "-o", "spot.png"]),
    ("bokeh", ["bokeh", *L, "--rays", "3000", "--pixels", "32", "--focus", "2m", "--light", "1m", "-o", "b.png"]),
    ("illumination", ["illumination", *L, "--grid", "16", "-o", "ill.png"]),
    ("colour", ["colour", *L, "--field", "0", "--field", "5", "-o", "col.png"]),
    ("breathing-real", ["breathing-real", *L, "--focus", "inf", "--focus", "2m", "-o", "brr.png"]),
    # the image from 3000 rays a path on 32 px (default 200000 on 256: 6.7 -> 2.1 s of CPU): the figure's text (title,
    # film axes in mm, the colour bar's log10 ticks and label, the sensor) is the same whatever the rays
    ("ghosts", ["ghosts", *L, "--top", "3", "--rays", "3000", "--pixels", "32", "-o", "gh.png"]),
    ("distortion", ["distortion", *L, "-o", "dist.png"]),
    ("mtf chart", ["mtf", *L, "--fstop", "4", "--fields", "3", "--pupil-samples", "32", "-o", "mtf.png"]),
    ("mtf field", ["mtf", *L, "--fstop", "8", "--field", "10", "--pupil-samples", "32", "-o", "mtff.png"]),
    ("psf", ["psf", *L, "--fstop", "8", "-o", "psf.png"]),
    ("psf huygens", ["psf", *L, "--fstop", "8", "--field", "5", "--method", "huygens", "--samples", "33",
                     "-o", "psfh.png"]),
    ("compare lenses", ["compare", "dgauss_50mm", "tessar_50mm_f2_8", "--rays", "2000", "-o", "cmp.png"]),
    ("distortion across focus", ["distortion", *L, "--resolution", "512x342", "--across-focus", "1m,inf",
                                 "-o", "daf.png"]),
    ("distortion fit residual", ["distortion", *L, "--resolution", "256x171", "--stmap", "st", "--fit", "brown"]),
]


def _draws_in_style(argv, folder, monkeypatch, capsys):
    """Run ``physcam argv`` in ``folder`` under the caller's SENTINEL settings with the strict style
    check: it succeeds, leaves the settings as they were, and its PNG figures have physcam's white."""
    monkeypatch.setenv(STRICT_ENV, "1")
    with matplotlib.rc_context(SENTINEL):
        before = dict(matplotlib.rcParams)
        rc = main(argv)
        assert changed_keys(before, dict(matplotlib.rcParams)) == []
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "figure style" not in err
    named = [argv[i + 1] for i, a in enumerate(argv) if a in ("-o", "--plot")]
    pngs = [folder / n for n in named if n.endswith(".png")] + list(folder.rglob("residual_*.png"))
    for png in pngs:  # the figures (not the ST maps beside the residual plots)
        assert imread(png)[0, 0, :3].tolist() == [1.0, 1.0, 1.0], png.name  # physcam's white, not the caller's red


@pytest.mark.parametrize("argv", [a for _, a in FIGURE_RUNS], ids=[n for n, _ in FIGURE_RUNS])
def test_every_figure_keeps_the_style(argv, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    _draws_in_style(argv, tmp_path, monkeypatch, capsys)


def test_the_light_field_figure_keeps_the_style(tmp_path, monkeypatch, capsys):
    """``microlens render``'s figure of images (its axes shown off): the checker counted the hidden
    tick labels of those axes as text outside the figure, so the figure failed the strict run."""
    monkeypatch.chdir(tmp_path)
    assert main(["microlens", "insert", *L, "--microlens-focal", "0.224", "--xdim", "77", "--ydim", "77",
                 "--film-width", "3.08", "--film-height", "3.08", "--focus", "0.8m", "-o", "lf.json"]) == 0
    _draws_in_style(["microlens", "render", "--lens", "lf.json", "--fstop", "5.6", "--point", "0.5m", "--point", "5m",
                     "-o", "lf.png"], tmp_path, monkeypatch, capsys)


def test_the_checker_sees_a_cut_off_title_and_a_label_without_unit():
    fig = new_figure(figsize=(3.0, 2.0))
    ax = fig.add_subplot(1, 1, 1)
    ax.plot([0, 1], [0, 1])
    ax.set_title("a title far too long for a figure three inches wide, running off both of its edges")
    ax.set_xlabel("distance")
    ax.set_ylabel("height (mm)")
    fig.tight_layout()
    problems = figure_problems(fig)
    assert any("reaches outside the figure" in p for p in problems)
    assert any("'distance' names no unit" in p for p in problems)
    assert not any("height" in p for p in problems)


@pytest.mark.parametrize("fmt", ["png", "svg", "pdf"])
def test_the_strict_check_is_made_on_the_draw_that_saves(fmt, tmp_path, monkeypatch):
    """With PHYSCAM_STRICT_FIGURES=1 a saved figure is checked on the draw that writes it (one draw per save;
    the check drew it once more before), and one that breaks the style is refused with nothing written."""
    from matplotlib.figure import Figure

    from physcam.errors import ExportError
    from physcam.figures import save_figure

    monkeypatch.setenv(STRICT_ENV, "1")
    draws = []
    draw = Figure.draw
    monkeypatch.setattr(Figure, "draw", lambda self, renderer: (draws.append(1), draw(self, renderer))[1])

    def figure(title):
        with figure_style():
            fig = new_figure(figsize=(3.0, 2.0))
            ax = fig.add_subplot(1, 1, 1)
            ax.plot([0, 1], [0, 1])
            ax.set_title(title)
            ax.set_xlabel("x (mm)")
            ax.set_ylabel("y (mm)")
            fig.tight_layout()
        return fig

    assert save_figure(figure("fits"), tmp_path / f"ok.{fmt}", dpi=50).stat().st_size > 0
    assert len(draws) == 1
    with pytest.raises(ExportError, match="reaches outside the figure"):
        save_figure(figure("a title far too long for a figure three inches wide, running off both of its edges"),
                    tmp_path / f"bad.{fmt}", dpi=50)
    assert not (tmp_path / f"bad.{fmt}").exists()


def test_fit_title_wraps_to_the_width():
    text = "Double Gauss 50mm f/2  f/2.8  focus 3.000 m  CoC 0.02264 mm (d/1500)  ARRI ALEXA 35 4.6K 3:2 Open Gate"
    with figure_style():  # the title's size is the style's (fit_title measures in it)
        fig = new_figure(figsize=(4.0, 3.0))
        ax = fig.add_subplot(1, 1, 1)
        ax.set_title(fit_title(text, 3.2))
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        fig.tight_layout()
        assert figure_problems(fig) == []
    assert fit_title(text, 3.2).replace("\n", " ") == text  # only wrapped, never cut


def test_fit_title_never_breaks_a_label_from_its_value():
    """A value in feet and inches has spaces (6' 6 3/4"): wrapped at any width, "focus" and the value
    stay on one line (the phone's lens diagram split them once its lens name grew)."""
    from physcam.figures import unbroken

    value = "focus 6' 6 3/4\""
    text = f"Double Gauss 50mm f/2 (pbrt dgauss.50mm): EFL 50.36 mm, f/4, {unbroken(value)}, half-field 16.0°"
    for width in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 6.0):
        lines = fit_title(text, width).split("\n")
        assert value in lines[[i for i, ln in enumerate(lines) if "focus" in ln][0]], (width, lines)
        assert "\u00a0" not in "".join(lines)
