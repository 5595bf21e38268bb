"""Benchmark: where the CPU time of a Cycles render through the extension's OSL camera goes, a fixed
cost per render against a cost per sample (issue 41, the price of a sample). Run in the Blender
environment (make blender):

    .venv-blender/bin/python benchmarks/blender_camera_price.py [--scene outdoor] [--fstop 2.8] [--samples 1 8 32 64]

Part 1, per camera: the scene of ``benchmarks/blender_render.py`` rendered at each sample count (seed 0,
240 x 160 px, 2 threads, CPU seconds of the process), and a line fitted through them: its intercept is
what a render pays once (scene sync, the OSL shader's load, runtime optimisation and LLVM JIT), its
slope what a sample costs. Cameras: the built-in one with Cycles' own shading (SVM) and with OSL
shading, a pinhole written in OSL (the floor of any OSL camera) and the extension's shader.

Part 2, the extension's work alone: its shader with the pinhole's rays written out at the end (each
output plus 1e-30 times the traced one, so nothing the shader computes is optimised away but the picture,
hence the scene's cost, is the pinhole's), then without the lens trace (the surface loop runs no
step), then also without the pupil ellipse's table reads. The differences to the pinhole are the
shader's own cost: fixed and per sample, per part.
"""

from __future__ import annotations

import argparse
import glob
import os
import sys
import tempfile
import zipfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import blender_render as br  # noqa: E402  (the scenes and cameras of the equal-noise benchmark)

PINHOLE = """shader physcam_pinhole(output point position = point(0, 0, 0), output vector direction = vector(0, 0, 1),
                       output color throughput = color(0))
{
    // the built-in camera's frame without its lens: 36 x 24 mm at 50 mm (the double Gauss's focal length)
    point rs = camera_shader_raster_position();
    position = point(0, 0, 0);
    direction = normalize(vector((2.0 * rs[0] - 1.0) * 0.36, (2.0 * rs[1] - 1.0) * 0.24, 1.0));
    throughput = color(1);
}
"""
_PIN_RAYS = ("position = point(0, 0, 0); direction = normalize(vector((2.0 * rs[0] - 1.0) * 0.36, "
             "(2.0 * rs[1] - 1.0) * 0.24, 1.0)); throughput = color(1);")


def _swap(text: str, old: str, new: str) -> str:
    if text.count(old) != 1:
        raise SystemExit(f"the extension's shader no longer has one {old.strip()[:60]!r}: update this benchmark")
    return text.replace(old, new)


def work_variants(src: str) -> dict[str, str]:
    """The extension's shader rendering the pinhole's rays: all its work, without the trace, and also
    without the pupil ellipse (its table reads)."""
    a = _swap(src, "    throughput = color(0);\n", f"    {_PIN_RAYS}\n")
    a = _swap(a, "    position = point(ray_in[0], ray_in[1], ray_in[2]);\n",
              "    position = position + 1e-30 * point(ray_in[0], ray_in[1], ray_in[2]);\n")
    a = _swap(a, "    direction = vector(ray_in[3], ray_in[4], ray_in[5])",
              "    direction = direction + 1e-30 * vector(ray_in[3], ray_in[4], ray_in[5])")
    a = _swap(a, "    throughput = color(w);\n", "    throughput = color(1.0 + 1e-30 * w);\n")
    b = _swap(a, "for (int q = 0; q < n_steps; q++) {", "for (int q = 0; q < 0; q++) {")
    i = b.index("    if (rho < RAD_MAX) {")
    j = b.index("    } else {\n        x0 = -SEMI[0]; x1 = SEMI[0]; y0 = -SEMI[0]; y1 = SEMI[0];", i)
    c = b[:i] + "    if (rho < RAD_MAX) {\n        pax = 5.0 + 1e-30 * rho; pay = 5.0; sample_area = M_PI * pax * pay;\n" + b[j:]
    return {"extension's work, pinhole rays": a, "  without the trace": b, "  without the trace and the ellipse": c}


def _fit(samples, seconds) -> tuple[float, float]:
    import numpy as np

    slope, intercept = np.polyfit(np.asarray(samples, float), np.asarray(seconds, float), 1)
    return float(intercept), float(slope)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lens", default="dgauss_50mm")
    ap.add_argument("--scene", default="outdoor", choices=list(br.SCENES))
    ap.add_argument("--fstop", type=float, default=2.8)
    ap.add_argument("--samples", type=int, nargs="+", default=[1, 8, 32, 64])
    args = ap.parse_args()
    import bpy

    for p in glob.glob(bpy.utils.resource_path("LOCAL") + "/python/lib/python3*/site-packages"):
        sys.path.insert(0, p)
    from physcam.export.blender_extension import build_extension
    from physcam.export.blender_variant import variant_source
    from physcam.lens.library import load_lens

    lens, slug, tmp = load_lens(args.lens), Path(args.lens).stem, Path(tempfile.mkdtemp())
    with zipfile.ZipFile(build_extension(tmp, lenses=[args.lens])) as z:  # dispersion and Fresnel off, as the add-on writes it
        ext_src = variant_source(z.read(f"shaders/{slug}.osl").decode(), dispersion=False, fresnel=False)
    scene = bpy.context.scene
    br.SCENES[args.scene](scene)

    def with_shader(src):
        def setup(sc):
            cams = br._cameras(lens, slug, args.fstop, tmp, src)
            cams["extension"](sc)
        return setup

    def builtin_osl(sc):
        cams["builtin"](sc)
        sc.cycles.shading_system = True

    cams = br._cameras(lens, slug, args.fstop, tmp, ext_src)
    setups = {"built-in (SVM shading)": cams["builtin"], "built-in (OSL shading)": builtin_osl,
              "pinhole in OSL": with_shader(PINHOLE), "extension": with_shader(ext_src)}
    setups.update({k: with_shader(v) for k, v in work_variants(ext_src).items()})
    n = args.samples
    print(f"{args.scene}, f/{args.fstop:g}, {lens.name}, {br.W} x {br.H} px, 2 threads; load average "
          f"{os.getloadavg()[0]:.1f} (1 min), {os.cpu_count()} CPUs; CPU s of the process per render")
    print("| camera | " + " | ".join(f"{k} samples" for k in n) + " | fixed (intercept) | per sample (slope) | fitted at 32 |")
    print("| --- |" + " --- |" * (len(n) + 3))
    for name, setup in setups.items():
        setup(scene)
        ts = [br._render(scene, tmp / f"r_{k}.exr", k, 0)[0] for k in n]
        c, s = _fit(n, ts)
        print(f"| {name} | " + " | ".join(f"{t:.2f}" for t in ts) + f" | {c:.2f} s | {1000 * s:.1f} ms | {c + 32 * s:.2f} s |",
              flush=True)
    print(f"load average at the end {os.getloadavg()[0]:.1f} (1 min)")


if __name__ == "__main__":
    main()
