"""Diffraction point spread function by FFT of the pupil function, and the Strehl ratio.

The pupil function of a field (:mod:`physcam.analysis.image_quality._pupil`: amplitude from the real pupil
-- the stop, its aperture shape and every rim that vignettes -- and phase exp(-2 pi i W) from
the OPD against the reference sphere) is sampled on a grid of cells; its discrete Fourier
transform, zero-padded ``padding`` times, gives the PSF on the film (Goodman, *Introduction to
Fourier Optics*, 6.2-6.3). A pupil cell of side du maps to image-space direction cosines by
the least-squares slopes s = dL/dx, dM/dy of the reference-sphere directions, so a PSF pixel
is lambda / (n' |s| du M) with M the padded size, in x and in y (an off-axis pupil is
foreshortened, and so the PSF's pixels are not square).

Strehl ratio: the PSF's peak over the peak of the unaberrated PSF of the same pupil (its
vignetted shape and aperture amplitude, no OPD), S = max |sum P e^{...}|^2 / (sum |P_0|)^2 --
the definition of optiland 0.6.3 and of Zemax's FFT PSF. The peak is found on the FFT grid
and refined by evaluating the transform off the grid, so it is not lost between pixels.

Lengths in mm (PSF pixels reported in um); see docs/image-quality.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, require_finite
from ...figures import styled
from ...optics.state import CameraState, OfACamera, takes_camera

__all__ = ["PointSpreadFunction", "psf", "strehl_of_pupil"]


def _dft_at(P: np.ndarray, fx, fy):
    """|sum P[i, j] exp(-2 pi i (fx j + fy i))|^2 for arrays of frequencies (cycles per cell)."""
    n_r, n_c = P.shape
    j = np.arange(n_c)
    i = np.arange(n_r)
    ex = np.exp(-2j * np.pi * np.outer(np.atleast_1d(fx), j))  # (k, n_c)
    ey = np.exp(-2j * np.pi * np.outer(np.atleast_1d(fy), i))  # (k, n_r)
    v = np.einsum("ki,ij,kj->k", ey, P, ex)
    return np.abs(v) ** 2


def strehl_of_pupil(field_cells, amplitude0, padding: int = 4) -> tuple[float, float, float]:
    """(Strehl ratio, fx, fy) of a cell-sampled pupil function: the PSF's highest point (found on a
    ``padding``-times padded FFT grid, then refined off the grid) over (sum amplitude0)^2.
    fx, fy locate the peak in cycles per cell."""
    P = np.asarray(field_cells, dtype=complex)
    a0 = float(np.asarray(amplitude0, dtype=float).sum())
    if P.ndim != 2 or not a0 > 0:
        raise InputError("the pupil function must be a 2-D array with light in it")
    n_r, n_c = P.shape
    M = int(padding) * max(n_r, n_c)
    F = np.abs(np.fft.fft2(P, s=(M, M))) ** 2
    ky, kx = np.unravel_index(int(np.argmax(F)), F.shape)
    fy = (ky if ky < M // 2 else ky - M) / M
    fx = (kx if kx < M // 2 else kx - M) / M
    best = float(F[ky, kx])
    h = 1.0 / M
    offs = np.array([-1.0, 0.0, 1.0])
    for _ in range(24):  # pattern search on the continuous transform
        gx, gy = np.meshgrid(fx + offs * h, fy + offs * h)
        vals = _dft_at(P, gx.ravel(), gy.ravel())
        k = int(np.argmax(vals))
        if vals[k] > best * (1 + 1e-12) and k != 4:
            best, fx, fy = float(vals[k]), float(gx.ravel()[k]), float(gy.ravel()[k])
        else:
            h *= 0.5
            if h < 1e-4 / max(n_r, n_c):
                break
    return best / a0 ** 2, fx, fy


@dataclass
class PointSpreadFunction(OfACamera):
    """A monochromatic PSF (module notes). ``image`` is normalised so the unaberrated PSF of the
    same pupil peaks at 1 (its maximum is then about the Strehl ratio); rows run along +y on the
    film, columns along +x, centred on the chief ray's film point; pixels ``pixel_um``."""

    lens_name: str
    field_deg: float
    wavelength_nm: float
    camera: CameraState  # the camera analysed: its focus and f-stop
    defocus_mm: float
    pupil_samples: int
    padding: int
    strehl: float
    peak_offset_um: tuple[float, float]  # (x, y) of the PSF's peak from the chief ray's point
    pixel_um: tuple[float, float]
    airy_radius_um: float  # 1.22 lambda / (2 NA'), NA' = n' |dM/dy| r_ep (the pupil's paraxial size)
    chief_image_height_mm: float
    image: np.ndarray = field(repr=False)

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "field_deg": self.field_deg, "wavelength_nm": self.wavelength_nm,
                "fstop": self.fstop,
                "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
                "defocus_mm": self.defocus_mm, "pupil_samples": self.pupil_samples, "padding": self.padding,
                "strehl": self.strehl, "peak_offset_um": list(self.peak_offset_um), "pixel_um": list(self.pixel_um),
                "airy_radius_um": self.airy_radius_um, "chief_image_height_mm": self.chief_image_height_mm,
                "definition": "Strehl = PSF peak / peak of the same pupil without OPD (vignetting and aperture "
                              "shape kept); PSF by FFT of the pupil function"}

    @styled
    def plot(self, path=None, *, force: bool = False, radius_airy: float = 6.0):
        """Draw the PSF (log scale) within ``radius_airy`` Airy radii of the chief ray's point."""
        from matplotlib.colors import LogNorm

        from .._plot import figure, save

        img = self.image
        ny, nx = img.shape
        px, py = self.pixel_um
        hx = min(nx // 2 - 1, max(2, int(radius_airy * self.airy_radius_um / px)))
        hy = min(ny // 2 - 1, max(2, int(radius_airy * self.airy_radius_um / py)))
        sub = img[ny // 2 - hy:ny // 2 + hy + 1, nx // 2 - hx:nx // 2 + hx + 1]
        fig, ax = figure(5.0, 4.4)
        top = max(float(sub.max()), 1e-12)
        im = ax.imshow(np.maximum(sub, top * 1e-5), origin="lower", cmap="magma", norm=LogNorm(top * 1e-5, top),
                       extent=(-(hx + 0.5) * px, (hx + 0.5) * px, -(hy + 0.5) * py, (hy + 0.5) * py))
        fig.colorbar(im, ax=ax, label="relative intensity (unaberrated peak = 1)")
        ax.set_xlabel("x on the film (µm)")
        ax.set_ylabel("y on the film (µm)")
        ax.set_title(f"{self.lens_name}\nPSF {self.field_deg:g} deg, {self.wavelength_nm:g} nm, f/{self.fstop:.3g}: "
                     f"Strehl {self.strehl:.3f}", fontsize=8)
        return save(fig, path, force)


@takes_camera
def psf(
    camera: CameraState,
    field_deg=0.0,
    *,
    wavelength_nm=None,
    defocus_mm=0.0,
    pupil_samples=None,
    padding: int = 4,
    backend: str = "auto",
    max_pupil_samples=None,
) -> PointSpreadFunction:
    """The diffraction PSF and Strehl ratio of ``camera`` at ``field_deg`` (degrees, Y meridian).

    Arguments as :func:`physcam.analysis.image_quality.wavefront.wavefront`; ``padding`` (2 to 16) sets the PSF
    sampling: pixels of lambda N / padding or so. The pupil grid follows the quarter-wave rule
    (:mod:`physcam.analysis.image_quality._sampling`), up to ``max_pupil_samples`` (default 1024).
    """
    from . import _sampling

    if isinstance(padding, bool) or not isinstance(padding, (int, np.integer)) or not 2 <= padding <= 16:
        raise InputError(f"padding must be a whole number from 2 to 16, got {padding!r}")
    dz = require_finite("defocus_mm", defocus_mm)
    fp = _sampling.field_pupils(camera, field_deg, wavelengths_nm=None if wavelength_nm is None else [wavelength_nm],
                                defocus_mm=[dz], pupil_samples=pupil_samples, backend=backend,
                                max_pupil_samples=max_pupil_samples)
    pf = fp.pupil(0, dz)
    ws = fp.samples(0, dz)
    st = fp.setup
    n = pf.field.shape[0]
    M = int(padding) * n
    a0 = float(pf.amplitude0.sum())
    F = np.fft.fftshift(np.abs(np.fft.fft2(pf.field, s=(M, M))) ** 2) / a0 ** 2
    lam = pf.wavelength_nm * 1e-6
    dx = lam / (pf.n_image * pf.slope_x * pf.cell_mm * M)  # signed: film x of FFT index +1 is -dx
    dy = lam / (pf.n_image * pf.slope_y * pf.cell_mm * M)
    # film coordinate = -(index) * d: flip an axis whose slope is positive so rows/columns run along +y/+x
    img = F
    if dy > 0:
        img = img[::-1]
        img = np.roll(img, 1, axis=0)
    if dx > 0:
        img = img[:, ::-1]
        img = np.roll(img, 1, axis=1)
    s, fx, fy = strehl_of_pupil(pf.field, pf.amplitude0, padding)
    peak = (-fx * M * dx * 1e3, -fy * M * dy * 1e3)  # film position of the peak's frequency index, um
    na = pf.n_image * abs(pf.slope_y) * st.r_ep
    return PointSpreadFunction(st.lens_name, fp.field.field_deg, pf.wavelength_nm, st.state, dz, n, int(padding), float(s), (float(peak[0]), float(peak[1])),
                               (abs(dx) * 1e3, abs(dy) * 1e3), 0.61 * lam / na * 1e3, ws.chief_film_xy[1],
                               np.ascontiguousarray(img))
