"""The calibration sheet's text fits its panel (round 22).

A verdict with its reasons ("NOT good: the chart covered only 33 % of the frame (shoot it in the corners too);
3DE4 Radial - Standard, Degree 4 misses ... ; USD lensDistortion standard misses ...", 190 characters) ran off the
A4 page, and tight_layout, unable to make room for it, left the whole sheet unlaid with a UserWarning (a review
found it on 8 rendered charts). Lines are now cut at words to TEXT_CHARS; measured here, such a line in the
sheet's 7 pt monospace fits the two thirds of the page's width its panel has."""

from __future__ import annotations

from physcam.analysis.calibration.sheet import TEXT_CHARS, _wrapped

VERDICT = ("verdict: NOT good: the chart covered only 33 % of the frame (shoot it in the corners too); 3DE4 Radial - "
           "Standard, Degree 4 misses the measured field by up to 2.71 px; USD lensDistortion standard misses the "
           "measured field by up to 2 px")


def test_long_lines_are_cut_at_words_and_short_ones_kept():
    text = "pinhole focal length 28.7601 mm +- 0.0053 (1 sigma)\n" + VERDICT
    lines = _wrapped(text).split("\n")
    assert lines[0] == "pinhole focal length 28.7601 mm +- 0.0053 (1 sigma)"
    assert len(lines) >= 3 and all(len(line) <= TEXT_CHARS for line in lines)
    assert " ".join(w for line in lines[1:] for w in line.split()) == " ".join(VERDICT.split())


def test_a_full_line_fits_the_text_panel():
    from physcam.figures import figure_style, new_figure

    with figure_style():
        fig = new_figure(figsize=(11.69, 8.27))
        t = fig.text(0.0, 0.5, "M" * TEXT_CHARS, family="monospace", fontsize=7)
        width_in = t.get_window_extent(fig.canvas.get_renderer()).width / fig.dpi
    assert width_in < 2 / 3 * 11.69 - 0.3
