"""Benchmark: a 15-field x 3-wavelength MTF chart of dgauss.50mm, physcam against optiland.

Goal (issue 16): the vendor chart (MTF at 10/20/40 lp/mm against field, 15 fields from the axis
to the full-frame corner, the F, d and C lines) in seconds, not minutes, timed against optiland on
the same settings: 64 pupil cells across (physcam's default grid; optiland's ``num_rays=64``),
f/4, infinity focus. optiland's chart is ``optiland.analysis.MTFvsField`` (one SampledMTF per
field and wavelength: a 37-term Zernike fit sheared in the pupil), run twice: with rays aimed at
the real stop ("iterative", the convention physcam's chief rays follow and the oracle used) and
with its default paraxial aiming. optiland is too heavy for physcam's environment, so it runs in
its own (``--optiland-python``, see scripts/optiland_mtf_oracle.py for the set-up); without it
only physcam is timed. Best of ``--repeat`` runs after a warm-up (numba compiles on first use).
The CLI chart cold, in fresh processes (goal 1 s, issue 27): ``benchmarks/startup.py --only mtf``.

    .venv/bin/python benchmarks/mtf.py --repeat 3 --optiland-python /tmp/optiland-venv/bin/python
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FSTOP = 4.0
FREQS = [10.0, 20.0, 40.0]
N_FIELDS = 15
PUPIL = 64

OPTILAND = r"""
import json, sys, time
sys.path.insert(0, {scripts!r})
from optiland_mtf_oracle import build
from optiland.analysis import MTFvsField
res = {{}}
for aiming in ("iterative", "paraxial"):
    op, _ = build({fstop}, fields=(0.0, {top}), wavelengths_um=(0.4861327, 0.5875618, 0.6562725))
    op.ray_tracer.set_aiming(aiming)
    MTFvsField(op, {freqs}, num_fields=3, num_rays={pupil})  # warm-up (numba, caches)
    best = float("inf")
    for _ in range({repeat}):
        t = time.perf_counter()
        MTFvsField(op, {freqs}, num_fields={nf}, num_rays={pupil})
        best = min(best, time.perf_counter() - t)
    res[aiming] = best
print(json.dumps(res))
"""


def time_physcam(repeat: int):
    from physcam.analysis.image_quality.mtf import WHITE_LIGHT_NM, mtf_chart
    from physcam.lens.library import load_lens
    from physcam.optics.state import as_designed

    camera = as_designed(load_lens("dgauss_50mm"), fstop=FSTOP)
    kw = dict(n_fields=N_FIELDS, frequencies=FREQS, wavelengths_nm=WHITE_LIGHT_NM, pupil_samples=PUPIL)
    chart = mtf_chart(camera, **kw)  # warm-up: numba compiles the kernels
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        chart = mtf_chart(camera, **kw)
        best = min(best, time.perf_counter() - t)
    return best, chart


def time_optiland(python: str, repeat: int, top_deg: float):
    code = OPTILAND.format(scripts=str(ROOT / "scripts"), fstop=FSTOP, top=top_deg, freqs=FREQS, nf=N_FIELDS,
                           pupil=PUPIL, repeat=repeat)
    out = subprocess.run([python, "-W", "ignore", "-c", code], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="timed runs (best is kept)")
    ap.add_argument("--optiland-python", default=None, help="python of an environment with optiland 0.6.3")
    args = ap.parse_args(argv)
    t_pc, chart = time_physcam(args.repeat)
    top = float(chart.fields_deg.max())
    print(f"physcam  mtf_chart: {N_FIELDS} fields (0 to {top:.2f} deg) x 3 wavelengths x {len(FREQS)} frequencies, "
          f"{PUPIL} pupil cells: {t_pc:.2f} s (best of {args.repeat})")
    if not args.optiland_python:
        print("optiland not timed: give --optiland-python (an environment with optiland==0.6.3)")
        return 0
    res = time_optiland(args.optiland_python, args.repeat, top)
    for aiming, t in res.items():
        print(f"optiland MTFvsField ({aiming} aiming), same settings: {t:.2f} s; optiland / physcam = {t / t_pc:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
