"""``physcam compare``'s figure file is laid out at the dpi it is drawn at (issue 47, round 21).

The six-panel figure was laid out (``tight_layout``) at matplotlib's 100 dpi and drawn at physcam's 130
(``physcam.figures.SAVE_DPI``): two renderers, so every text's extent was measured twice (matplotlib
remembers text metrics per renderer). Made at 130 dpi, the layout and the drawing share one renderer:
-27 ms of a cold `physcam compare` (docs/performance.md). The layout is then measured at the size it is
drawn, so its margins move by a pixel or two (the PNG is not main's); what must hold, and is checked:
the file is exactly that figure, drawn in physcam's style (``figure_problems``: no text outside it, units
on every axis), and a Figure returned to a caller keeps matplotlib's dpi. Every number is the
measurements' (the command's --json bytes are main's: the round's notes)."""

import math

import numpy as np

from physcam.cli.compare import compare_figure
from physcam.figures import SAVE_DPI, figure_bytes, figure_problems
from physcam.optics.sensors import find_sensor

ROWS = [{"name": name, "fstop": 2.8, "focus_from_film_mm": 2000.0, "bokeh_light_from_film_mm": 4000.0,
         "bokeh_diameter_mm": d} for name, d in (("A", 0.1), ("B", 0.2))]


def _curves():
    y, x = np.mgrid[-1:1:32j, -1:1:32j]
    disk = (x * x + y * y < 0.8).astype(float)
    return [{"breathing": ([math.inf, 2000.0, 1000.0], [0.0, -1.0, -k]), "distortion": ([0.0, 10.0], [0.0, -k]),
             "illumination": ([0.0, 10.0], [1.0, 0.8]), "bokeh": (disk * k, (-0.2, 0.2, -0.2, 0.2))} for k in (1.0, 2.0)]


def test_the_file_is_the_figure_laid_out_at_the_dpi_it_is_saved_at(tmp_path):
    sensor = find_sensor("S35")
    path = compare_figure(ROWS, _curves(), tmp_path / "cmp.png", sensor=sensor)
    fig = compare_figure(ROWS, _curves(), sensor=sensor, dpi=SAVE_DPI)
    assert fig.dpi == SAVE_DPI
    assert figure_problems(fig) == []
    assert path.read_bytes() == figure_bytes(compare_figure(ROWS, _curves(), sensor=sensor, dpi=SAVE_DPI), "png")


def test_a_returned_figure_keeps_matplotlibs_dpi():
    assert compare_figure(ROWS, _curves(), sensor=find_sensor("S35")).dpi == 100.0
