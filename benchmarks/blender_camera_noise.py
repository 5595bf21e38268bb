"""Benchmark: the extension camera's own noise, a white world and nothing else (the built-in camera
renders it without noise), so what shows is where the camera's aims miss the lens: the pupil tables'
untrusted cells take one aim per ray, each miss a dark sample (issue 41, round 9).
Run in the Blender environment (make blender):

    .venv-blender/bin/python benchmarks/blender_camera_noise.py [--fstop 2.8] [--samples 16]
        [--checkout <another checkout>] [--pupil-stride 1]

Double Gauss, focus 2.5 m, full frame, 240 x 160 px (benchmarks/blender_render.py's set-up, from
``--checkout``'s copy of it and its physcam: a side by side with main). Prints the extension build's CPU
seconds and the pixel noise: the RMS of two seeds' difference over sqrt(2), over the mean (RGB, pixels
above 5 % of the mean). ``--pupil-stride 1``: the pupil tables traced at every focus mark.
"""

from __future__ import annotations

import argparse
import glob
import os
import runpy
import sys
import tempfile
import time
import zipfile
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fstop", type=float, default=2.8)
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--checkout", default=str(Path(__file__).resolve().parents[1]))
    ap.add_argument("--pupil-stride", type=int)
    args = ap.parse_args()
    bench = runpy.run_path(str(Path(args.checkout) / "benchmarks/blender_render.py"), run_name="bench")  # puts its src first
    import bpy
    import numpy as np

    for p in glob.glob(bpy.utils.resource_path("LOCAL") + "/python/lib/python3*/site-packages"):
        sys.path.insert(0, p)
    import physcam.export.blender_focus as bf
    from physcam.export.blender_extension import build_extension
    from physcam.export.blender_variant import variant_source
    from physcam.lens.library import load_lens

    if args.pupil_stride:
        bf.PUPIL_STRIDE = args.pupil_stride
    slug = "dgauss_50mm"
    tmp = Path(tempfile.mkdtemp())
    t0 = time.process_time()
    with zipfile.ZipFile(build_extension(tmp, lenses=[slug])) as z:  # dispersion and Fresnel off, as the add-on writes it
        ext_src = variant_source(z.read(f"shaders/{slug}.osl").decode(), dispersion=False, fresnel=False)
    build = time.process_time() - t0
    scene = bpy.context.scene
    bench["_common"](scene, 1.0)
    scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bench["_cameras"](load_lens(slug), slug, args.fstop, tmp, ext_src)["extension"](scene)
    runs = [bench["_render"](scene, tmp / f"white_{seed}.exr", args.samples, seed) for seed in (0, 1)]
    a, b = (r[1].reshape(-1, 4)[:, :3] for r in runs)
    mean = 0.5 * (a + b)
    lit = mean.mean(axis=1) > 0.05 * mean.mean()
    noise = np.sqrt(((a - b)[lit] ** 2).mean() / 2) / mean[lit].mean()
    print(f"{bf.__file__}: pupil stride {bf.PUPIL_STRIDE}; extension build {build:.2f} s CPU; f/{args.fstop:g}, "
          f"{args.samples} samples: {0.5 * (runs[0][0] + runs[1][0]):.2f} s CPU per render, pixel noise {noise:.4f}; "
          f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
