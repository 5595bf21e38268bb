"""Benchmark: ``physcam defocus`` of a 2048 x 1080 frame with a full depth range (issue 34).

A synthetic frame: a ground plane receding from 0.6 m to infinity (depth by row), a checker
texture, and 20 small bright spots at random depths. The double Gauss 50 mm focused at 2 m, f/2.8,
on a 36 mm wide sensor. Prints the cold time (kernels traced into an empty cache) and the warm time
(the next frame of the shot, kernels from the cache): the goal is the warm time under 10 s.

    python benchmarks/defocus.py [--width 2048 --height 1080 --tile 64 --step-rel 0.05 --kernel-cache DIR --profile]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from physcam.analysis.defocus.render import defocus, inverse_depth
from physcam.analysis.defocus.kernels import KernelCache, defocus_camera
from physcam.lens.library import load_lens


def frame(w, h, seed=0):
    rng = np.random.default_rng(seed)
    ys, xs = np.indices((h, w))
    img = np.where(((xs // 32) + (ys // 32)) % 2, 0.8, 0.1).astype(np.float32)[..., None].repeat(3, axis=2)
    z = 0.6 + 60.0 * (ys / h) ** 4  # metres: the top row far, the bottom near
    z[: h // 5] = 1e10  # sky
    for _ in range(20):
        x, y = rng.integers(0, w), rng.integers(0, h)
        img[y, x] = 50.0
        z[y, x] = rng.uniform(0.6, 20.0)
    return img, z


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--width", type=int, default=2048)
    ap.add_argument("--height", type=int, default=1080)
    ap.add_argument("--tile", type=int, default=64)
    ap.add_argument("--step-rel", type=float, default=0.05)
    ap.add_argument("--kernel-cache", default=None, help="a folder: kernels kept across runs")
    ap.add_argument("--profile", action="store_true", help="cProfile the warm run (top 25 by own time)")
    a = ap.parse_args()
    cam = defocus_camera(load_lens("dgauss_50mm"), focus_mm=2000.0, fstop=2.8, sensor_width_mm=36.0, width=a.width,
                         height=a.height, tile=a.tile, step_rel=a.step_rel)
    img, z = frame(a.width, a.height)
    u = inverse_depth(z, cam)
    cache = KernelCache(cam, a.kernel_cache)
    print(f"{int(np.floor(cam.node_index(1 / 600.0))) + 1 - cam.node_far() + 1} depth nodes")
    print(f"blur from {cam.blur_px(600.0):.1f} px (0.6 m) to {cam.blur_px(1e9):.1f} px (infinity)")
    for label in ("cold (kernels traced)", "warm (kernel cache)"):
        t0 = time.perf_counter()
        defocus(img, u, cache)
        print(f"{label}: {time.perf_counter() - t0:.2f} s; kernels traced so far {cache.traced}, loaded {cache.loaded}")
    if a.profile:
        import cProfile
        import pstats

        pr = cProfile.Profile()
        pr.runcall(defocus, img, u, cache)
        pstats.Stats(pr).sort_stats("tottime").print_stats(25)


if __name__ == "__main__":
    main()
