"""Ray-tracing throughput: physcam's compiled kernels beside a branch-free, auto-vectorised C loop of the same work.

Run:  .venv/bin/python benchmarks/trace.py [--rays 1000000] [--repeat 7] [--no-c] [--backends c,numba]

The work (shared/bench/limit_soa.c, mode 1 "simd"): 1e6 on-axis collimated rays filling a disk of
radius 12.40255 mm, generated before the clock starts, traced in place through pbrt's
dgauss.50mm (sphere intersections, clipping at every clear semi-diameter, vector Snell, TIR
check) to the paraxial image plane; one wavelength (the d line), no Fresnel. The C reference is
compiled here with ``gcc -O3 -march=native -fno-math-errno -fopenmp`` when gcc is present (it
auto-vectorises to AVX-512 on this machine) and run in the same process tree, alternating with
physcam, on 1 and 2 threads (``OMP_NUM_THREADS``, ``physcam.trace.kernels.set_threads``): other jobs share
this machine, so the ratio physcam / C of one run is the figure that counts. Both print the RMS
spot radius as a check that they did the same work.

physcam's kernels are its two compiled ones, each where this install has it: the C kernel built with the
package (``c``, ahead of time, for the instruction set the CPU has: its line names it) and the numba JIT kernel
(``numba``, the ``fast`` extra); they alternate with the C reference run by run.

Then physcam alone, per kernel: the public ``trace_to_film`` copying the batch, dispersion (400-700 nm)
plus Fresnel, and float32 rays; the numpy reference kernel. The stretch goal is 25 % of the arithmetic
ceiling (about 790 flops, 20 square roots and 12 divisions per ray: 25 M rays/s per core).
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from physcam.lens.prescription import LensMetadata, Medium, Prescription, Surface
from physcam.trace import RayBatch, paraxial_image_z, trace_to_film
from physcam.trace import kernels
from physcam.trace.kernels import c_available, numba_available

ROWS = [  # radius thickness index aperture-diameter (pbrt-v4 scenes/lenses/dgauss.50mm.dat)
    (29.475, 3.76, 1.67, 25.2), (84.83, 0.12, 1.0, 25.2), (19.275, 4.025, 1.67, 23.0),
    (40.77, 3.275, 1.699, 23.0), (12.75, 5.705, 1.0, 18.0), (0.0, 4.5, 0.0, 17.1),
    (-14.495, 1.18, 1.603, 17.0), (40.77, 6.065, 1.658, 20.0), (-20.385, 0.19, 1.0, 20.0),
    (437.065, 3.22, 1.717, 20.0), (-39.73, 0.0, 1.0, 20.0),
]
ABBE = {1.67: 47.2, 1.699: 30.1, 1.603: 38.0, 1.658: 57.3, 1.717: 47.9}  # assumed, typical glasses
BEAM_MM = 12.40255  # the C reference's beam radius (every ray passes)


def _c_source() -> Path:
    """shared/bench/limit_soa.c in the nearest folder above this checkout that has it (the repository's
    parent, or its parent's parent for a worktree under wt/); ``PHYSCAM_C_REFERENCE`` overrides."""
    if os.environ.get("PHYSCAM_C_REFERENCE"):
        return Path(os.environ["PHYSCAM_C_REFERENCE"])
    here = Path(__file__).resolve().parent
    for up in here.parents:
        cand = up / "shared" / "bench" / "limit_soa.c"
        if cand.exists():
            return cand
    return here.parents[1] / "shared" / "bench" / "limit_soa.c"


C_SOURCE = _c_source()
CEILING_PER_CORE = 100e6  # rays/s: ~790 flops + 20 sqrt + 12 div per ray at this core's peak (issue 14)


def dgauss() -> Prescription:
    s = []
    for r, t, n, ap in ROWS:
        n = 1.0 if n == 0 else n
        s.append(Surface(r, t, Medium(n, ABBE.get(n, 0.0)), ap / 2, "stop" if r == 0 else "spherical"))
    return Prescription(tuple(s), LensMetadata(name="dgauss.50mm")).validate()


def _xorshift_disk(n, radius):
    """The C reference's rays: xorshift64 (seed 0x9E3779B97F4A7C15), r = R sqrt(u1), theta = 2 pi u2,
    so both trace the same points (their RMS spots agree to rounding). Compiled by numba where installed."""
    if numba_available():
        import numba

        return numba.njit(cache=False)(_xorshift_loop)(n, radius)
    with np.errstate(over="ignore"):
        return _xorshift_loop(n, radius)


def _xorshift_loop(n, radius):
    s = np.uint64(0x9E3779B97F4A7C15)
    x = np.empty(n)
    y = np.empty(n)
    for k in range(n):
        s ^= s << np.uint64(13)
        s ^= s >> np.uint64(7)
        s ^= s << np.uint64(17)
        u1 = (s >> np.uint64(11)) * (1.0 / 9007199254740992.0)
        s ^= s << np.uint64(13)
        s ^= s >> np.uint64(7)
        s ^= s << np.uint64(17)
        u2 = (s >> np.uint64(11)) * (1.0 / 9007199254740992.0)
        r = radius * np.sqrt(u1)
        th = 2 * np.pi * u2
        x[k] = r * np.cos(th)
        y[k] = r * np.sin(th)
    return x, y


def load() -> str:
    return ", ".join(f"{v:.2f}" for v in os.getloadavg())


def build_c(src: Path) -> Path | None:
    gcc = shutil.which("gcc")
    if gcc is None or not src.exists():
        return None
    out = Path(tempfile.mkdtemp(prefix="physcam-bench-")) / "limit_soa"
    cmd = [gcc, "-O3", "-march=native", "-fno-math-errno", "-fopenmp", str(src), "-o", str(out), "-lm"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        print(f"  (gcc failed: {r.stderr.strip()[:200]})")
        return None
    return out


def run_c(exe: Path, n: int, threads: int, repeat: int) -> tuple[float, float]:
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    r = subprocess.run([str(exe), str(n), "1", str(repeat)], capture_output=True, text=True, env=env, check=True)
    m = re.search(r"rays_per_s=([0-9.e+]+) rms_um=([0-9.]+)", r.stdout)
    return float(m.group(1)), float(m.group(2))


def _timed(fn) -> float:
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def rms_um(b: RayBatch) -> float:
    ok = b.ok
    x, y = b.x[ok], b.y[ok]
    return float(1e3 * np.sqrt(((x - x.mean()) ** 2 + (y - y.mean()) ** 2).mean()))


def rate(lens, rays, film_z, repeat, *, in_place=True, **kw) -> tuple[float, RayBatch]:
    """Rays per second, best of ``repeat``. ``in_place``: trace a copy made outside the timing
    (as the C loop traces arrays generated before its clock starts)."""
    best, out = float("inf"), None
    for _ in range(repeat):
        batch = rays.copy() if in_place else rays
        t = time.perf_counter()
        out = trace_to_film(lens, batch, film_z, in_place=in_place, **kw)
        best = min(best, time.perf_counter() - t)
    return len(rays) / best, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--no-c", action="store_true", help="skip the C reference")
    ap.add_argument("--backends", default="c,numba", help="physcam's compiled kernels to run, those installed")
    ap.add_argument("--isa", help="the C kernel's instruction set (one of _c.isa_levels(): a CPU without AVX-512)")
    ap.add_argument("--c-source", type=Path, default=C_SOURCE, help=f"the C reference (default {C_SOURCE})")
    args = ap.parse_args()
    lens = dgauss()
    film = paraxial_image_z(lens)
    rng = np.random.default_rng(0)
    mono = RayBatch.collimated(*_xorshift_disk(args.rays, BEAM_MM), -1.0)
    colour = mono.copy()
    colour.wavelength_nm[:] = rng.uniform(400.0, 700.0, args.rays)
    backends = [b for b in args.backends.split(",") if b and {"c": c_available, "numba": numba_available}[b]()]
    kernels.LOAD_AWARE = False  # the thread counts below are the ones asked for, busy machine or not
    for be in backends:  # warm the JIT (or load it from the cache); the C kernel needs nothing
        for b in (mono, colour, mono.astype(np.float32)):
            trace_to_film(lens, b.take(slice(0, 5000)), film, fresnel=True, backend=be)
            trace_to_film(lens, b.take(slice(0, 5000)), film, backend=be)
    mono32 = mono.astype(np.float32)
    exe = None if args.no_c else build_c(args.c_source)
    print(f"dgauss.50mm, {args.rays:,} rays, beam radius {BEAM_MM} mm, film at z = {film:.4f} mm")
    if exe is not None:
        print(f"C reference: {args.c_source}")
    if "c" in backends:
        from physcam.trace.kernels import _c

        if args.isa:
            _c.set_isa(args.isa)
        print(f"physcam's C kernel: instruction set {_c.isa()} (of {', '.join(_c.isa_levels())})")
    print(f"machine: {os.cpu_count()} cores, load average {load()} at start")
    nmax = kernels.threads()
    for threads in (1, 2):
        if threads > nmax:
            continue
        kernels.set_threads(threads)  # the compiled kernels' threads (one block range each)
        best = {be: 0.0 for be in backends}
        rms = {be: float("nan") for be in backends}
        best_c, rms_c = 0.0, float("nan")
        for _ in range(3):  # alternate, so all see the same machine
            if exe is not None:
                rc, rms_c = run_c(exe, args.rays, threads, args.repeat)
                best_c = max(best_c, rc)
            for be in backends:
                rp, out = rate(lens, mono, film, args.repeat, backend=be)
                best[be] = max(best[be], rp)
                rms[be] = rms_um(out)
        for be in backends:
            line = (f"  {threads} thread{'s' if threads > 1 else ' '}: physcam {be:5s} {best[be] / 1e6:6.2f} M rays/s "
                    f"(RMS {rms[be]:.4f} um)")
            if exe is not None:
                line += f" | C simd {best_c / 1e6:6.2f} M rays/s (RMS {rms_c:.4f} um) | ratio {best[be] / best_c:.2f}"
            line += f" | {best[be] / threads / 25e6:.2f} x the 25 M/s-per-core stretch"
            r32, _ = rate(lens, mono32, film, args.repeat, backend=be)
            line += f" | float32 {r32 / 1e6:.2f} M rays/s"
            print(line)
    if exe is None and not args.no_c:
        print(f"  (no C reference: gcc or {args.c_source} missing)")
    kernels.set_threads(None)
    for be in backends:
        print(f"physcam's {be} kernel alone, {nmax} threads:")
        for name, rays, kw in (("monochrome, copying the batch", mono, dict(in_place=False)),
                               ("dispersion + Fresnel, in place", colour, dict(fresnel=True)),
                               ("monochrome, float32, in place", mono.astype(np.float32), {}),
                               ("dispersion + Fresnel, float32", colour.astype(np.float32), dict(fresnel=True))):
            rp, _ = rate(lens, rays, film, args.repeat, backend=be, **kw)
            print(f"  {name:32s} {rp / 1e6:7.2f} M rays/s")
    # the copy of the batch on its own, against the call that makes it (issue 14 corrected the record)
    tc = min(_timed(mono.copy) for _ in range(args.repeat))
    rp, _ = rate(lens, mono, film, args.repeat, in_place=False, backend=backends[0] if backends else "numpy")
    print(f"  copy of the batch alone          {tc * 1e3:7.2f} ms = {100 * tc / (len(mono) / rp):.1f} % of the copying "
          f"call ({len(mono) / rp * 1e3:.1f} ms)")
    small = mono.take(slice(0, min(args.rays, 100_000)))
    rp, _ = rate(lens, small, film, 2, backend="numpy")
    line = f"  numpy reference kernel           {rp / 1e6:7.2f} M rays/s"
    for be in backends:
        rj, _ = rate(lens, small, film, 2, backend=be)
        line += f" ({be} on the same 1e5 rays: {rj / 1e6:.2f}, {rj / rp:.1f}x)"
    print(line)
    print(f"load average {load()} at end")
    if exe is not None:
        shutil.rmtree(exe.parent, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
