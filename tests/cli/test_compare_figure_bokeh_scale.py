"""``physcam compare``'s bokeh panels are drawn at one film scale (round 22).

Each lens's bokeh image has its own extent (the image is fitted to its own blur: about ±0.15 to ±0.18 mm for
the three 50 mm lenses of docs/cli.md at f/2.8), so drawn at their own extents every disc filled its panel and a
bokeh 20 % wider looked the same size. The panels now share the widest image's scale, about the axis. Checked
on hand-made images with known extents (±0.2 mm and ±0.4 mm: both panels must then span ±0.4 mm, each image
keeping its own extent), with a lens without a bokeh between them (its panel stays empty and shares nothing)."""

import math

import numpy as np

from physcam.cli.compare import compare_figure
from physcam.figures import figure_problems
from physcam.optics.sensors import find_sensor


def _rows_and_curves():
    y, x = np.mgrid[-1:1:32j, -1:1:32j]
    disk = (x * x + y * y < 0.8).astype(float)
    rows, curves = [], []
    for name, half in (("A", 0.2), ("B", None), ("C", 0.4)):
        rows.append({"name": name, "fstop": 2.8, "focus_from_film_mm": 2000.0, "bokeh_light_from_film_mm": 4000.0,
                     "bokeh_diameter_mm": None if half is None else 1.5 * half})
        c = {"breathing": ([math.inf, 1000.0], [0.0, -2.0]), "distortion": ([0.0, 10.0], [0.0, 1.0]),
             "illumination": ([0.0, 10.0], [1.0, 0.8])}
        if half is not None:
            c["bokeh"] = (disk, (-half, half, -half, half))
        curves.append(c)
    return rows, curves


def test_every_bokeh_panel_spans_the_widest_image():
    fig = compare_figure(*_rows_and_curves(), sensor=find_sensor("S35"))
    with_images = [ax for ax in fig.axes if ax.images]
    assert len(with_images) == 2
    for ax in with_images:
        assert np.allclose(ax.get_xlim(), (-0.4, 0.4)) and np.allclose(ax.get_ylim(), (-0.4, 0.4))
    assert [tuple(ax.images[0].get_extent()) for ax in with_images] == [(-0.2, 0.2, -0.2, 0.2), (-0.4, 0.4, -0.4, 0.4)]
    assert figure_problems(fig) == []


def test_only_the_first_bokeh_panel_labels_film_y():
    fig = compare_figure(*_rows_and_curves(), sensor=find_sensor("S35"))
    fig.canvas.draw()
    first, second = [ax for ax in fig.axes if ax.images]
    assert first.get_ylabel() == "film y (mm)" and second.get_ylabel() == ""
    assert any(t.get_visible() and t.get_text() for t in first.get_yticklabels())
    assert not any(t.get_visible() and t.get_text() for t in second.get_yticklabels())
    empty = [ax for ax in fig.axes if not ax.axison]
    assert [ax.get_title() for ax in empty] == ["B\n(no bokeh)"]


def test_eight_lenses_take_two_rows_of_four_with_titles_apart():
    """Eight lenses' bokeh panels in one row of an 11-inch figure were 1.4 inches wide: their two-line titles
    (a 28-character lens name) ran into one another and past the figure's edge. More than four lenses now take
    two rows (four and four here), and one legend beside the curves names them all."""
    y, x = np.mgrid[-1:1:32j, -1:1:32j]
    disk = (x * x + y * y < 0.8).astype(float)
    rows, curves = [], []
    for k in range(8):
        rows.append({"name": f"a_rather_long_lens_name_{k}_mm", "fstop": 2.8, "focus_from_film_mm": 2000.0,
                     "bokeh_light_from_film_mm": 4000.0, "bokeh_diameter_mm": 0.3})
        curves.append({"breathing": ([math.inf, 1000.0], [0.0, -k]), "distortion": ([0.0, 10.0], [0.0, k / 4]),
                       "illumination": ([0.0, 10.0], [1.0, 0.8]), "bokeh": (disk, (-0.2, 0.2, -0.2, 0.2))})
    fig = compare_figure(rows, curves, sensor=find_sensor("S35"))
    assert figure_problems(fig) == []
    panels = [ax for ax in fig.axes if ax.images]
    lefts = sorted({round(ax.get_position().x0, 3) for ax in panels})
    tops = sorted({round(ax.get_position().y1, 3) for ax in panels})
    assert len(lefts) == 4 and len(tops) == 2
    renderer = fig.canvas.get_renderer()
    boxes = [ax.title.get_window_extent(renderer) for ax in panels]
    assert all(fig.bbox.x0 <= b.x0 and b.x1 <= fig.bbox.x1 for b in boxes)
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    assert len(legends) == 1 and [t.get_text() for t in legends[0].get_texts()] == [r["name"] for r in rows]
