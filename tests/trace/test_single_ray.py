"""physcam.trace.single (one ray in Python floats) against the numpy kernel, and the report's chief rays
aimed in floats against the numpy aimer: the same operations, so the same numbers (issue 43's report
without numpy). The oracle is the numpy kernel, an independent code path over arrays."""

import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.analysis._chief import aim_from_film
from physcam.analysis._chief_float import film_chief_directions
from physcam.lens.library import load_lens
from physcam.trace import RayBatch, trace_through
from physcam.trace.single import rows, trace_ray

#: spheres (dgauss), even aspheres (the Signature prime), cylinders (a 2x anamorphic), catalogue glasses (zuiko)
LENSES = ("dgauss_50mm", "arri_signature_prime_58mm_ex1", "navarro_anamorphic_2x", "zuiko_18mm_f3_5")


@pytest.fixture(scope="module")
def lenses():
    return {name: load_lens(name) for name in LENSES}


@settings(max_examples=25, deadline=None)
@given(which=st.sampled_from(LENSES), reverse=st.booleans(), clip=st.booleans(),
       x=st.floats(-0.9, 0.9), y=st.floats(-0.9, 0.9), tx=st.floats(-0.5, 0.5), ty=st.floats(-0.5, 0.5),
       wl=st.sampled_from([486.1327, 587.5618, 656.2725]))
def test_one_ray_is_the_numpy_kernels(lenses, which, reverse, clip, x, y, tx, ty, wl):
    lens = lenses[which]
    r = lens.surfaces[-1 if reverse else 0].semi_diameter
    z = lens.vertex_z[-1] + 5.0 if reverse else -5.0
    d = np.array([tx, ty, -1.0 if reverse else 1.0])
    d = d / np.linalg.norm(d)
    batch = RayBatch.from_arrays([[x * r, y * r, z]], [d], wl)
    ref = trace_through(lens, batch, reverse=reverse, clip=clip, backend="numpy")
    flag, *ray = trace_ray(rows(lens, wl, reverse=reverse), batch.x[0], batch.y[0], batch.z[0], batch.L[0],
                           batch.M[0], batch.N[0], clip=clip)
    assert flag == ref.flag[0]
    if flag == 0:  # bit for bit: the same IEEE operations in the same order
        assert ray == [ref.x[0], ref.y[0], ref.z[0], ref.L[0], ref.M[0], ref.N[0]]


@pytest.mark.parametrize("name", LENSES)
def test_report_chief_rays_are_the_numpy_aimers(lenses, name):
    """The film's edge, top and corner of a Super 35 frame at the lens's infinity film plane."""
    from physcam.optics import paraxial

    lens = lenses[name]
    fz = float(paraxial.gaussian(lens).z_rear_focal_point)
    pts = ((12.445, 0.0), (0.0, 9.33), (12.445, 9.33))
    got = film_chief_directions(lens, pts, fz, lens.wavelength_nm)
    aimed = aim_from_film(lens, np.array(pts), fz, wavelength_nm=lens.wavelength_nm, backend="numpy")
    out = trace_through(lens, RayBatch.from_arrays(aimed.start, aimed.direction, lens.wavelength_nm), reverse=True,
                        clip=True, backend="numpy")
    assert got is not None
    for (flag, L, M, N), ok, L0, M0, N0 in zip(got, aimed.ok & out.ok, out.L, out.M, out.N):
        assert (flag == 0) == bool(ok)
        if ok:
            assert math.isclose(L, L0, rel_tol=1e-12, abs_tol=1e-15)
            assert math.isclose(M, M0, rel_tol=1e-12, abs_tol=1e-15)
            assert math.isclose(N, N0, rel_tol=1e-12, abs_tol=1e-15)


@pytest.mark.parametrize("slug, focus_mm", [("dgauss_50mm", 3000.0),
                                             ("zuiko_18mm_f3_5", 2000.0)])  # its glasses are refitted (stored fits)
def test_a_prescription_report_does_not_import_numpy(slug, focus_mm):
    code = ("import sys, warnings; warnings.simplefilter('ignore')\n"
            "from physcam.lens.library import load_lens\n"
            "from physcam.onset.report import solve_lens_report\n"
            f"r = solve_lens_report(lens=load_lens({slug!r}), sensor='S35', fstop=4.0, focus_mm={focus_mm})\n"
            "assert r.real_fov['diagonal_deg'] > 0\n"
            "print(sorted(m for m in ('numpy', 'scipy', 'matplotlib') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
