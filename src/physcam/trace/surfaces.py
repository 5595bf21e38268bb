"""A prescription flattened into float64 columns, one row per surface, for the kernels.

Each surface is the quadric  ax x^2 + ay y^2 + az z^2 - 2 z = 0  (z from its vertex,
+z toward the film) plus, for an even asphere, the polynomial A4 r^4 + ... + A16 r^16:

==============  ======  ======  ===============
kind            ax      ay      az
==============  ======  ======  ===============
flat, stop      0       0       0
spherical       c       c       c
aspheric        c       c       (1 + k) c        (+ A4..A16, Newton iteration)
cylindrical_x   c       0       c                (curved in X-Z only)
cylindrical_y   0       c       c                (curved in Y-Z only)
==============  ======  ======  ===============

c = 1 / radius. This is the sphere/conic sag equation z = c r^2 / (1 + sqrt(1 - (1+k) c^2 r^2))
solved for z (Zemax OpticStudio manual, "Standard" and "Even Asphere" surfaces).

Media are stored as the 9 dispersion coefficients of :func:`physcam.optics.glass.dispersion`
(catalogue Sellmeier, normal-line Cauchy or constant, one shared form evaluated exactly by
:func:`physcam.optics.glass.evaluate`), for the medium before and after each surface in the
order the rays meet them, so the kernel computes the index per ray wavelength.
``r_scale`` multiplies the Fresnel reflectance (coating model, :mod:`physcam.trace.fresnel`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..lens.prescription import Prescription, takes_prescription
from ..optics.glass import Dispersion, dispersion, evaluate, medium_dispersion

__all__ = ["KIND_FLAT", "KIND_STOP", "KIND_QUADRIC", "KIND_ASPHERE", "SurfaceTable", "surface_table"]

KIND_FLAT = 0
KIND_STOP = 1
KIND_QUADRIC = 2
KIND_ASPHERE = 3
N_ASPHERIC = 7  # A4 .. A16


@dataclass(frozen=True)
class SurfaceTable:
    """Per-surface columns in tracing order (front to back, or back to front when ``reverse``)."""

    vertex_z: np.ndarray
    ax: np.ndarray
    ay: np.ndarray
    az: np.ndarray
    curvature: np.ndarray
    conic: np.ndarray
    aspheric: np.ndarray  # (n, 7): A4..A16
    semi_diameter: np.ndarray
    kind: np.ndarray  # int64 codes KIND_*
    disp_before: np.ndarray  # (n, 9) dispersion coefficients of the medium before each row
    disp_after: np.ndarray  # (n, 9) ... and after it
    r_scale: np.ndarray
    index: np.ndarray  # prescription surface index of each row
    reverse: bool
    media: tuple = ()  # Dispersion of object space and of the medium after each surface (prescription order)

    def __len__(self) -> int:
        return int(self.vertex_z.shape[0])

    def index_after(self, wavelength_nm: float) -> np.ndarray:
        """Refractive index after each row at one wavelength (for checks and reports)."""
        return np.array([float(evaluate(c, wavelength_nm)) for c in self.disp_after])

    def index_before(self, wavelength_nm: float) -> np.ndarray:
        """Refractive index before each row at one wavelength."""
        return np.array([float(evaluate(c, wavelength_nm)) for c in self.disp_before])


@takes_prescription
def surface_table(
    lens: Prescription,
    *,
    reverse: bool = False,
    stop_semi_diameter: float | None = None,
    coating: str | None = "none",
) -> SurfaceTable:
    """Flatten ``lens`` for tracing. ``reverse`` orders rows film side first (film -> scene).

    ``stop_semi_diameter`` (mm) overrides the stop's clear semi-diameter (stopping down).
    ``coating``: "none", "single" or "multi" (see :mod:`physcam.trace.fresnel`); ``None`` uses
    the lens metadata's coating when it names one of these, else "none".
    """
    from .fresnel import reflectance_scale

    surfs = lens.surfaces
    n = len(surfs)
    if n == 0:
        raise InputError(f"lens {lens.name!r} has no surfaces")
    if coating is None:
        coating = lens.metadata.coating if lens.metadata.coating in ("none", "single", "multi") else "none"
    vz = np.asarray(lens.vertex_z, dtype=np.float64)
    ax = np.zeros(n)
    ay = np.zeros(n)
    az = np.zeros(n)
    cv = np.zeros(n)
    k = np.zeros(n)
    asph = np.zeros((n, N_ASPHERIC))
    semi = np.zeros(n)
    kind = np.zeros(n, dtype=np.int64)
    for i, s in enumerate(surfs):
        c = s.curvature
        semi[i] = s.semi_diameter
        if s.kind == "stop":
            kind[i] = KIND_STOP
            if stop_semi_diameter is not None:
                if not (np.isfinite(stop_semi_diameter) and 0 < stop_semi_diameter):
                    raise InputError(f"stop semi-diameter must be > 0 mm, got {stop_semi_diameter}")
                semi[i] = float(stop_semi_diameter)
        elif c == 0.0:
            kind[i] = KIND_FLAT
        else:
            cv[i] = c
            k[i] = s.conic
            if s.kind == "cylindrical_x":
                ax[i], ay[i], az[i] = c, 0.0, c
            elif s.kind == "cylindrical_y":
                ax[i], ay[i], az[i] = 0.0, c, c
            else:
                ax[i], ay[i], az[i] = c, c, (1.0 + s.conic) * c
            kind[i] = KIND_QUADRIC
            if s.kind == "aspheric" and any(a != 0.0 for a in s.aspheric):
                kind[i] = KIND_ASPHERE
                asph[i, : len(s.aspheric)] = s.aspheric
    # medium after surface i is surfs[i].medium; before surface 0 is air (object space).
    nd = np.array([1.0] + [s.medium.nd for s in surfs])
    media: tuple[Dispersion, ...] = (dispersion(1.0, 0.0),) + tuple(
        medium_dispersion(s.medium) for s in surfs)
    co = np.array([m.coefficients for m in media], dtype=np.float64)  # (n + 1, 9)
    rs = np.array([reflectance_scale(coating, nd[i], nd[i + 1]) for i in range(n)])
    idx = np.arange(n)
    if not reverse:
        before, after = co[:-1], co[1:]
    else:
        idx = idx[::-1]
        before, after = co[1:][::-1], co[:-1][::-1]
    c = np.ascontiguousarray
    return SurfaceTable(
        c(vz[idx]), c(ax[idx]), c(ay[idx]), c(az[idx]), c(cv[idx]), c(k[idx]), c(asph[idx]), c(semi[idx]),
        c(kind[idx]), c(before), c(after), c(rs[idx]), c(idx), reverse, media,
    )
