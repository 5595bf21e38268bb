"""A y-u trace by hand of the bundled anamorphics, per meridian (issue 49): the oracle of their two
entrance pupils and framing focal lengths (breathing per axis), shared by the lens, USD, OpenTrackIO,
frustum and Unreal tests.

Written from each lens file's own numbers (``tomllib``, nd at the d line; Smith, *Modern Optical
Engineering*, 4th ed., eqs. 2.31-2.32: n'u' = nu - y c (n' - n), y' = y + t u'). A cylinder is flat
in the meridian along its axis: ``cylindrical_x`` is curved in X only, ``cylindrical_y`` in Y only.
"""

from __future__ import annotations

import tomllib

from physcam.lens.library import library_dir, load_lens
from physcam.optics import focusing


def _surfaces(slug, thicknesses=None):
    doc = tomllib.loads((library_dir() / f"{slug}.toml").read_text(encoding="utf-8"))
    out = []
    for i, s in enumerate(doc["surface"]):
        n = 1.0 if s["medium"] == "air" else float(s["medium"]["nd"])
        t = float(s["thickness"]) if thicknesses is None else thicknesses[i]
        out.append((s["kind"], float(s["radius"]), t, n))
    return out


def _yu(surfaces, meridian):
    """(EFL, entrance pupil z from the first vertex, back focal distance) by a y-u trace, by hand."""
    def trace(y, u, upto=None):
        n0 = 1.0
        for i, (kind, r, t, n) in enumerate(surfaces):
            flat = kind in ("flat", "stop") or r == 0 or kind == f"cylindrical_{'y' if meridian == 'x' else 'x'}"
            c = 0.0 if flat else 1.0 / r
            if i == upto:
                return y
            u = (n0 * u - y * c * (n - n0)) / n
            if i < len(surfaces) - 1:
                y += t * u
            n0 = n
        return y, u

    y, u = trace(1.0, 0.0)
    stop = next(i for i, s in enumerate(surfaces) if s[0] == "stop")
    # the chief ray crosses the axis at the stop: a ray y0 A + u0 B (A = (1, 0), B = (0, 1) at the first
    # vertex) passes there when y0 yA + u0 yB = 0; it crosses the axis in object space at z = -y0 / u0
    return -1.0 / u, trace(0.0, 1.0, stop) / trace(1.0, 0.0, stop), -y / u


def _framing_focal_length(surfaces, meridian):
    """|y_film / u| of the chief ray (through the stop centre) at unit object-space slope, by hand: the
    focal length a pinhole at the entrance pupil needs to frame like the lens (Smith 3.5)."""
    _, z_ep, _ = _yu(surfaces, meridian)
    n0, y, u = 1.0, -z_ep, 1.0  # at the first vertex: height -z_ep, slope 1, crossing the axis at z_ep
    for i, (kind, r, t, n) in enumerate(surfaces):
        flat = kind in ("flat", "stop") or r == 0 or kind == f"cylindrical_{'y' if meridian == 'x' else 'x'}"
        u = (n0 * u - y * (0.0 if flat else 1.0 / r) * (n - n0)) / n
        y += t * u  # the last gap ends on the film
        n0 = n
    return abs(y)


def hand_framing_focal_lengths(slug, mark):
    """(X, Y) framing focal lengths (mm) of ``slug`` focused at ``mark``: the per-axis breathing, traced
    by hand through the gaps the focus solver set."""
    st = focusing.focus(load_lens(slug), mark)
    surfaces = _surfaces(slug, [s.thickness for s in st.prescription.surfaces])
    return _framing_focal_length(surfaces, "x"), _framing_focal_length(surfaces, "y")


def hand_pupils_from_film(slug, mark):
    """(X, Y) entrance pupils in front of the film (mm) of ``slug`` focused at ``mark``: the focus
    solver only moves the gaps; this trace takes those gaps and finds both pupils itself."""
    st = focusing.focus(load_lens(slug), mark)
    surfaces = _surfaces(slug, [s.thickness for s in st.prescription.surfaces])
    z_film = sum(s[2] for s in surfaces)  # the last gap is the back focus to the film
    return z_film - _yu(surfaces, "x")[1], z_film - _yu(surfaces, "y")[1]
