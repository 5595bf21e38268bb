"""Ray-tracing throughput: 1e6 on-axis collimated rays through pbrt's dgauss.50mm to the image plane.

Run:  .venv/bin/python benchmarks/trace.py [--rays 1000000] [--repeat 5]

The rays fill the entrance pupil (radius found by bisection on the marginal ray) uniformly at
random. Cases: monochrome (d line) with clipping on; dispersion (400-700 nm, Abbe numbers
assumed below since pbrt's .dat has none) plus Fresnel transmission. The JIT is warmed first;
the best of ``--repeat`` runs of the public ``trace_to_film`` call is reported, copying the batch
(the default) and in place (``in_place=True`` on a copy made outside the timing).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from physcam.lens.prescription import LensMetadata, Medium, Prescription, Surface
from physcam.trace import RayBatch, paraxial_image_z, trace_through, trace_to_film

ROWS = [  # radius thickness index aperture-diameter (pbrt-v4 scenes/lenses/dgauss.50mm.dat)
    (29.475, 3.76, 1.67, 25.2), (84.83, 0.12, 1.0, 25.2), (19.275, 4.025, 1.67, 23.0),
    (40.77, 3.275, 1.699, 23.0), (12.75, 5.705, 1.0, 18.0), (0.0, 4.5, 0.0, 17.1),
    (-14.495, 1.18, 1.603, 17.0), (40.77, 6.065, 1.658, 20.0), (-20.385, 0.19, 1.0, 20.0),
    (437.065, 3.22, 1.717, 20.0), (-39.73, 0.0, 1.0, 20.0),
]
ABBE = {1.67: 47.2, 1.699: 30.1, 1.603: 38.0, 1.658: 57.3, 1.717: 47.9}  # assumed, typical glasses


def dgauss() -> Prescription:
    s = []
    for r, t, n, ap in ROWS:
        n = 1.0 if n == 0 else n
        s.append(Surface(r, t, Medium(n, ABBE.get(n, 0.0)), ap / 2, "stop" if r == 0 else "spherical"))
    return Prescription(tuple(s), LensMetadata(name="dgauss.50mm")).validate()


def entrance_pupil_radius(lens) -> float:
    lo, hi = 0.0, lens.surfaces[0].semi_diameter
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        ok = trace_through(lens, RayBatch.collimated([0.0], [mid], -1.0), backend="numpy").ok[0]
        lo, hi = (mid, hi) if ok else (lo, mid)
    return lo


def rate(lens, rays, film_z, backend, repeat, in_place=False, **kw) -> float:
    """Rays per second, best of ``repeat``. ``in_place``: trace a fresh copy made outside the
    timing (a renderer tracing the batch it generated); else the call copies the batch itself."""
    best = float("inf")
    for _ in range(repeat):
        batch = rays.copy() if in_place else rays
        t = time.perf_counter()
        trace_to_film(lens, batch, film_z, backend=backend, in_place=in_place, **kw)
        best = min(best, time.perf_counter() - t)
    return len(rays) / best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    lens = dgauss()
    film = paraxial_image_z(lens)
    rep = entrance_pupil_radius(lens)
    rng = np.random.default_rng(0)
    r = rep * np.sqrt(rng.random(args.rays))
    phi = 2 * np.pi * rng.random(args.rays)
    mono = RayBatch.collimated(r * np.cos(phi), r * np.sin(phi), -1.0)
    colour = mono.copy()
    colour.wavelength_nm[:] = rng.uniform(400.0, 700.0, args.rays)
    trace_to_film(lens, mono.take(slice(0, 1000)), film, backend="numba", fresnel=True)  # warm the JIT
    trace_to_film(lens, colour.take(slice(0, 1000)), film, backend="numba", fresnel=True)
    print(f"dgauss.50mm, {args.rays:,} rays, entrance pupil radius {rep:.4f} mm, film at z = {film:.4f} mm")
    res = {}
    for name, rays, kw in (("monochrome, clipping", mono, {}), ("dispersion + Fresnel", colour, {"fresnel": True})):
        for be in ("numba", "numpy"):
            res[name, be] = rate(lens, rays, film, be, args.repeat if be == "numba" else 2, **kw)
            print(f"  {name:22s} {be:6s} {res[name, be] / 1e6:7.2f} M rays/s")
        print(f"  {name:22s} numba/numpy {res[name, 'numba'] / res[name, 'numpy']:.1f}x")
    m, c = res["monochrome, clipping", "numba"], res["dispersion + Fresnel", "numba"]
    print(f"  dispersion + Fresnel costs {m / c:.2f}x the monochrome time (numba)")
    # the copy of the batch (9 fresh arrays, page faults included) is serial work outside the
    # kernel; tracing in place shows the kernel's own rate
    for name, rays, kw in (("monochrome, clipping", mono, {}), ("dispersion + Fresnel", colour, {"fresnel": True})):
        r = rate(lens, rays, film, "numba", args.repeat, in_place=True, **kw)
        print(f"  {name:22s} numba, in place {r / 1e6:7.2f} M rays/s")
    print(f"  goals: monochrome {m / 4e6:.2f} x 4 M rays/s, dispersion + Fresnel {c / 2e6:.2f} x 2 M rays/s "
          "(copying the batch)")


if __name__ == "__main__":
    main()
