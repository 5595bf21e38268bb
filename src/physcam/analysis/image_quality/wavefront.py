"""Wavefront error: optical path difference over the exit pupil, its Zernike fit, RMS and peak-to-valley.

The OPD of a field is computed by :mod:`physcam.analysis.image_quality._pupil` (real rays over the real
pupil, each followed to the reference sphere centred on the chief ray's point on the film and
passing through the paraxial exit pupil; W = OPL(chief) - OPL(ray), the sign optiland 0.6.3
uses). Reported in waves of the wavelength analysed:

- ``rms_waves``: root mean square about the mean over the lit pupil, weighted by area
  (piston removed; Zemax's "RMS to chief"), ``pv_waves`` the peak-to-valley;
- ``rms_to_centroid_waves``: with tilt removed too (a weighted least-squares plane), the error
  against the sphere centred where the light is, from which the Marechal estimate of the
  Strehl ratio exp(-(2 pi sigma)^2) is given (Born & Wolf, *Principles of Optics*, 9.1);
- ``zernike``: a weighted least-squares fit of Zernike polynomials in **Noll's ordering and
  normalisation** (R. J. Noll, "Zernike polynomials and atmospheric turbulence", JOSA 66, 207,
  1976): Z_j = sqrt(n + 1) R_n^|m|(rho) (sqrt 2 cos(m theta) for even j, sqrt 2 sin(m theta)
  for odd j, 1 when m = 0), so on an unvignetted circular pupil the RMS is
  sqrt(sum of c_j^2 for j >= 2). j = 1 piston, 2 and 3 tilt in x and y, 4 defocus, 5 and 6
  astigmatism, 7 and 8 coma, 11 spherical aberration. Pupil coordinates: x, y in lens space
  (x right, y up, the Y meridian holding the field), theta from +x toward +y, origin at the
  chief ray and unit radius the paraxial entrance pupil's at the f-stop, on the plane of the
  paraxial entrance pupil. A vignetted pupil does not fill the unit disk, where Zernike
  polynomials are no longer orthogonal: the fit is then a fit, and RMS and PV come from the
  samples, not from the coefficients.

Lengths in mm, lens space (docs/conventions.md); see docs/image-quality.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, require_finite
from ...figures import styled
from ...optics.state import CameraState, OfACamera, takes_camera

__all__ = ["WavefrontMap", "wavefront", "noll_indices", "zernike_noll", "ZERNIKE_ORDERING"]

ZERNIKE_ORDERING = ("Noll (1976), orthonormal on the unit disk: RMS = sqrt(sum c_j^2, j >= 2) on an "
                    "unvignetted circular pupil; j=1 piston, 2/3 tilt x/y, 4 defocus, 5/6 astigmatism, "
                    "7/8 coma, 11 spherical")
MAX_ZERNIKE_TERMS = 231  # radial orders up to 20


def noll_indices(j) -> tuple[int, int]:
    """Radial order n and signed azimuthal frequency m of Noll's term ``j`` (1-based): m > 0 for the
    cosine terms (even j), m < 0 for the sine terms (odd j)."""
    if isinstance(j, bool) or not isinstance(j, (int, np.integer)) or j < 1:
        raise InputError(f"a Noll index is a whole number from 1, got {j!r}")
    j = int(j)
    n = 0
    rest = j - 1
    while rest > n:  # term j is the (rest + 1)-th of radial order n
        n += 1
        rest -= n
    # the |m| of the (rest + 1)-th term of order n: |m| rises in pairs from n mod 2
    am = (n % 2) + 2 * ((rest + ((n + 1) % 2)) // 2)
    if am == 0:
        return n, 0
    return n, am if j % 2 == 0 else -am


def _radial(n: int, am: int, rho):
    out = np.zeros_like(rho)
    for k in range((n - am) // 2 + 1):
        c = (-1) ** k * math.factorial(n - k) / (
            math.factorial(k) * math.factorial((n + am) // 2 - k) * math.factorial((n - am) // 2 - k))
        out = out + c * rho ** (n - 2 * k)
    return out


def zernike_noll(j, rho, theta):
    """Noll's normalised Zernike polynomial Z_j at polar pupil coordinates (``rho``, ``theta`` radians)."""
    n, m = noll_indices(j)
    rho = np.asarray(rho, dtype=float)
    theta = np.asarray(theta, dtype=float)
    r = _radial(n, abs(m), rho)
    if m == 0:
        return math.sqrt(n + 1) * r
    ang = np.cos(m * theta) if m > 0 else np.sin(-m * theta)
    return math.sqrt(2 * (n + 1)) * r * ang


@dataclass
class WavefrontMap(OfACamera):
    """The wavefront of one field of ``camera`` at one wavelength (module notes). OPD in waves; ``x``,
    ``y`` normalised pupil coordinates of every sample (unit radius: the paraxial entrance pupil)."""

    lens_name: str
    field_deg: float
    wavelength_nm: float
    camera: CameraState  # the camera analysed: its focus (inf at infinity) and f-stop
    film_z_mm: float
    defocus_mm: float
    pupil_samples: int
    x: np.ndarray = field(repr=False)
    y: np.ndarray = field(repr=False)
    opd_waves: np.ndarray = field(repr=False)
    weight: np.ndarray = field(repr=False)
    rms_waves: float = 0.0
    pv_waves: float = 0.0
    rms_to_centroid_waves: float = 0.0
    zernike: tuple[float, ...] = ()
    chief_image_height_mm: float = 0.0
    reference_radius_mm: float = 0.0
    lit_fraction: float = 1.0  # lit pupil area over the paraxial entrance pupil's
    cell: float = 0.0  # side of a pupil grid cell, normalised (edge samples stand for a quarter of it)

    @property
    def strehl_marechal(self) -> float:
        """exp(-(2 pi sigma)^2) with sigma the RMS to the centroid (good for sigma below ~0.1 wave)."""
        return math.exp(-(2 * math.pi * self.rms_to_centroid_waves) ** 2)

    def to_dict(self) -> dict:
        return {
            "lens": self.lens_name, "field_deg": self.field_deg, "wavelength_nm": self.wavelength_nm,
            "fstop": self.fstop,
            "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
            "film_z_mm": self.film_z_mm, "defocus_mm": self.defocus_mm, "pupil_samples": self.pupil_samples,
            "rms_waves": self.rms_waves, "pv_waves": self.pv_waves, "rms_to_centroid_waves": self.rms_to_centroid_waves,
            "strehl_marechal": self.strehl_marechal, "chief_image_height_mm": self.chief_image_height_mm,
            "reference_radius_mm": self.reference_radius_mm, "lit_fraction": self.lit_fraction,
            "zernike_ordering": ZERNIKE_ORDERING,
            "zernike_waves": {str(j + 1): c for j, c in enumerate(self.zernike)},
            "definition": "OPD = OPL(chief) - OPL(ray) to the reference sphere centred on the chief ray's film point "
                          "through the paraxial exit pupil, in waves; RMS about the mean (piston removed), "
                          "area-weighted over the lit pupil; PV max - min",
        }

    @styled
    def plot(self, path=None, *, force: bool = False):
        """Draw the OPD map (waves) over the normalised pupil; write it to ``path`` or return the figure."""
        from .._plot import figure, save

        fig, ax = figure(5.2, 4.4)
        lim = 1.05 * max(1.0, float(np.abs(self.x).max()), float(np.abs(self.y).max()))
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        fig.tight_layout()
        # square markers one cell (a quarter cell at the edge) across, in points
        pts_per_unit = ax.get_window_extent().width / fig.dpi * 72.0 / (2 * lim)
        big = self.weight >= self.weight.max() * 0.99
        lo, hi = float(self.opd_waves.min()), float(self.opd_waves.max())
        for sel, side in ((big, self.cell), (~big, self.cell / 4)):
            sc = ax.scatter(self.x[sel], self.y[sel], c=self.opd_waves[sel], s=(1.15 * side * pts_per_unit) ** 2,
                            marker="s", cmap="RdBu_r", lw=0, vmin=lo, vmax=hi)
        t = np.linspace(0, 2 * np.pi, 200)
        ax.plot(np.cos(t), np.sin(t), color="0.6", lw=0.6, ls=":")
        ax.set_xlabel("pupil x (normalised)")
        ax.set_ylabel("pupil y (normalised)")
        fig.colorbar(sc, ax=ax, label="OPD (waves)")
        ax.set_title(f"{self.lens_name}\n{self.field_deg:g} deg, {self.wavelength_nm:g} nm, f/{self.fstop:.3g}: "
                     f"RMS {self.rms_waves:.3f}, PV {self.pv_waves:.3f} waves", fontsize=8)
        return save(fig, path, force)


def zernike_fit(x, y, w, weights, terms: int) -> tuple[float, ...]:
    rho = np.hypot(x, y)
    th = np.arctan2(y, x)
    B = np.stack([zernike_noll(j, rho, th) for j in range(1, terms + 1)], axis=1)
    sw = np.sqrt(weights)[:, None]
    c, *_ = np.linalg.lstsq(B * sw, w * sw[:, 0], rcond=None)
    return tuple(float(v) for v in c)


def rms_pv(w, weights):
    """(RMS about the mean, PV, RMS with tilt removed) of OPD samples ``w`` with quadrature ``weights``."""
    sw = weights.sum()
    mean = float((w * weights).sum() / sw)
    rms = math.sqrt(max(float((weights * (w - mean) ** 2).sum() / sw), 0.0))
    return rms, float(w.max() - w.min()), mean


def _terms(zernike_terms) -> int:
    if isinstance(zernike_terms, bool) or not isinstance(zernike_terms, (int, np.integer)) or \
            not 1 <= zernike_terms <= MAX_ZERNIKE_TERMS:
        raise InputError(f"zernike_terms must be a whole number from 1 to {MAX_ZERNIKE_TERMS}, got {zernike_terms!r}")
    return int(zernike_terms)


@takes_camera
def wavefront(
    camera: CameraState,
    field_deg=0.0,
    *,
    wavelength_nm=None,
    defocus_mm=0.0,
    pupil_samples=None,
    zernike_terms: int = 37,
    backend: str = "auto",
) -> WavefrontMap:
    """Wavefront of ``camera`` (:func:`physcam.optics.state.camera_state`: the lens focused and stopped,
    its iris shape) at field angle ``field_deg`` (degrees, Y meridian) and ``wavelength_nm`` (default
    the camera's primary), with the film moved ``defocus_mm`` away from the lens. ``pupil_samples``:
    cells across the pupil (16 to 1024, default 64; each traced at its centre, the pupil's edge at 4 x 4
    points per cell). See the module notes for the definitions.
    """
    from . import _sampling

    terms = _terms(zernike_terms)
    dz = require_finite("defocus_mm", defocus_mm)
    # the OPD is exact at every ray: no phase sampling rule (RMS and PV converge by 64 cells)
    fp = _sampling.field_pupils(camera, field_deg, wavelengths_nm=None if wavelength_nm is None else [wavelength_nm],
                                defocus_mm=[dz], pupil_samples=pupil_samples, backend=backend, check=False)
    pt = fp.traces[0]
    ws = fp.samples(0, dz)
    st = fp.setup
    x = (pt.gx - fp.field.chief_ep_xy[0]) / st.r_ep
    y = (pt.gy - fp.field.chief_ep_xy[1]) / st.r_ep
    wgt = pt.weight * pt.rays.amplitude ** 2
    w = ws.opd_waves
    rms, pv, _ = rms_pv(w, wgt)
    A = np.stack([np.ones_like(x), x, y], axis=1)
    sw = np.sqrt(wgt)[:, None]
    c, *_ = np.linalg.lstsq(A * sw, w * sw[:, 0], rcond=None)
    rms_c, _, _ = rms_pv(w - A @ c, wgt)
    lit = float((pt.weight * pt.rays.amplitude).sum() * pt.cell_mm ** 2 / (math.pi * st.r_ep ** 2))
    return WavefrontMap(st.lens_name, fp.field.field_deg, pt.wavelength_nm, st.state, st.film_z + dz, dz, pt.n, x, y, w, wgt, rms, pv, rms_c, zernike_fit(x, y, w, wgt, terms),
                        ws.chief_film_xy[1], ws.radius_mm, lit, pt.cell_mm / st.r_ep)
