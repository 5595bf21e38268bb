"""Benchmark: ``physcam defocus`` of a 2048 x 1080 frame with a full depth range (issues 34, 42, 47).

A synthetic frame: a ground plane whose depth runs from 0.6 m to 60.6 m down the frame (depth by
row), a sky at infinity above it, a checker texture, and 20 small bright spots at random depths. The
double Gauss 50 mm focused at 2 m, f/2.8, on a 36 mm wide sensor. Prints, in CPU seconds of this
process (the machine is shared: the load average is printed too), the cold time (kernels traced
into an empty cache: the goal is under 10 s, issue 47) and the warm time (the next frame of the
shot, its kernels from the cache), the kernels and rays traced, and the light kept.

``--interpolation-check`` also defocuses the frame with every kernel traced where it is used (each
tile corner's own fan at its depth node's own depth: no field or depth-ladder interpolation) and
prints the largest difference, in per cent of the picture's peak (issue 47: under 0.5 %).
``--baseline-src DIR`` runs the same frame through another checkout (``DIR/src``, e.g. ``main``
before this change) in a fresh process first, and prints the ratios, measured side by side.

    python benchmarks/defocus.py [--width 2048 --height 1080 --tile 64 --kernel-cache DIR --profile]
                                 [--interpolation-check] [--baseline-src /path/to/checkout]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np


def frame(w, h, seed=0):
    rng = np.random.default_rng(seed)
    ys, xs = np.indices((h, w))
    img = np.where(((xs // 32) + (ys // 32)) % 2, 0.8, 0.1).astype(np.float32)[..., None].repeat(3, axis=2)
    z = 0.6 + 60.0 * (ys / h) ** 4  # metres: 0.6 m at the top row of the ground, 60.6 m at the bottom
    z[: h // 5] = 1e10  # sky
    for _ in range(20):
        x, y = rng.integers(0, w), rng.integers(0, h)
        img[y, x] = 50.0
        z[y, x] = rng.uniform(0.6, 20.0)
    return img, z


def run(width, height, tile, kernel_cache=None):
    """Cold and warm CPU seconds of one frame (a fresh process's first and second defocus)."""
    from physcam.analysis.defocus.render import defocus, inverse_depth
    from physcam.analysis.defocus.kernels import KernelCache, defocus_camera
    from physcam.lens.library import load_lens
    from physcam.optics.state import camera_state

    state = camera_state(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=2.8, sensor_mm=(36.0, 36.0 * height / width))
    cam = defocus_camera(state, width=width, height=height, tile=tile)  # (the defocus reads the sensor's width)
    img, z = frame(width, height)
    u = inverse_depth(z, cam)
    cache = KernelCache(cam, kernel_cache)
    t = time.process_time()
    out = defocus(img, u, cache)
    cold = time.process_time() - t
    t = time.process_time()
    defocus(img, u, cache)
    warm = time.process_time() - t
    return {"cold_cpu_s": cold, "warm_cpu_s": warm, "kernels_traced": cache.traced, "kernels_loaded": cache.loaded,
            "light_in": float(img.sum()), "light_out": float(out.sum()), "peak": float(out.max())}, (cam, img, u, out)


def interpolation_check(cam, img, u, out):
    """The largest difference (per cent of the peak) between ``out`` and the frame defocused with every
    kernel traced where it is used (module notes)."""
    from physcam.analysis.defocus.render import defocus
    from physcam.analysis.defocus.kernels import KernelCache

    class Traced(KernelCache):
        """Every tile corner's kernel traced at its own position and its node's own depth."""

        def tile_kernel(self, x, y, n):
            key = (round(float(x), 3), round(float(y), 3), int(n))
            if key not in self._tiles:
                v = float(self.camera.node_u(n))
                k = self.camera.kernels([(x, y, 1.0 / max(v, 1e-7))])[0].image
                self._tiles[key] = (k / k.sum(axis=(0, 1), keepdims=True)).astype(np.float32)
            return self._tiles[key]

    ref = defocus(img, u, Traced(cam))
    return float(np.abs(out - ref).max() / ref.max() * 100.0), float(np.abs(out - ref).mean() / ref.max() * 100.0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--width", type=int, default=2048)
    ap.add_argument("--height", type=int, default=1080)
    ap.add_argument("--tile", type=int, default=64)
    ap.add_argument("--kernel-cache", default=None, help="a folder: kernels kept across runs")
    ap.add_argument("--profile", action="store_true", help="cProfile a warm run (top 25 by own CPU time)")
    ap.add_argument("--interpolation-check", action="store_true", help="compare with kernels traced everywhere")
    ap.add_argument("--baseline-src", default=None, help="another checkout to time side by side (its src/)")
    ap.add_argument("--json-only", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.json_only:  # the child of --baseline-src
        print(json.dumps(run(a.width, a.height, a.tile)[0]))
        return
    print(f"load average {os.getloadavg()[0]:.1f} {os.getloadavg()[1]:.1f} {os.getloadavg()[2]:.1f} "
          f"on {os.cpu_count()} CPUs (a shared machine: CPU seconds of this process)")
    base = None
    if a.baseline_src:
        env = dict(os.environ, PYTHONPATH=os.path.join(a.baseline_src, "src"))
        p = subprocess.run([sys.executable, __file__, "--json-only", "--width", str(a.width), "--height",
                            str(a.height), "--tile", str(a.tile)], capture_output=True, text=True, env=env, check=True)
        base = json.loads(p.stdout.strip().splitlines()[-1])
        print(f"baseline ({a.baseline_src}): cold {base['cold_cpu_s']:.2f} s, warm {base['warm_cpu_s']:.2f} s CPU, "
              f"{base['kernels_traced']} kernels traced")
    res, (cam, img, u, out) = run(a.width, a.height, a.tile, a.kernel_cache)
    print(f"{a.width} x {a.height}: cold (kernels traced) {res['cold_cpu_s']:.2f} s CPU, {res['kernels_traced']} node "
          f"kernels; warm (kernel cache) {res['warm_cpu_s']:.2f} s CPU")
    print(f"light: in {res['light_in']:.0f}, out {res['light_out']:.0f} ({res['light_out'] / res['light_in']:.4f}: the "
          f"lens's relative illumination and the spots' occlusion)")
    if base:
        print(f"ratios (baseline / this): cold {base['cold_cpu_s'] / res['cold_cpu_s']:.1f}x, warm "
              f"{base['warm_cpu_s'] / res['warm_cpu_s']:.2f}x")
    if a.interpolation_check:
        mx, mean = interpolation_check(cam, img, u, out)
        print(f"interpolated kernels against kernels traced everywhere: largest difference {mx:.3f} % of the peak, "
              f"mean {mean:.4f} %")
    if a.profile:
        import cProfile
        import pstats

        from physcam.analysis.defocus.render import defocus
        from physcam.analysis.defocus.kernels import KernelCache

        cache = KernelCache(cam)
        defocus(img, u, cache)
        pr = cProfile.Profile(time.process_time)
        pr.runcall(defocus, img, u, cache)
        pstats.Stats(pr).sort_stats("tottime").print_stats(25)


if __name__ == "__main__":
    main()
