"""The Blender extension's focus tables (physcam.export.blender_focus) between their marks: the lens
state the shader blends focuses where physcam's exact focus solve (physcam.optics.focusing.focus)
says, down to the closest focus. Before round 7 the marks were uniform in 1/distance and the states
linear in it: near a unit-focusing lens's 1:1 closest focus the film plane was out by 4.3 mm on the
double Gauss 50 (1.3 mm of defocus) and 27 mm at the Canon 70-200's tele end (12 marks; 11.7 mm of
defocus). The blend is evaluated as the shader's lines do (blended_geometry); the oracle
is the exact focus solve at the same mark, and the defocus is the paraxial image of that mark through
the blended lens less the blended film plane."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import InputError
from physcam.export.blender_focus import (N_FOCUS, FocusAxis, blend_weights, blended_geometry, focus_axis,
                                         focus_geometry, hermite_basis)
from physcam.export.blender_zoom import N_FOCUS_ZOOM, N_ZOOM_GEOMETRY, zoom_focus_axis
from physcam.lens.library import load_lens
from physcam.lens.zoom import prescription_at
from physcam.optics.focusing import closest_focus, focus, gaussian_at_focus, image_distance

#: Half the depth of focus a 0.030 mm circle of confusion (full frame) allows at f/N is N x 0.030 mm
#: (object side far away; more at close focus): the tables must stay within a tenth of it wide open.
COC_MM = 0.030


def _defocus(q, film, vz_film_first, mark_mm):
    """The paraxial image of a subject mark_mm in front of the film, through q with these vertices, less
    the film plane (mm, + behind it)."""
    vz = np.asarray(vz_film_first)[::-1]
    qb = q.with_thicknesses({i: float(vz[i + 1] - vz[i]) for i in range(len(vz) - 1)})
    return vz[-1] + image_distance(qb, mark_mm - (film - vz[0])) - film


CASES = {
    # unit focusing down to 1:1 (closest_focus: 4 f + hiatus)
    "dgauss_50mm": None,
    "telephoto_250mm": None,
    # internal focusing: the groups' gaps move
    "sigma_50mm_f1_4_art": None,
    # zooms at an end, on the focus axis their tables share: the Canon's tele end is at 1:1 there
    "canon_ef_70_200mm_f2_8_zoom": 1.0,
    "nikon_af_s_70_200mm_f2_8e_zoom": 1.0,
}


@pytest.mark.parametrize("slug", sorted(CASES))
def test_between_marks_the_table_focuses_where_physcam_does(slug):
    """At 3 points inside every interval between marks and 15 inside the last (the closest focus): the
    blended film plane within 0.002 mm and every gap within 0.003 mm of the exact focus solve's, and the
    subject at the mark imaged within a tenth of the half depth of focus wide open (N x 0.030 mm / 10)
    of the blended film plane. (Before: 1.29 mm on the double Gauss, 11.7 mm at the Canon's tele end.)"""
    lens = load_lens(slug)
    u = CASES[slug]
    if u is None:
        q, axis = lens, focus_axis(closest_focus(lens), N_FOCUS)
    else:
        q = prescription_at(lens, u)
        axis = zoom_focus_axis([prescription_at(lens, float(v)) for v in np.linspace(0, 1, N_ZOOM_GEOMETRY)])
        assert axis.n == N_FOCUS_ZOOM
    geometry = focus_geometry(q, axis)
    tol_defocus = gaussian_at_focus(q, math.inf).f_number * COC_MM / 10
    points = [k + j / 4 for k in range(axis.n - 2) for j in (1, 2, 3)] + [axis.n - 2 + j / 16 for j in range(1, 16)]
    worst = {"film": 0.0, "gap": 0.0, "defocus": 0.0}
    for x in points:
        mark = axis.mark(x)
        film, vz = blended_geometry(axis, geometry, mark)
        exact = focus(q, mark)
        worst["film"] = max(worst["film"], abs(film - exact.film_z))
        worst["gap"] = max(worst["gap"], float(np.abs(np.diff(vz) - np.diff(exact.prescription.vertex_z[::-1])).max()))
        worst["defocus"] = max(worst["defocus"], abs(_defocus(q, film, vz, mark)))
    print(slug, worst, "tolerance", tol_defocus)
    assert worst["film"] < 0.002 and worst["gap"] < 0.003, worst
    assert worst["defocus"] < tol_defocus, worst


def test_the_marks_by_hand():
    """Three marks down to C = 1000 mm (last mark C (1 + 1e-6)): s_near = sqrt(1 - 1/(1 + 1e-6)) =
    0.000999999500, the middle mark at s = (1 + s_near) / 2, i.e. C / (1 - 0.25050025) = 1334.22 mm; index 1 there,
    0 at infinity, 2 at the last mark and closer."""
    ax = focus_axis(1000.0, 3)
    assert ax.s_near == pytest.approx(0.000999999500, rel=1e-9)
    s = (1 + 0.000999999500) / 2
    assert ax.marks_mm[0] == math.inf
    assert ax.marks_mm[1] == pytest.approx(1000.0 / (1 - s * s), rel=1e-12)
    assert ax.marks_mm[1] == pytest.approx(1334.22, abs=0.005)
    assert ax.marks_mm[2] == pytest.approx(1000.001, rel=1e-12)
    assert [ax.index(m) for m in (math.inf, ax.marks_mm[1], ax.marks_mm[2], 500.0)] == pytest.approx([0, 1, 2, 2])
    with pytest.raises(InputError, match="at least 3"):
        focus_axis(1000.0, 2)


@settings(max_examples=40)
@given(x=st.floats(0.0, 31.0), closest=st.floats(10.0, 5000.0))
def test_index_and_mark_round_trip(x, closest):
    ax = FocusAxis(closest, closest * (1 + 1e-6), 32)
    m = ax.mark(x)
    assert m >= ax.near_mm * (1 - 1e-12)
    assert ax.index(m) == pytest.approx(x, abs=1e-6)


@settings(max_examples=40)
@given(x=st.floats(0.0, 9.0), c=st.lists(st.floats(-5.0, 5.0), min_size=4, max_size=4), n=st.sampled_from([3, 4, 10]))
def test_the_blend_is_exact_for_quadratics_and_the_hermite_for_cubics(x, c, n):
    """Catmull-Rom with the quadratic's extrapolation at the ends reproduces any quadratic in the index; the
    cubic Hermite with exact slopes any cubic (worked by hand: both are the cubic's Taylor identities)."""
    x = min(x, n - 1.0)
    k = np.arange(n, dtype=float)
    quad = c[0] + c[1] * k + c[2] * k * k
    k0, t, taps, w = blend_weights(x, n)
    assert sum(wi * quad[i] for i, wi in zip(taps, w)) == pytest.approx(c[0] + c[1] * x + c[2] * x * x, abs=1e-9)
    cubic, slope = quad + c[3] * k ** 3, c[1] + 2 * c[2] * k + 3 * c[3] * k * k
    h = hermite_basis(t)
    got = h[0] * cubic[k0] + h[1] * slope[k0] + h[2] * cubic[k0 + 1] + h[3] * slope[k0 + 1]
    assert got == pytest.approx(c[0] + c[1] * x + c[2] * x * x + c[3] * x ** 3, abs=1e-8)


def _addon_function(name):
    """A function of the add-on's template (it runs inside Blender, without physcam), compiled alone."""
    import ast
    from importlib import resources

    src = resources.files("physcam.export").joinpath("blender_addon.py.in").read_text(encoding="utf-8")
    (node,) = [n for n in ast.parse(src).body if isinstance(n, ast.FunctionDef) and n.name == name]
    scope = {"math": math}
    exec(compile(ast.Module([node], type_ignores=[]), "blender_addon.py.in", "exec"), scope)
    return scope[name]


@settings(max_examples=60)
@given(closest=st.floats(100.0, 5000.0), n=st.integers(3, 40), s=st.floats(0.0, 1.0))
def test_the_addons_focus_taps_are_blend_weights(closest, n, s):
    """The panel's report rows (the add-on's _focus_taps, a copy of the shader's blend for Blender's Python)
    take the states and weights physcam's blend_weights gives at the same mark (s = sqrt(1 - C / D))."""
    ax = focus_axis(closest, n)
    focus_mm = closest / max(1.0 - s * s, 1e-12)
    data = {"focus_axis": {"closest_m": ax.closest_mm / 1000.0, "s_near": ax.s_near}}
    _, _, taps, w = blend_weights(ax.index(focus_mm), n)
    got = _addon_function("_focus_taps")(data, focus_mm / 1000.0, n)
    assert [k for k, _ in got] == taps
    assert [x for _, x in got] == pytest.approx(w, abs=1e-9)
