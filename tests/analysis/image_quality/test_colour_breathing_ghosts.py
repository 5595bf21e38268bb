"""Colour, real breathing and ghosts against hand-worked numbers."""

import math

import numpy as np
import pytest

from physcam.analysis.framing.breathing_real import real_breathing
from physcam.analysis.image_quality.colour import chromatic_aberration
from physcam.analysis.distortion.field import real_distortion
from physcam.analysis.image_quality.ghosts import _Tables, ghost_analysis, ghost_pairs, trace_ghost
from physcam.errors import InputError, OpticsError
from physcam.lens.library import load_lens
from physcam.optics.focusing import breathing_table
from physcam.optics.glass import LINE_C_NM, LINE_F_NM, refractive_index
from physcam.optics.state import camera_state
from physcam.trace import RayBatch, trace_to_film

from _analysis_lenses import N_BK7, plano_convex, plate


@pytest.fixture(scope="module")
def dgauss():
    return load_lens("dgauss.50mm")


def test_thin_lens_longitudinal_colour_is_f_over_vd():
    lens = plano_convex(f=100.0, thickness=1.0)
    res = chromatic_aberration(lens, [0.0, 2.0, 5.0])
    # closed form of this plano-convex lens: rear focus z = t + R/(n-1) - t/n (EFL exact, BFL = f - t/n)
    nF, nC = (float(refractive_index(N_BK7.nd, N_BK7.vd, w)) for w in (LINE_F_NM, LINE_C_NM))
    R, t = 100.0 * (N_BK7.nd - 1.0), 1.0
    z = lambda n: t + R / (n - 1.0) - t / n  # noqa: E731
    assert res.longitudinal_paraxial_mm == pytest.approx(z(nC) - z(nF), rel=1e-9)
    # and, to first order, f / Vd (Smith 10.4): 1.558 mm for f = 100, Vd = 64.17
    assert res.longitudinal_paraxial_mm == pytest.approx(100.0 / 64.17, rel=0.015)
    assert res.longitudinal_real_mm == pytest.approx(res.longitudinal_paraxial_mm, rel=0.01)
    # stop in contact with a thin lens: the chief ray is hardly displaced, no lateral colour
    assert all(abs(p.lateral_colour_um) < 0.5 for p in res.lateral)
    assert res.lateral[0].lateral_colour_um == 0.0


def test_lens_without_dispersion_has_no_colour(dgauss):
    res = chromatic_aberration(dgauss, [0.0, 10.0], wavelengths_nm=(450.0, 600.0))
    assert res.longitudinal_paraxial_mm == 0.0 and res.longitudinal_real_mm == 0.0
    assert all(p.lateral_colour_um == 0.0 for p in res.lateral)
    assert set(res.wavelengths_nm) >= {450.0, 600.0, LINE_F_NM, LINE_C_NM}
    d = res.to_dict()
    assert len(d["curve"]["wavelength_nm"]) == len(d["curve"]["focus_shift_mm"])
    with pytest.raises(InputError):
        chromatic_aberration(dgauss, zone=1.5)
    with pytest.raises(InputError):
        chromatic_aberration(dgauss, wavelengths_nm=(2000.0,))


def test_real_breathing_tends_to_the_paraxial_table(dgauss):
    # a tiny sensor: the real chief ray is paraxial, so the paraxial breathing table must be reproduced
    marks = (math.inf, 3000.0, 700.0, 250.0)
    res = real_breathing(dgauss, marks, sensor_width_mm=0.02, sensor_height_mm=0.01)
    table = breathing_table(dgauss, marks, sensor_width_mm=0.02)
    for row, par in zip(res.rows, table):
        assert row.hfov_real_deg == pytest.approx(par.hfov_deg, rel=1e-6)
    assert res.rows[-1].change_real_pct < 0  # a unit-focusing lens narrows its view when focused close


def test_paraxial_breathing_from_the_published_dgauss_figures(dgauss):
    # Independent of physcam's engine: from the published dgauss.50mm figures (EFL 50.3582, BFL
    # 36.1059, exit pupil 17.7714 before the last vertex, pupil magnification 1.06988, hiatus
    # H1-H2 = -5.448), a unit-focusing lens focused at mark D extends by s' - f (s + s' + hiatus
    # = D) and the chief ray from the film corner through the exit pupil gives
    # HFOV = 2 atan(m_p (w/2) / (BFL + 17.7714 + ext)); for w = 36 mm: 39.338, 38.459, 37.526 and
    # 35.455 deg at infinity, 2 m, 1 m and 0.5 m (worked in a separate script).
    res = real_breathing(dgauss, (math.inf, 2000.0, 1000.0, 500.0), sensor_width_mm=36.0, sensor_height_mm=24.0)
    for row, expect in zip(res.rows, (39.338, 38.459, 37.526, 35.455)):
        assert row.hfov_paraxial_deg == pytest.approx(expect, abs=2e-3)


def test_real_breathing_internal_focus_and_full_frame(dgauss):
    lens = load_lens("canon_rf_85mm_f1_2")
    small = real_breathing(lens, sensor_width_mm=0.02, sensor_height_mm=0.01)
    assert small.method == "internal"
    assert all(r.hfov_real_deg == pytest.approx(r.hfov_paraxial_deg, rel=1e-5) for r in small.rows)
    # full frame at infinity: the edge chief ray lands where the forward (distortion) chief ray of
    # half the real HFOV does
    full = real_breathing(dgauss, [math.inf], sensor_width_mm=30.0, sensor_height_mm=20.0)
    half = full.rows[0].hfov_real_deg / 2
    h = real_distortion(dgauss, [half]).points[0].real_height_mm
    assert h == pytest.approx(15.0, abs=1e-6)
    with pytest.raises(OpticsError, match="does not cover"):
        real_breathing(dgauss, [math.inf], sensor_width_mm=80.0)


def _fresnel_rsp(theta, n):
    """(R_s, R_p, refraction angle) of an air-glass surface, Hecht eqs. 4.42-4.43, by hand."""
    tp = math.asin(math.sin(theta) / n)
    ci, ct = math.cos(theta), math.cos(tp)
    rs = (ci - n * ct) / (ci + n * ct)
    rp = (n * ci - ct) / (n * ci + ct)
    return rs * rs, rp * rp, tp


def test_plate_ghost_normal_incidence():
    res = ghost_analysis(camera_state(plate(), film_z=60.0), 0.0, rank_rays=2000)
    assert [(p.i, p.j) for p in res.paths] == [(2, 1)]
    R = ((1.5 - 1) / (1.5 + 1)) ** 2
    assert res.paths[0].relative_flux == pytest.approx(R * R, rel=1e-12)  # T R R T / (T T)


@pytest.mark.parametrize("theta_deg", [15.0, 35.0])
def test_plate_ghost_oblique_ray_by_hand(theta_deg):
    lens, t = plate(thickness=10.0), 10.0
    th = math.radians(theta_deg)
    y0 = -5.0 - 6.0 * math.tan(th)  # meets the plate at y = -5 so that the ghost stays inside its rims
    ray = RayBatch.from_arrays([[0.0, y0, -1.0]], [[0.0, math.sin(th), math.cos(th)]])
    direct = trace_to_film(lens, ray, 60.0, fresnel=True)
    ghost = trace_ghost(lens, ray, 2, 1, 60.0)
    Rs, Rp, tp = _fresnel_rsp(th, 1.5)
    assert ghost.ok.all()
    # The s and p halves of unpolarised light go their own way through T R R T (glass-air R and T
    # equal air-glass ones at the refracted angle, Stokes relations, Hecht 4.6.3), so
    # ghost / direct = (Ts^2 Rs^2 + Tp^2 Rp^2) / (Ts^2 + Tp^2), not ((Rs + Rp) / 2)^2.
    Ts, Tp = 1.0 - Rs, 1.0 - Rp
    expect = (Ts * Ts * Rs * Rs + Tp * Tp * Rp * Rp) / (Ts * Ts + Tp * Tp)
    assert ghost.weight[0] / direct.weight[0] == pytest.approx(expect, rel=1e-10)
    assert ghost.weight_s[0] == pytest.approx(Ts * Ts * Rs * Rs, rel=1e-10)  # unit starting weight
    assert ghost.weight_p[0] == pytest.approx(Tp * Tp * Rp * Rp, rel=1e-10)
    # two extra passes through the plate: the ghost leaves parallel, shifted by 2 t tan(theta')
    assert ghost.y[0] - direct.y[0] == pytest.approx(2 * t * math.tan(tp), rel=1e-10)
    assert (ghost.L[0], ghost.M[0], ghost.N[0]) == pytest.approx((direct.L[0], direct.M[0], direct.N[0]), abs=1e-12)


def test_lens_ghosts_ranked_coated_and_imaged(dgauss):
    pairs = ghost_pairs(dgauss)
    n_refl = sum(1 for s in dgauss.surfaces if not s.is_stop)
    assert len(pairs) == n_refl * (n_refl - 1) // 2
    bare = ghost_analysis(dgauss, 8.0, rank_rays=600, coating="none")
    multi = ghost_analysis(dgauss, 8.0, rank_rays=600, coating="multi", image_rays=3000, image_paths=4, pixels=32)
    flux = [p.relative_flux for p in bare.paths]
    assert flux == sorted(flux, reverse=True) and flux[0] > 0
    assert sum(p.relative_flux for p in multi.paths) < 0.1 * sum(flux)
    assert multi.image is not None and np.isfinite(multi.image).all() and multi.image.max() > 0
    assert multi.to_dict()["image"]["paths"] == 4
    with pytest.raises(InputError):
        ghost_analysis(dgauss, 95.0)
    with pytest.raises(InputError):
        trace_ghost(dgauss, RayBatch.from_arrays([[0, 0, -1.0]], [[0, 0, 1.0]]), 2, 5, 80.0)
    assert _Tables(dgauss, "none", None).n == 11  # dgauss.50mm has 11 surfaces, the stop included


def test_colour_says_when_the_file_has_no_dispersion():
    from physcam.analysis.image_quality.colour import chromatic_aberration
    from physcam.lens.library import load_lens

    res = chromatic_aberration(load_lens("dgauss_50mm"))  # pbrt file: no Abbe numbers
    assert res.longitudinal_paraxial_mm == 0.0
    assert any("Abbe" in n for n in res.notes)
    res = chromatic_aberration(load_lens("tessar_50mm_f2_8"))  # every glass with an Abbe number
    assert res.longitudinal_paraxial_mm != 0.0 and not res.notes


def test_colour_names_each_glass_model_and_its_uncertainty():
    # catalogue glass: exact (no uncertainty); the model is named
    res = chromatic_aberration(plano_convex(f=100.0, thickness=1.0), [0.0])
    assert [m["glass"] for m in res.media] == ["N-BK7"] and res.media[0]["maker"] == "SCHOTT"
    assert res.longitudinal_uncertainty_mm == 0.0 and res.curve_uncertainty_mm == 0.0
    # a glass known only by (nd, Vd): normal line, and the C - F uncertainty equals the closed form
    # of a plano-convex lens (focus z = t + R/(n-1) - t/n) with P_gF moved by +-0.01
    from physcam.lens.prescription import Medium, Prescription, Surface
    from physcam.optics.glass import normal_line

    nd, vd, R, t = 1.6, 40.0, 60.0, 1.0
    lens = Prescription((Surface(0.0, 0.0, semi_diameter=4.0, kind="stop"), Surface(R, t, Medium(nd, vd), 6.0),
                         Surface(0.0, 90.0, semi_diameter=6.0, kind="flat"))).validate()
    res = chromatic_aberration(lens, [0.0])
    assert res.media[0]["model"] == "normal-line" and res.media[0]["surfaces"] == [1]
    z = lambda n: t + R / (n - 1.0) - t / n  # noqa: E731
    p0 = 0.6438 - 0.001682 * vd
    cf = []
    for p in (p0 + 0.01, p0 - 0.01):
        m = normal_line(nd, vd, p)
        cf.append(z(float(m.index(LINE_C_NM))) - z(float(m.index(LINE_F_NM))))
    assert res.longitudinal_uncertainty_mm == pytest.approx(abs(cf[0] - cf[1]) / 2, rel=1e-6)
    assert res.to_dict()["uncertainty"]["longitudinal_paraxial_mm"] == res.longitudinal_uncertainty_mm


def test_ghost_ranking_traces_each_first_leg_once_and_matches_each_path_traced_alone(monkeypatch):
    # issue 47: the paths that reflect first at surface i share their first leg (forward to i and the
    # reflection there), so a ranking traces one first leg per i and two legs per path (main traced
    # three legs per path); each path's flux and centroid are still those of the path traced alone
    # with the public trace_ghost (the same rays, to the bit)
    import physcam.trace.trace as tr
    from physcam.analysis.image_quality.ghosts import _beam
    from physcam.optics.state import camera_state

    lens = load_lens("tessar_50mm_f2_8")
    pairs = ghost_pairs(lens)
    calls = []
    real = tr.trace_packed
    monkeypatch.setattr(tr, "trace_packed", lambda *a, **k: calls.append(1) or real(*a, **k))
    cam = camera_state(lens)
    res = ghost_analysis(cam, 5.0, rank_rays=400, backend="numpy")
    monkeypatch.undo()
    assert len(calls) == len({i for i, _ in pairs}) + 2 * len(pairs)
    beam = _beam(lens, 5.0, res.wavelength_nm, 400)
    direct = trace_to_film(lens, beam, res.film_z_mm, fresnel=True, coating=res.coating, backend="numpy")
    flux0 = float(direct.weight[direct.ok].sum())
    by_path = {(p.i, p.j): p for p in res.paths}
    assert sum(p.relative_flux > 0 for p in res.paths) > len(pairs) // 2
    for i, j in pairs:
        g = trace_ghost(cam, beam, i, j, coating=res.coating, backend="numpy")
        ok = g.ok & (g.weight > 0)
        flux = float(g.weight[ok].sum())
        assert by_path[i, j].relative_flux == pytest.approx(flux / flux0, rel=1e-12, abs=0.0)
        if flux > 0:
            assert by_path[i, j].centroid_y_mm == float((g.y[ok] * g.weight[ok]).sum() / flux)
