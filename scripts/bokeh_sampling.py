"""How clean is a bokeh image for its ray count? Low-discrepancy (the default) against random rays.

    .venv/bin/python scripts/bokeh_sampling.py [--lens dgauss_50mm] [--reference-rays 32000000]

For `physcam bokeh`'s default scene (the lens focused at infinity, a light on the axis 1 m from
the film, 256 x 256 pixels), prints the RMS error over the pixels brighter than a fifth of the
peak, relative to their mean, and the L1 error relative to the total, against a reference image
of many rays (low-discrepancy with another seed), for physcam's sampling and for independent
uniform random rays (the sampling before, built here with the same ray arithmetic), and the
Poisson expectation 1 / sqrt(rays per pixel) for random rays.
"""

import argparse
import math
import time

import numpy as np

from physcam.analysis.defocus.bokeh import bokeh_image
from physcam.lens.library import load_lens
from physcam.optics import focusing
from physcam.optics.state import camera_state
from physcam.trace import RayBatch, trace_to_film


def random_image(lens, film_z, depth, n, extent, pixels, seed):
    """The same picture from independent uniform random points on the front element."""
    rng = np.random.default_rng(seed)
    z_src = film_z - depth
    r = lens.surfaces[0].semi_diameter * np.sqrt(rng.random(n))
    phi = 2 * np.pi * rng.random(n)
    d = np.stack([r * np.cos(phi), r * np.sin(phi), np.full(n, -z_src)])
    d /= np.linalg.norm(d, axis=0)
    b = RayBatch(np.zeros(n), np.zeros(n), np.full(n, z_src), d[0], d[1], d[2], np.full(n, lens.wavelength_nm),
                 d[2] ** 3, np.zeros(n, dtype=np.uint8))
    out = trace_to_film(lens, b, film_z)
    x0, x1, y0, y1 = extent
    ix = np.floor((out.x - x0) / (x1 - x0) * pixels).astype(np.int64)
    iy = np.floor((out.y - y0) / (y1 - y0) * pixels).astype(np.int64)
    ok = out.ok & (ix >= 0) & (ix < pixels) & (iy >= 0) & (iy < pixels)
    return np.bincount(iy[ok] * pixels + ix[ok], weights=out.weight[ok], minlength=pixels * pixels).reshape(pixels, pixels)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lens", default="dgauss_50mm")
    ap.add_argument("--reference-rays", type=int, default=32_000_000)
    args = ap.parse_args()
    lens = load_lens(args.lens)
    st = focusing.focus(lens, math.inf)
    depth, pixels = 1000.0, 256
    t0 = time.perf_counter()
    cam = camera_state(st.prescription, film_z=st.film_z)
    ref = bokeh_image(cam, depth, rays=args.reference_rays, pixels=pixels, seed=12345)
    extent = ref.extent_mm
    R = ref.image[..., 0]
    mask = R > 0.2 * R.max()
    lit = int(mask.sum())
    print(f"{lens.name}: light 1 m on axis, focus infinity, {pixels} x {pixels} px; reference "
          f"{args.reference_rays:.3g} rays ({time.perf_counter() - t0:.1f} s); {lit} pixels above a fifth of the peak")

    def err(img):
        img = img / img.sum() * R.sum()
        return (float(np.sqrt(np.mean((img[mask] - R[mask]) ** 2)) / R[mask].mean()),
                float(np.abs(img - R).sum() / R.sum()))

    print(f"{'rays':>10} | {'low-discrepancy RMS':>20} {'L1':>6} | {'random RMS':>11} {'L1':>6} | Poisson 1/sqrt(rays/px)")
    for n in (250_000, 500_000, 1_000_000, 4_000_000):
        q = bokeh_image(cam, depth, rays=n, pixels=pixels, extent_mm=extent, seed=1)
        rnd = random_image(st.prescription, st.film_z, depth, n, extent, pixels, seed=1)
        per_px = n * (q.rays_passed / n) * float(q.image[..., 0][mask].sum() / q.image[..., 0].sum()) / lit
        eq, lq = err(q.image[..., 0])
        er, lr = err(rnd)
        print(f"{n:>10,} | {eq:>20.4f} {lq:>6.3f} | {er:>11.4f} {lr:>6.3f} | {1 / math.sqrt(per_px):.4f}")


if __name__ == "__main__":
    main()
