"""Which root of a sphere a ray meets (trust review, issue 24 item 6).

Rays from far in front of a concave first surface at steep angles can cross its sphere twice on the
vertex side (the bowl's steep wall, then its floor). The tracer took the crossing nearest the ray's
start, on the wall, where the ray passes from the glass side into the air: not a crossing a
sequential ray makes. Steep rays that pass the clear aperture were reported clipped (4 of 2,400 in
the review; 1,264 of 215,805 here). The surface is now met where the ray crosses from the medium
before it into the medium after it: for a concave front (centre of curvature in front), where the
ray leaves the sphere; for a convex one, where it enters. The reference below is that crossing,
solved by hand in the test; it is the one nearest the vertex.
"""

from __future__ import annotations

import numpy as np
import pytest

from physcam.lens.prescription import LensMetadata, Medium, Prescription, Surface
from physcam.trace import RayBatch
from physcam.trace.kernels import get_kernel
from physcam.trace.kernels._layout import pack
from physcam.trace.surfaces import surface_table
from physcam.trace.trace import trace_packed


def _steep_rays(sd, distance, n=100_000, seed=1):
    rng = np.random.default_rng(seed)
    ang = np.radians(rng.uniform(-70, 70, n))
    phi = rng.uniform(0, 2 * np.pi, n)
    d = np.stack([np.sin(ang) * np.cos(phi), np.sin(ang) * np.sin(phi), np.cos(ang)], axis=1)
    aim = np.stack([rng.uniform(-sd, sd, n), rng.uniform(-sd, sd, n), np.zeros(n)], axis=1)
    return aim - d * (distance / d[:, 2])[:, None], d


def _forward_crossing(p, d, r):
    """The point where each ray crosses the sphere of radius r (vertex at z = 0, centre at z = r) from
    the side it comes from (air, z below the surface) into the glass: it enters the sphere when r > 0,
    it leaves it when r < 0. NaN where that crossing is not on the vertex half of the sphere."""
    oc = p - np.array([0.0, 0.0, r])
    b = (oc * d).sum(axis=1)
    disc = b * b - ((oc * oc).sum(axis=1) - r * r)
    root = np.sqrt(np.where(disc >= 0, disc, np.nan))
    t = -b - root if r > 0 else -b + root
    q = p + t[:, None] * d
    on_vertex_half = (q[:, 2] - r) * np.sign(r) < 0  # z < r for r > 0, z > r for r < 0
    return np.where(on_vertex_half[:, None], q, np.nan)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("radius, sd", [(-16.0, 15.5), (-40.0, 15.0), (40.0, 15.0)])
@pytest.mark.parametrize("distance", [1000.0, 1.0e4])
def test_a_steep_ray_meets_the_surface_where_it_enters_the_glass(backend, radius, sd, distance):
    lens = Prescription((Surface(radius, 40.0, Medium(1.5, 0.0), sd, kind="spherical"),
                         Surface(0.0, 30.0, semi_diameter=1e4, kind="stop")), LensMetadata(name="one surface")).validate()
    S, kinds = pack(surface_table(lens))
    p, d = _steep_rays(sd, distance)
    want = _forward_crossing(p, d, radius)
    rays = RayBatch.from_arrays(p, d)
    trace_packed(get_kernel(backend), rays, S[:1], kinds[:1], clip=True, fresnel=False, end_z=None)
    through = np.isfinite(want[:, 0]) & (np.hypot(want[:, 0], want[:, 1]) < sd * (1 - 1e-9))
    assert through.sum() > 10_000
    assert rays.ok[through].all(), f"{(~rays.ok[through]).sum()} rays that pass the clear aperture were stopped"
    got = np.stack([rays.x, rays.y, rays.z], axis=1)[through]
    assert np.abs(got - want[through]).max() < 1e-9 * max(distance, 1.0)
