"""Issue 13.4: the microlens array as a traceable system (physcam.trace.microlens).

Oracles: the lattice worked by hand (lenstool/omni layout: cells tile the film, centres at
-W/2 + (i + 1/2) p); the perfect thin lens (a parallel bundle meets at the focal point on the line
through the lenslet centre); reversibility of refraction (a ray sent back retraces its path).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.errors import InputError, WrongTypeError
from physcam.lens.formats.iset import microlens_of, with_microlens
from physcam.lens.library import load_lens
from physcam.trace import RayBatch
from physcam.trace.microlens import (microlens_array, plenoptic_camera, refract_through_array, trace_from_sensor,
                                     trace_to_sensor)


@pytest.fixture(scope="module")
def dgauss():
    return load_lens("dgauss_50mm")


def test_lattice_tiles_the_film_like_lenstool():
    a = microlens_array(4, 3, 2.0, 1.2, focal_length_mm=0.2)
    assert (a.pitch_x, a.pitch_y) == pytest.approx((0.5, 0.4))
    cx, _ = a.cell_centres(np.arange(4), 0)
    _, cy = a.cell_centres(0, np.arange(3))
    assert list(cx) == pytest.approx([-0.75, -0.25, 0.25, 0.75]) and list(cy) == pytest.approx([-0.4, 0.0, 0.4])
    ix, iy, inside = a.index_at([-0.99, 0.01, 0.99, 1.01], [-0.59, 0.0, 0.59, 0.0])
    assert list(ix[:3]) == [0, 2, 3] and list(iy[:3]) == [0, 1, 2] and list(inside) == [True, True, True, False]
    # ISET offsets: row-major in y then x; lenslet (ix=1, iy=2) is row 2 * 4 + 1 = 9
    offs = np.zeros((12, 2))
    offs[9] = (0.01, -0.02)
    b = microlens_array(4, 3, 2.0, 1.2, focal_length_mm=0.2, offsets_mm=offs)
    assert b.centres(1, 2) == pytest.approx((-0.25 + 0.01, 0.4 - 0.02))
    assert b.centres(2, 1) == pytest.approx((0.25, 0.0))


def test_sensor_offset_defaults_to_the_lenslet_focal_plane():
    assert microlens_array(5, 5, 1.0, 1.0, focal_length_mm=0.3).sensor_offset_mm == 0.3
    # a plano-convex glass lenslet (the thin lenslet's ISET stand-in): its back focal distance
    p = with_microlens(load_lens("dgauss_50mm"), thin_focal_length_mm=0.8, count_x=5, count_y=5, film_width_mm=1.0,
                       film_height_mm=1.0)
    import json

    from physcam.lens.formats.iset import loads

    rows = microlens_of(p)
    block = json.loads(dict(p.extras)["iset.microlens"])
    lenslet = loads(json.dumps({"name": "pc", "surfaces": block["surfaces"]}))
    a = microlens_array(5, 5, 1.0, 1.0, lenslet=lenslet)
    # plano-convex, curved side first: f = R/(n-1) = 0.8; the rear principal plane t/n in front of the flat
    t = block["surfaces"][0]["thickness"]
    assert a.sensor_offset_mm == pytest.approx(0.8 - t / 1.5, rel=1e-9)
    assert rows["thin_focal_length_mm"] == 0.8


def test_bad_arrays_are_refused(dgauss):
    for kw in ({"focal_length_mm": None}, {"focal_length_mm": 0.2, "lenslet": dgauss}, {"focal_length_mm": -1.0}):
        with pytest.raises(InputError):
            microlens_array(5, 5, 1.0, 1.0, **kw)
    with pytest.raises(InputError):
        microlens_array(0, 5, 1.0, 1.0, focal_length_mm=0.2)
    with pytest.raises(InputError):
        microlens_array(5, 5, 1.0, 1.0, focal_length_mm=0.2, offsets_mm=np.zeros((24, 2)))
    a = microlens_array(5, 5, 1.0, 1.0, focal_length_mm=0.2)
    with pytest.raises(InputError):
        plenoptic_camera(dgauss, a, focus_mm=2000.0, film_to_lens_mm=40.0)
    with pytest.raises(InputError):
        plenoptic_camera(dgauss, a, film_to_lens_mm=0.1)  # no room for the array
    with pytest.raises(WrongTypeError):
        plenoptic_camera("dgauss", a, focus_mm=2000.0)
    with pytest.raises(InputError, match="anamorphic"):
        plenoptic_camera(load_lens("navarro_anamorphic_2x"), a, focus_mm=3000.0)


def test_thin_lenslet_is_a_perfect_lens(dgauss):
    """A bundle parallel to a tilted direction, all on one lenslet, meets at one point of its focal
    plane: the lenslet centre plus f times the direction's slope (Hecht 5.2)."""
    a = microlens_array(7, 7, 0.7, 0.7, focal_length_mm=0.25)
    cam = plenoptic_camera(dgauss, a, film_to_lens_mm=45.0)
    cx, cy = a.centres(5, 2)  # (0.2, -0.1)
    g = np.random.default_rng(3)
    n = 50
    x = cx + (g.random(n) - 0.5) * 0.09
    y = cy + (g.random(n) - 0.5) * 0.09
    sx, sy = 0.05, -0.02
    rays = RayBatch.from_arrays(np.stack([x, y, np.full(n, cam.z_array - 1.0)], 1) - np.array([sx, sy, 0.0]),
                                np.array([[sx, sy, 1.0]]))
    refract_through_array(cam, rays)
    assert rays.ok.all()
    t = (cam.z_array + 0.25 - rays.z) / rays.N
    assert rays.x + t * rays.L == pytest.approx(np.full(n, cx + 0.25 * sx), abs=1e-12)
    assert rays.y + t * rays.M == pytest.approx(np.full(n, cy + 0.25 * sy), abs=1e-12)


def _lenslet_camera(dgauss, thin: bool):
    if thin:
        a = microlens_array(9, 9, 0.9, 0.9, focal_length_mm=0.3)
    else:
        import json

        from physcam.lens.formats.iset import loads

        p = with_microlens(dgauss, thin_focal_length_mm=0.3, count_x=9, count_y=9, film_width_mm=0.9, film_height_mm=0.9)
        rows = json.loads(dict(p.extras)["iset.microlens"])["surfaces"]
        a = microlens_array(9, 9, 0.9, 0.9, lenslet=loads(json.dumps({"name": "pc", "surfaces": rows})))
    return plenoptic_camera(dgauss, a, film_to_lens_mm=45.0)


@pytest.mark.parametrize("thin", [True, False], ids=["thin", "prescription"])
@settings(max_examples=30)
@given(x=st.floats(-0.44, 0.44), y=st.floats(-0.44, 0.44), sx=st.floats(-0.08, 0.08), sy=st.floats(-0.08, 0.08))
def test_refraction_through_the_array_is_reversible(dgauss, thin, x, y, sx, sy):
    """Forward through the lattice, then back with the direction reversed: the ray returns along
    its incoming line (same lenslet both ways)."""
    cam = _lenslet_camera(dgauss, thin)
    z0 = cam.z_array_front - 0.5
    r = RayBatch.from_arrays([[x - 0.5 * sx, y - 0.5 * sy, z0]], [[sx, sy, 1.0]])
    refract_through_array(cam, r)
    if not r.ok.all():
        return  # clipped at a cell wall: nothing to reverse
    back = RayBatch.from_arrays(np.stack([r.x, r.y, r.z], 1), -np.stack([r.L, r.M, r.N], 1))
    refract_through_array(cam, back, reverse=True)
    assert back.ok.all()
    d = np.array([sx, sy, 1.0]) / np.linalg.norm([sx, sy, 1.0])
    assert -np.array([back.L[0], back.M[0], back.N[0]]) == pytest.approx(d, abs=1e-9)
    t = (z0 - back.z[0]) / back.N[0]
    assert (back.x[0] + t * back.L[0], back.y[0] + t * back.M[0]) == pytest.approx((x - 0.5 * sx, y - 0.5 * sy),
                                                                                    abs=1e-9)


def test_rays_outside_the_array_are_clipped(dgauss):
    cam = _lenslet_camera(dgauss, True)
    r = RayBatch.from_arrays([[0.46, 0.0, cam.z_array - 1.0], [0.0, 0.0, cam.z_array - 1.0]], [[0.0, 0.0, 1.0]])
    refract_through_array(cam, r)
    assert list(r.ok) == [False, True] and r.weight[0] == 0.0


def test_sensor_to_scene_and_back_agree(dgauss):
    """A ray traced from the sensor out through the array and the main lens, then reversed, lands
    where it started (the whole system is reversible)."""
    a = microlens_array(31, 31, 1.24, 1.24, focal_length_mm=0.16)
    cam = plenoptic_camera(dgauss, a, focus_mm=1000.0, fstop=4.0)
    g = np.random.default_rng(0)
    n = 400
    start = np.stack([(g.random(n) - 0.5) * 1.2, (g.random(n) - 0.5) * 1.2, np.full(n, cam.z_sensor)], 1)
    d = np.stack([(g.random(n) - 0.5) * 0.3, (g.random(n) - 0.5) * 0.3, -np.ones(n)], 1)
    out = trace_from_sensor(cam, RayBatch.from_arrays(start, d))
    ok = out.ok
    assert ok.sum() > 20
    back = RayBatch.from_arrays(np.stack([out.x, out.y, out.z], 1)[ok], -np.stack([out.L, out.M, out.N], 1)[ok])
    home = trace_to_sensor(cam, back)
    assert home.ok.all()
    assert np.stack([home.x, home.y], 1) == pytest.approx(start[ok, :2], abs=1e-7)


@pytest.mark.parametrize("thin", [True, False], ids=["thin", "prescription"])
def test_a_ray_entering_on_a_cell_wall_reverses(dgauss, thin):
    """The example hypothesis found: a ray parallel to the axis entering exactly on the wall between two
    cells (y = 0.25 mm, pitch 0.1 mm) is refracted by one of them; reversed, it returns to the wall, which
    rounding put a hair outside that cell, and it was clipped."""
    cam = _lenslet_camera(dgauss, thin)
    r = RayBatch.from_arrays([[0.0, 0.25, cam.z_array_front - 0.5]], [[0.0, 0.0, 1.0]])
    refract_through_array(cam, r)
    assert r.ok.all()
    back = RayBatch.from_arrays(np.stack([r.x, r.y, r.z], 1), -np.stack([r.L, r.M, r.N], 1))
    refract_through_array(cam, back, reverse=True)
    assert back.ok.all() and back.y[0] == pytest.approx(0.25, abs=1e-9)
