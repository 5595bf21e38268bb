"""Huygens PSF and MTF: the time of the issue's goal and the FFT method beside it.

Goal (issue 27): a 14-degree Huygens MTF of dgauss_50mm at 256 x 256 pupil samples and a 128 x 128
image grid in under 2 s on the project's 2-core machine. Prints the wall time of each (median of
``REPEATS`` warm runs, after one cold run that loads the tracer and FINUFFT), and the two methods'
MTF at 10, 20 and 40 lp/mm.

    .venv/bin/python benchmarks/huygens.py
"""

from __future__ import annotations

import statistics
import time

from physcam.analysis.image_quality.huygens import huygens_psf
from physcam.analysis.image_quality.mtf import mtf
from physcam.lens.library import load_lens
from physcam.optics.state import as_designed

REPEATS = 5
FREQS = (10.0, 20.0, 40.0)


def main() -> None:
    camera = as_designed(load_lens("dgauss_50mm"), fstop=4.0)
    kw = dict(wavelengths_nm=[587.5618], pupil_samples=256)
    t0 = time.perf_counter()
    huygens_psf(camera, 14.0, image_samples=128, **kw)
    cold = time.perf_counter() - t0
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        p = huygens_psf(camera, 14.0, image_samples=128, **kw)
        times.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    f = mtf(camera, 14.0, frequencies=FREQS, **kw)
    fft = time.perf_counter() - t0
    warm = statistics.median(times)
    print(f"Huygens PSF, dgauss_50mm 14 deg f/4, 256 x 256 pupil, 128 x 128 image: cold {cold:.2f} s, warm median "
          f"{warm:.2f} s (goal 2 s: {'met' if warm < 2.0 else 'NOT met'}); its grid holds {p.energy_in_grid:.1%}")
    for axis, name, vals in (("y", "tangential", f.tangential), ("x", "sagittal", f.sagittal)):
        h = abs(p.otf(FREQS, axis))
        print(f"  {name}: Huygens " + ", ".join(f"{v:.3f}" for v in h) + "; FFT " + ", ".join(f"{v:.3f}" for v in vals)
              + " at " + "/".join(f"{v:g}" for v in FREQS) + " lp/mm")
    print(f"FFT MTF of the same field and pupil grid: {fft:.2f} s")


if __name__ == "__main__":
    main()
