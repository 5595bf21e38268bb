"""Offline oracle for physcam's image-quality analyses: optiland's numbers for dgauss.50mm.

optiland (PyPI) computes wavefront, FFT PSF and MTF. Its dependencies (vtk, pandas, scipy,
seaborn, ~1.3 GB installed) are too heavy for physcam's test extra, so it runs in a throwaway
virtual environment and its numbers are recorded in ``tests/data/optiland_mtf_dgauss.json``,
which tests/analysis/test_mtf_oracle.py compares against (docs/image-quality.md):

    python3 -m venv /tmp/optiland-venv
    /tmp/optiland-venv/bin/pip install optiland==0.6.3
    /tmp/optiland-venv/bin/python scripts/optiland_mtf_oracle.py > tests/data/optiland_mtf_dgauss.json

The lens is read from physcam's bundled TOML with the standard library (no physcam import):
dispersionless glasses become optiland IdealMaterials, every clear semi-diameter a
RadialAperture (so rims vignette as in physcam's tracer), the stop is set by the entrance
pupil diameter EFL / N, the image surface at the paraxial focus (optiland's image_solve, the
same definition as physcam's film at infinity focus), rays are aimed at the real stop
(optiland's "iterative" aiming, as physcam's chief ray through the centre of the stop).

Conventions matched, and how:
- OPD: optiland's "chief_ray" wavefront strategy (reference sphere centred on the chief ray's
  image point, radius to the paraxial exit pupil), the definition physcam uses. optiland's own
  ``OPD.rms()`` does not remove piston; the RMS recorded for comparison is computed here from
  optiland's OPD samples (uniform grid, intensity-weighted) about their mean, physcam's RMS.
- Strehl: optiland's FFTPSF peak over the unaberrated peak of the same pupil (physcam's
  definition), on a fine pupil grid and a large padding so the peak is not lost between pixels.
- MTF: optiland's FFTMTF (scalar, real pupil with vignetting), its frequency axis calibrated from
  marginal-ray directions, read at 10/20/40 lp/mm by linear interpolation between its samples on
  a fine grid; SampledMTF (Zernike-fitted, unvignetted shear) is recorded beside it.
"""

from __future__ import annotations

import importlib.metadata
import json
import math
import sys
import time
import tomllib
from pathlib import Path

import numpy as np


from optiland import optic
from optiland.materials import IdealMaterial
from optiland.mtf import FFTMTF, SampledMTF
from optiland.physical_apertures import RadialAperture
from optiland.psf import FFTPSF
from optiland.wavefront import Wavefront

LENS = Path(__file__).resolve().parents[1] / "src" / "physcam" / "data" / "lenses" / "dgauss_50mm.toml"
WAVELENGTH_UM = 0.5875618
FSTOPS = (2.8, 8.0)
FIELDS = (0.0, 14.0)
FREQS = (10.0, 20.0, 40.0)


def build(fstop: float, fields=FIELDS, wavelengths_um=(WAVELENGTH_UM,)):
    rows = tomllib.loads(LENS.read_text())["surface"]
    op = optic.Optic()
    op.surfaces.add(index=0, radius=np.inf, thickness=np.inf)
    for i, s in enumerate(rows, start=1):
        med = s["medium"]
        mat = "air" if med == "air" else IdealMaterial(n=float(med["nd"]))
        r = float(s["radius"]) or np.inf
        op.surfaces.add(index=i, radius=r, thickness=float(s["thickness"]), material=mat,
                        is_stop=s["kind"] == "stop", aperture=RadialAperture(r_max=float(s["semi_diameter"])))
    op.surfaces.add(index=len(rows) + 1)
    op.fields.set_type(field_type="angle")
    for f in fields:
        op.fields.add(y=f)
    for k, w in enumerate(wavelengths_um):
        op.wavelengths.add(value=w, is_primary=(k == (len(wavelengths_um) // 2 if len(wavelengths_um) > 1 else 0)))
    efl = float(op.paraxial.f2())
    op.set_aperture(aperture_type="EPD", value=efl / fstop)
    op.image_solve()
    # iterative aiming maps the unit pupil onto the stop radius the EPD sets; the file's f/2 rim on the
    # stop is removed so it can neither clip nor differ from it
    stop = next(s for s in op.surfaces if getattr(s, "is_stop", False))
    stop.aperture = None
    op.ray_tracer.set_aiming("iterative")
    return op, efl


def rms_about_mean(data):
    w = np.asarray(data.intensity, dtype=float)
    o = np.asarray(data.opd, dtype=float)
    m = w > 0
    w, o = w[m], o[m]
    mean = float((w * o).sum() / w.sum())
    return math.sqrt(float((w * (o - mean) ** 2).sum() / w.sum())), float(np.sqrt(np.mean(o ** 2)))


def mtf_at(m, k, freqs):
    t = np.interp(freqs, np.asarray(m.freq_tang[k]), np.asarray(m.mtf[k][0]))
    s = np.interp(freqs, np.asarray(m.freq_sag[k]), np.asarray(m.mtf[k][1]))
    return [float(v) for v in t], [float(v) for v in s]


def main():
    out = {"optiland_version": importlib.metadata.version("optiland"), "lens": "dgauss_50mm (physcam bundled TOML)",
           "wavelength_nm": WAVELENGTH_UM * 1000, "frequencies_lpmm": list(FREQS), "script": "scripts/optiland_mtf_oracle.py",
           "settings": {"aiming": "iterative (real stop)", "wavefront": "chief_ray strategy, uniform 257 x 257",
                        "psf": "FFTPSF num_rays=257 grid_size=4096", "mtf": "FFTMTF num_rays=257 grid_size=1024 "
                        "(and 129/512 to show convergence); SampledMTF num_rays=257"},
           "cases": []}
    for fstop in FSTOPS:
        op, efl = build(fstop)
        image_z = float(op.surfaces.positions[-1].item())
        for k, fd in enumerate(FIELDS):
            field = (0.0, fd / max(FIELDS))
            t0 = time.time()
            wf = Wavefront(op, fields=[field], wavelengths=[WAVELENGTH_UM], num_rays=257, distribution="uniform")
            rms, rms_raw = rms_about_mean(wf.get_data(field, WAVELENGTH_UM))
            psf = FFTPSF(op, field, WAVELENGTH_UM, num_rays=257, grid_size=4096)
            strehl = psf.strehl_ratio()
            m = FFTMTF(op, [field], WAVELENGTH_UM, num_rays=257, grid_size=1024)
            t, s = mtf_at(m, 0, FREQS)
            m2 = FFTMTF(op, [field], WAVELENGTH_UM, num_rays=129, grid_size=512)
            t2, s2 = mtf_at(m2, 0, FREQS)
            sm = SampledMTF(op, field, WAVELENGTH_UM, num_rays=257)
            sv = sm.calculate_mtf([(0.0, f) for f in FREQS] + [(f, 0.0) for f in FREQS])
            out["cases"].append({
                "fstop": fstop, "field_deg": fd, "efl_mm": efl, "image_z_mm": image_z,
                "rms_waves": rms, "rms_waves_optiland_no_piston_removal": rms_raw, "strehl": strehl,
                "mtf_tangential": t, "mtf_sagittal": s,
                "mtf_tangential_coarser": t2, "mtf_sagittal_coarser": s2,
                "sampled_mtf_tangential": [float(v) for v in sv[:3]], "sampled_mtf_sagittal": [float(v) for v in sv[3:]],
                "seconds": time.time() - t0,
            })
            print(f"f/{fstop} {fd} deg done in {time.time() - t0:.1f} s", file=sys.stderr)
    json.dump(out, sys.stdout, indent=2)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
