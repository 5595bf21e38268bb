"""Memory of a large bokeh: 1e8 rays through dgauss.50mm, accumulated in chunks.

Goal (issue 5): under 1 GB. Prints the peak resident memory of this process and the time.
    .venv/bin/python benchmarks/bokeh_memory.py [--rays 100000000]
"""

import argparse
import resource
import time

from physcam.analysis.defocus.bokeh import bokeh_image
from physcam.lens.library import load_lens
from physcam.optics import focusing
from physcam.optics.state import camera_state


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=100_000_000)
    args = ap.parse_args()
    lens = load_lens("dgauss_50mm")
    st = focusing.focus(lens, 3000.0)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    t = time.perf_counter()
    res = bokeh_image(camera_state(st.prescription, film_z=st.film_z), 1200.0, 250.0, 150.0, rays=args.rays, pixels=512,
                      spectral=True)
    dt = time.perf_counter() - t
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"bokeh: {args.rays:,} rays ({res.rays_passed:,} reach the film) in {dt:.1f} s "
          f"= {args.rays / dt / 1e6:.2f} M rays/s")
    print(f"peak resident memory {peak:.0f} MiB (before tracing {before:.0f} MiB); goal 1024 MiB: "
          f"ratio {peak / 1024:.2f} ({'met' if peak < 1024 else 'NOT met'})")


if __name__ == "__main__":
    main()
