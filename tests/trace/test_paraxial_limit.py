"""Issue 5 acceptance: the tracer's paraxial limit agrees with the Gaussian engine.

Two independent methods: the Gaussian engine (y-nu matrices, physcam.optics.paraxial) and
near-axis real rays through the tracer's kernels (Richardson-extrapolated axis crossings for
focus; a tiny off-axis object point for magnification).
"""

import math

import pytest

from physcam.lens.library import list_lenses, load_lens
from physcam.optics import paraxial
from physcam.trace import RayBatch, paraxial_image_z, trace_through

SPHERICAL = [r.slug for r in list_lenses() if not r.anamorphic]


@pytest.mark.parametrize("slug", SPHERICAL)
def test_focus_agrees_with_gaussian_engine(slug):
    lens = load_lens(slug)
    g = paraxial.gaussian(lens)
    assert paraxial_image_z(lens) == pytest.approx(g.z_rear_focal_point, abs=1e-6 * max(1.0, g.efl))


@pytest.mark.parametrize("slug", ["dgauss_50mm", "tessar_50mm_f2_8", "telephoto_250mm", "zeiss_distagon_35mm_f4"])
def test_finite_conjugate_magnification(slug):
    # an object point 1e-3 mm off axis, 20 focal lengths in front of the first vertex: real rays
    # through a tiny pupil region land at the Gaussian image plane with the Gaussian magnification
    lens = load_lens(slug)
    efl = paraxial.gaussian(lens).efl
    z_obj = -20.0 * efl
    g = paraxial.gaussian(lens, object_z=z_obj)
    h = 1e-3
    # chief-like ray aimed at the entrance pupil centre, and a slightly tilted neighbour
    zp = g.z_entrance_pupil
    rays = []
    for dy in (0.0, 1e-4):
        L, M, N = 0.0, (dy - h) / (zp - z_obj), 1.0
        n = math.sqrt(M * M + N * N)
        rays.append((0.0, h, z_obj, L, M / n, N / n))
    b = RayBatch.from_arrays([r[:3] for r in rays], [r[3:] for r in rays], wavelength_nm=lens.wavelength_nm)
    out = trace_through(lens, b, end_z=g.z_image, clip=False, backend="numpy")
    assert out.ok.all()
    # both rays from the same object point meet (to first order) at the image point
    assert out.y[0] == pytest.approx(out.y[1], abs=1e-8)
    assert out.y[0] / h == pytest.approx(g.magnification, rel=1e-4)
