"""Huygens point spread function and MTF: the exit-pupil wavefront summed as secondary wavelets.

The FFT method (:mod:`physcam.analysis.image_quality.psf`, :mod:`physcam.analysis.image_quality.mtf`) takes the pupil function
on the entrance-pupil grid and maps grid cells to image-space directions by one affine fit. The
Huygens method needs no such map (Zemax OpticStudio's "Huygens PSF"; Born & Wolf, *Principles of
Optics*, 8.3, the Huygens-Fresnel principle): every traced ray j is a wavelet source at its point
S_j on the reference sphere (centre C, the primary chief ray's film point; radius R, through the
paraxial exit pupil point), and the field at an image point P is the sum

    U(P) = n' / (i lambda R) sum_j A_j exp(i k [OPL_j + n' (|P - S_j| - R)])

with k = 2 pi / lambda and A_j the ray's wavelet strength.

**Energy through the lens.** A ray launched from cell area dA_j of the entrance-pupil plane
carries power p_j dA_j (p = 1 for a collimated beam; for a point at a finite distance the solid
angle per area, cos(theta) / r^2 ~ dz / r^3). On the reference sphere the same rays spread over
J_j dA_j, J the Jacobian of the map from pupil plane to sphere (from a cubic least-squares fit
of the sphere points against the pupil coordinates, differentiated), so the field there is
sqrt(p_j / J_j) and the wavelet strength A_j = a_j sqrt(p_j J_j) dA_j (a_j the aperture
amplitude, sqrt of the iris's density). The sum then conserves energy: the PSF, in fractions of
the field's power per pixel, sums to the power that falls on the image grid.

**The image points.** P = C + D0 + (s, t, s tan(tilt_y) + t tan(tilt_x)) on a grid of s, t (film
x and y offsets from the grid's centre C + D0, the blur's centroid by default): a film tilted by
tilt_x about the x axis and tilt_y about the y axis, in degrees, s and t its points' x and y
coordinates. With u_j = (C - S_j) / R the ray's unit direction and D = P - C,

    |P - S_j| - R = u_j . D + (|D|^2 - (u_j . D)^2) / (2 R) + O(|D|^3 / R^2),

the first term linear in s and t, so the sum over the rays on the image grid is a type-1
non-uniform FFT (FINUFFT: Barnett, Magland & af Klinteberg, SIAM J. Sci. Comput. 41, 2019), O(rays +
pixels log pixels) instead of rays x pixels; |D|^2 is the same for every ray (a phase per image point,
which intensities do not see); the last term, a few hundredths of a radian over a PSF's extent, is
expanded in its power series (one more transform per monomial) until the next term is below 1e-6
radian. The next term of the distance's own expansion, (u.D)(|D|^2 - (u.D)^2) / 2R^2, is under 1e-3
radian over a PSF's grid; tests/analysis/image_quality/test_huygens.py checks the whole sum against the exact
distance |P - S_j| summed ray by ray.

**MTF**: the Fourier transform of the PSF on its grid, evaluated at each frequency directly
(not on an FFT grid), normalised by the field's whole power (the pupil's: Parseval), not by the
grid's sum, which the power outside the grid would inflate (dgauss_50mm at f/4 on axis read
0.9587/0.8929/0.7400 at 10/20/40 lp/mm against the FFT's 0.9554/0.8902/0.7382 before issue 39);
sagittal along film x, tangential along y for a field in the Y meridian. Polychromatic: each
wavelength's PSF in fractions of its own power, weighted and summed, then transformed.

**What is refused.** The pupil grid is capped at :data:`MAX_PUPIL_SAMPLES` by default (512, the
CLI's cap: the API refuses what ``physcam mtf --method huygens`` refuses, with the same sentence;
``max_pupil_samples`` raises it). A grid so large that the quadratic phase's series would need more
than :data:`MAX_SERIES_ORDER` terms is summed in quadrants, each expanded about its own centre; and
a sum that puts more than all the field's power on the grid (``energy_in_grid`` above 1 +
:data:`ENERGY_SLACK`) raises :class:`OpticsError` instead of returning it.

Lengths in mm (the PSF's pixels reported in um); lens space (docs/conventions.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError, OpticsError, require_finite
from ...figures import styled
from ...optics.state import CameraState, OfACamera, takes_camera

__all__ = ["HuygensPSF", "huygens_psf", "huygens_mtf", "DEFAULT_IMAGE_SAMPLES", "MAX_PUPIL_SAMPLES"]

#: The largest pupil grid by default (cells across): the CLI's cap (physcam.cli.mtf.CLI_MAX_PUPIL_SAMPLES).
MAX_PUPIL_SAMPLES = 512
#: How far above 1 the power on the image grid may come out (the sums' rounding) before it is refused.
ENERGY_SLACK = 0.01
#: Image grid points per side by default, and the most allowed.
DEFAULT_IMAGE_SAMPLES = 129  # odd: the centre pixel lies on the blur's centroid
MAX_IMAGE_SAMPLES = 1024
#: Default pixel: this fraction of lambda N_w (the Airy radius is 1.22 lambda N_w): the PSF is sampled
#: well above its Nyquist rate (its spectrum ends at 1 / (lambda N_w)).
PIXEL_OVER_LAMBDA_N = 0.25


@dataclass
class HuygensPSF(OfACamera):
    """A Huygens PSF (module notes): ``image`` (rows along +t = film y, columns along +s = film x) in
    fractions of the field's power per pixel; ``centre_mm`` the film point of the grid's centre."""

    lens_name: str
    field_deg: float
    wavelengths_nm: tuple[float, ...]
    weights: tuple[float, ...]
    camera: CameraState  # the camera analysed: its focus and f-stop
    defocus_mm: float
    tilt_deg: tuple[float, float]
    pupil_samples: int
    pixel_um: float
    centre_mm: tuple[float, float]
    chief_film_mm: tuple[float, float]
    strehl: float | None  # monochromatic only: peak over the peak of the same pupil without OPD
    energy_in_grid: float  # fraction of the field's power the grid holds
    image: np.ndarray = field(repr=False)

    def otf(self, frequencies, axis: str) -> np.ndarray:
        """Complex OTF at ``frequencies`` (lp/mm) along ``axis`` ("x" sagittal, "y" tangential), from the
        PSF's own grid: sum I exp(-2 pi i nu s) / P, evaluated at each frequency directly. P is the field's
        whole power (the image is in fractions of it: 1), not the grid's sum: by Parseval the pupil's power
        is the PSF's over the whole film, so power the grid misses lowers the OTF near zero frequency
        only, where dividing by the grid's sum raised every frequency by that fraction (module notes)."""
        if axis not in ("x", "y"):
            raise InputError(f"axis must be 'x' or 'y', got {axis!r}")
        nu = np.atleast_1d(np.asarray(frequencies, dtype=float))
        img = self.image
        line = img.sum(axis=0) if axis == "x" else img.sum(axis=1)  # the line spread function
        n = line.size
        pos = (np.arange(n) - (n - 1) / 2) * self.pixel_um * 1e-3
        if not float(line.sum()) > 0:
            raise OpticsError("the Huygens PSF holds no light on its grid")
        return np.exp(-2j * np.pi * np.outer(nu, pos)) @ line / float(sum(self.weights))

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "field_deg": self.field_deg, "wavelengths_nm": list(self.wavelengths_nm),
                "weights": list(self.weights), "fstop": self.fstop,
                "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
                "defocus_mm": self.defocus_mm, "tilt_deg": list(self.tilt_deg), "pupil_samples": self.pupil_samples,
                "image_samples": int(self.image.shape[0]), "pixel_um": self.pixel_um,
                "centre_mm": list(self.centre_mm), "chief_film_mm": list(self.chief_film_mm), "strehl": self.strehl,
                "energy_in_grid": self.energy_in_grid,
                "definition": "Huygens PSF: wavelets from the real rays on the exit-pupil reference sphere, energy "
                              "conserved; image in fractions of the field's power per pixel, rows along film y"}

    @styled
    def plot(self, path=None, *, force: bool = False):
        from matplotlib.colors import LogNorm

        from .._plot import figure, save

        img = self.image
        n = img.shape[0]
        half = n * self.pixel_um / 2
        fig, ax = figure(5.0, 4.4)
        top = max(float(img.max()), 1e-300)
        im = ax.imshow(np.maximum(img, top * 1e-5), origin="lower", cmap="magma", norm=LogNorm(top * 1e-5, top),
                       extent=(-half, half, -half, half))
        fig.colorbar(im, ax=ax, label="power per pixel (fraction)")
        ax.set_xlabel("film x from the grid centre (µm)")
        ax.set_ylabel("film y from the grid centre (µm)")
        wl = ", ".join(f"{w:g}" for w in self.wavelengths_nm)
        ax.set_title(f"{self.lens_name}\nHuygens PSF {self.field_deg:g} deg, {wl} nm, f/{self.fstop:.3g}", fontsize=8)
        return save(fig, path, force)


def _jacobian(gx, gy, sx, sy, sz, weight) -> np.ndarray:
    """Area ratio (sphere over pupil plane) at each ray, from a weighted cubic fit of the sphere points."""
    cx, cy = np.average(gx, weights=weight), np.average(gy, weights=weight)
    scale = max(float(np.ptp(gx)), float(np.ptp(gy)), 1e-12) / 2
    u, v = (gx - cx) / scale, (gy - cy) / scale
    powers = [(i, j) for i in range(4) for j in range(4 - i)]
    A = np.stack([u ** i * v ** j for i, j in powers], axis=1)
    sw = np.sqrt(weight)[:, None]
    du = np.stack([i * u ** max(i - 1, 0) * v ** j for i, j in powers], axis=1) / scale
    dv = np.stack([j * u ** i * v ** max(j - 1, 0) for i, j in powers], axis=1) / scale
    grads = []
    for comp in (sx, sy, sz):
        c, *_ = np.linalg.lstsq(A * sw, comp * sw[:, 0], rcond=None)
        grads.append((du @ c, dv @ c))
    dsu = np.stack([g[0] for g in grads], axis=1)
    dsv = np.stack([g[1] for g in grads], axis=1)
    return np.linalg.norm(np.cross(dsu, dsv), axis=1)


def _wavelets(fp, i, dz, ref):
    """Per ray: wavelet strength A (complex, phase -2 pi W), unit direction u (n, 3); and the sphere's R and C."""
    pt = fp.traces[i]
    ws = fp.samples(i, dz, ref)
    R, C = ws.radius_mm, np.array(ws.reference)
    L, M = ws.ref_L, ws.ref_M
    Nz = np.sqrt(np.maximum(1.0 - L * L - M * M, 0.0))
    u = np.stack([L, M, Nz], axis=1)
    S = C[None, :] - R * u
    dA = pt.weight * pt.cell_mm ** 2
    J = _jacobian(pt.gx, pt.gy, S[:, 0], S[:, 1], S[:, 2], pt.weight)
    if not (np.isfinite(J).all() and (J > 0).all()):
        raise OpticsError(f"the pupil of field {pt.field.field_deg:g} degrees maps onto the reference sphere "
                          "irregularly: no Huygens sum")
    p = np.ones_like(dA)
    o = pt.field.object_point
    if o is not None:  # a point at a finite distance: power per pupil area ~ cos / r^2 = dz / r^3
        r = np.sqrt((pt.gx - o[0]) ** 2 + (pt.gy - o[1]) ** 2 + (fp.setup.z_ep - o[2]) ** 2)
        p = (fp.setup.z_ep - o[2]) / r ** 3
        p = p / p.max()
    amp = pt.rays.amplitude * np.sqrt(p * J) * dA
    power = float((pt.rays.amplitude ** 2 * p * dA).sum())
    return amp * np.exp(-2j * np.pi * ws.opd_waves), u, R, C, power, pt.n_image


#: The quadratic phase term's series stops when its next term is below this (radians).
SERIES_TOLERANCE = 1e-6
MAX_SERIES_ORDER = 5
#: The non-uniform FFT's requested relative accuracy (FINUFFT's eps).
NUFFT_TOLERANCE = 1e-9
#: Grids of at most this many points (the peak's search) are summed directly, ray by ray.
DIRECT_POINTS = 25


def _series_order(eps: float) -> int | None:
    """Terms of exp(-i kappa Q^2)'s power series past the constant one that bring the next term below
    SERIES_TOLERANCE for |kappa Q^2| <= eps; None when more than MAX_SERIES_ORDER would be needed."""
    order = 0
    while eps ** (order + 1) / math.factorial(order + 1) > SERIES_TOLERANCE:
        order += 1
        if order > MAX_SERIES_ORDER:
            return None
    return order


def _field_sum(A, u, R, n_img, lam_mm, d0, s, t, tilt):
    """sum_j A_j exp(i k n' (|P - S_j| - R)) up to the |D|^2 phase, on the regular grid s (columns) x t
    (rows): type-1 non-uniform FFTs (FINUFFT), one per term of the quadratic phase's power series. A grid
    too large for the series to converge within MAX_SERIES_ORDER terms (a wide, aberrated spot) is summed
    in quadrants, each expanded exactly about its own centre (module notes): the same sum, tile by tile."""
    k = 2.0 * np.pi * n_img / lam_mm
    kappa = k / (2.0 * R)
    tx, ty = (math.tan(math.radians(a)) for a in tilt)
    a_s = u[:, 0] + u[:, 2] * ty  # d(u . D)/ds
    a_t = u[:, 1] + u[:, 2] * tx  # d(u . D)/dt
    q_max = float(np.abs(a_s).max() * np.abs(s).max() + np.abs(a_t).max() * np.abs(t).max())
    if s.size * t.size > DIRECT_POINTS and _series_order(kappa * q_max * q_max) is None:
        if s.size < 2 and t.size < 2:
            raise OpticsError("the Huygens sum's quadratic phase does not converge on one image point")
        out = np.empty((t.size, s.size), dtype=complex)
        for rows in (slice(0, t.size // 2 or 1), slice(t.size // 2 or 1, t.size)):
            for cols in (slice(0, s.size // 2 or 1), slice(s.size // 2 or 1, s.size)):
                ss, tt = s[cols], t[rows]
                if ss.size == 0 or tt.size == 0:
                    continue
                sc, tc = 0.5 * (ss[0] + ss[-1]), 0.5 * (tt[0] + tt[-1])
                shift = np.array([sc, tc, sc * ty + tc * tx])
                out[rows, cols] = _field_sum(A, u, R, n_img, lam_mm, d0 + shift, ss - sc, tt - tc, tilt)
        return out
    return _field_sum_tile(A, u, R, n_img, lam_mm, d0, s, t, a_s, a_t, k, kappa)


def _field_sum_tile(A, u, R, n_img, lam_mm, d0, s, t, a_s, a_t, k, kappa):
    """:func:`_field_sum` on one tile whose quadratic phase's series converges."""
    import finufft

    b0 = u @ d0
    # exact in the exponent: the constant and linear parts of k (u.D) - kappa (u.D)^2 about D = d0
    c = A * np.exp(1j * (k * b0 - kappa * b0 * b0))
    alpha = k * a_s - 2.0 * kappa * b0 * a_s
    beta = k * a_t - 2.0 * kappa * b0 * a_t
    ds, dt = (float(g[1] - g[0]) if g.size > 1 else 1.0 for g in (s, t))
    # a regular grid s = s0 + m ds is the NUFFT's integer modes k = m - floor(M/2) plus an offset
    ks, kt = np.arange(s.size) - s.size // 2, np.arange(t.size) - t.size // 2
    off_s, off_t = float(s[0]) - ks[0] * ds, float(t[0]) - kt[0] * dt
    c = c * np.exp(1j * (alpha * off_s + beta * off_t))
    x = np.mod(alpha * ds + np.pi, 2.0 * np.pi) - np.pi
    y = np.mod(beta * dt + np.pi, 2.0 * np.pi) - np.pi
    if s.size * t.size <= DIRECT_POINTS:  # a few points (the peak's search): the sum itself, exponent exact
        q = a_s[:, None, None] * s[None, None, :] + a_t[:, None, None] * t[None, :, None]
        ph = alpha[:, None, None] * s[None, None, :] + beta[:, None, None] * t[None, :, None] - kappa * q * q
        return np.tensordot(A * np.exp(1j * (k * b0 - kappa * b0 * b0)), np.exp(1j * ph), axes=(0, 0))
    # exp(-i kappa Q^2), Q = a_s s + a_t t: its power series, to the order that meets the tolerance
    q_max = float(np.abs(a_s).max() * np.abs(s).max() + np.abs(a_t).max() * np.abs(t).max())
    order = _series_order(kappa * q_max * q_max)
    terms = [(n, i) for n in range(order + 1) for i in range(2 * n + 1)]  # Q^(2n): C(2n, i) (a_s s)^i (a_t t)^(2n-i)
    strengths = np.stack([c * a_s ** i * a_t ** (2 * n - i) for n, i in terms])
    plan = finufft.Plan(1, (s.size, t.size), n_trans=len(terms), eps=NUFFT_TOLERANCE, isign=1)
    plan.setpts(x, y)  # one sort of the rays' points for every term
    f = plan.execute(np.ascontiguousarray(strengths, dtype=complex)).reshape(len(terms), s.size, t.size)
    S, T = s[None, :], t[:, None]
    out = np.zeros((t.size, s.size), dtype=complex)
    for (n, i), fk in zip(terms, f):
        out += (-1j * kappa) ** n / math.factorial(n) * math.comb(2 * n, i) * S ** i * T ** (2 * n - i) * fk.T
    return out


def _peak(A, u, R, n_img, lam, d0, grid, intensity, pix, tilt) -> float:
    """The PSF's highest |U|^2, refined off the grid around its brightest pixel (pattern search)."""
    row, col = np.unravel_index(int(np.argmax(intensity)), intensity.shape)
    s0, t0 = float(grid[col]), float(grid[row])
    best, h = float(intensity[row, col]), pix / 2
    offs = np.array([-1.0, 0.0, 1.0])
    for _ in range(12):
        vals = np.abs(_field_sum(A, u, R, n_img, lam, d0, s0 + offs * h, t0 + offs * h, tilt)) ** 2
        k = int(np.argmax(vals))
        if vals.flat[k] > best * (1 + 1e-12) and k != 4:
            best, s0, t0 = float(vals.flat[k]), s0 + offs[k % 3] * h, t0 + offs[k // 3] * h
        else:
            h *= 0.5
    return best


def _whole(name, v, lo, hi) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not lo <= v <= hi:
        raise InputError(f"{name} must be a whole number from {lo} to {hi}, got {v!r}")
    return int(v)


def _centroid(fp, dz, ref):
    """The primary wavelength's geometric centroid on the film (mm): where the PSF's grid is centred."""
    pt = fp.traces[0]
    ws = fp.samples(0, dz, ref)
    w = pt.weight * pt.rays.amplitude ** 2
    return float(np.average(ws.film_x, weights=w)), float(np.average(ws.film_y, weights=w))


@takes_camera
def huygens_psf(
    camera: CameraState,
    field_deg=0.0,
    *,
    wavelengths_nm=None,
    weights=None,
    defocus_mm=0.0,
    tilt_deg=(0.0, 0.0),
    pupil_samples=None,
    image_samples: int = DEFAULT_IMAGE_SAMPLES,
    pixel_um=None,
    backend: str = "auto",
    max_pupil_samples=None,
) -> HuygensPSF:
    """The Huygens PSF of ``camera`` at ``field_deg`` (degrees, Y meridian): module notes.

    Arguments as :func:`physcam.analysis.image_quality.mtf.mtf`; ``tilt_deg`` (about x, about y) tilts the film,
    ``image_samples`` points per side (8 to 1024) of ``pixel_um`` (default a quarter of lambda N_w at
    the shortest wavelength). The pupil grid follows the quarter-wave rule (:mod:`._sampling`) and is
    made fine enough that its wavelets do not alias the image grid (a grid spanning more than
    0.8 lambda / (n' du), du the direction step between pupil cells, would see the PSF's periodic copies)."""
    from . import _sampling

    dz = require_finite("defocus_mm", defocus_mm)
    try:
        tilt = tuple(require_finite("film tilt", a) for a in tilt_deg)
    except TypeError:
        raise InputError(f"tilt_deg is (about x, about y) in degrees, got {tilt_deg!r:.40}") from None
    if len(tilt) != 2 or any(abs(a) >= 45.0 for a in tilt):
        raise InputError(f"tilt_deg is (about x, about y), each under 45 degrees, got {tilt_deg!r:.40}")
    m = _whole("image_samples", image_samples, 8, MAX_IMAGE_SAMPLES)
    if pixel_um is not None:
        pixel_um = require_finite("pixel_um", pixel_um)
        if not 1e-3 < pixel_um < 1e3:
            raise InputError(f"the PSF's pixel must lie between 0.001 and 1000 µm, got {pixel_um!r}")
    cap = MAX_PUPIL_SAMPLES if max_pupil_samples is None else max_pupil_samples
    kw = dict(wavelengths_nm=wavelengths_nm, weights=weights, defocus_mm=[dz], backend=backend, max_pupil_samples=cap)
    fp = _sampling.field_pupils(camera, field_deg, pupil_samples=pupil_samples, **kw)
    for _ in range(3):  # the pupil grid must not alias the image grid (module notes)
        ref = fp.reference_point(dz)
        pix = (PIXEL_OVER_LAMBDA_N * min(fp.wavelengths_nm) * 1e-6 * _working_f_number(fp, dz, ref)
               if pixel_um is None else pixel_um * 1e-3)
        need = _pupil_samples_for(fp, dz, ref, m * pix)
        if need <= fp.n:
            break
        if pupil_samples is not None:
            raise InputError(f"a {m}-sample image grid of {pix * 1e3:.3g} µm pixels needs at least {need} pupil "
                             f"samples to be free of aliasing (given {fp.n}); give more, or leave them out to have "
                             "them chosen")
        if need > cap:
            raise OpticsError(f"a {m}-sample image grid of {pix * 1e3:.3g} µm pixels needs {need} pupil samples to be "
                              f"free of aliasing, more than {cap}: the spot is too large for a Huygens sum here "
                              "(give max_pupil_samples, or use the FFT or geometric MTF)")
        fp = _sampling.field_pupils(camera, field_deg, pupil_samples=need, **kw)
    st = fp.setup
    centre = _centroid(fp, dz, ref)
    d0 = np.array([centre[0] - ref[0], centre[1] - ref[1], 0.0])
    grid = (np.arange(m) - (m - 1) / 2) * pix
    total = np.zeros((m, m))
    strehl = None
    for i, w in enumerate(fp.weights):
        A, u, R, C, power, n_img = _wavelets(fp, i, dz, ref)
        lam = fp.wavelengths_nm[i] * 1e-6
        U = _field_sum(A, u, R, n_img, lam, d0, grid, grid, tilt)
        # power on the film: the wave's intensity times the cosine of its obliquity to the film's normal
        tx, ty = (math.tan(math.radians(a)) for a in tilt)
        normal = np.array([-ty, -tx, 1.0]) / math.sqrt(1.0 + tx * tx + ty * ty)
        cos_film = float(np.average(u @ normal, weights=np.abs(A) ** 2))
        img = np.abs(U) ** 2 * (n_img / (lam * R)) ** 2 * pix * pix * cos_film / power
        total += w * img
        if len(fp.weights) == 1:
            strehl = _peak(A, u, R, n_img, lam, d0, grid, np.abs(U) ** 2, pix, tilt) / np.abs(A).sum() ** 2
    energy = float(total.sum())
    if not energy <= 1.0 + ENERGY_SLACK:
        raise OpticsError(f"the Huygens sum put {energy:.3g} of the field's power on the image grid, more than all of "
                          f"it: its sampling ({fp.n} pupil cells, {m} image points) does not hold this field")
    return HuygensPSF(st.lens_name, fp.field.field_deg, tuple(fp.wavelengths_nm), tuple(fp.weights), st.state,
                      dz, tilt, fp.n, pix * 1e3, centre, (float(ref[0]), float(ref[1])),
                      strehl, energy, total)


#: The image grid may span at most this fraction of the alias-free extent lambda / (n' du) of the pupil grid
#: (du: the change of a ray's direction cosine from one pupil cell to the next).
ALIAS_MARGIN = 0.8


def _pupil_samples_for(fp, dz, ref, extent_mm: float) -> int:
    """The pupil grid (cells across) whose alias-free image extent holds ``extent_mm`` at every wavelength."""
    worst = 0.0
    for i in range(len(fp.traces)):
        pf = fp.pupil(i, dz, ref if len(fp.traces) > 1 else None)
        du = max(abs(pf.slope_x), abs(pf.slope_y)) * pf.cell_mm
        alias_free = pf.wavelength_nm * 1e-6 / (pf.n_image * du)
        worst = max(worst, extent_mm / (ALIAS_MARGIN * alias_free))
    return int(math.ceil(fp.n * worst / 8.0) * 8) if worst > 1.0 else fp.n


def _working_f_number(fp, dz, ref) -> float:
    """1 / (2 sin u') of the primary wavelength's beam: half the spread of its rays' directions."""
    ws = fp.samples(0, dz, ref)
    spread = max(float(np.ptp(ws.ref_L)), float(np.ptp(ws.ref_M)))
    if not spread > 0:
        raise OpticsError("the beam has no angular spread: no PSF scale")
    return 1.0 / spread


#: The MTF's PSF grid: wide enough to hold 99.7 % of an Airy pattern's power, sampled at 0.45 lambda N_w
#: (the PSF's spectrum ends at 1 / (lambda N_w): Nyquist is 0.5).
MTF_IMAGE_SAMPLES = 257
MTF_PIXEL_OVER_LAMBDA_N = 0.45


@takes_camera
def huygens_mtf(camera: CameraState, field_deg=0.0, *, frequencies, image_samples: int = MTF_IMAGE_SAMPLES,
                pixel_um=None, **kwargs):
    """(tangential, sagittal, psf): the MTF at ``frequencies`` (lp/mm) from :func:`huygens_psf` (module notes).

    The PSF's grid is ``image_samples`` of ``pixel_um`` (default 0.45 lambda N_w): the MTF is accurate to
    about the power the grid misses (``psf.energy_in_grid``; 0.3 % for a perfect lens's Airy pattern)."""
    from . import _sampling
    from ._sampling import spatial_frequencies

    nu = spatial_frequencies(frequencies)
    if pixel_um is None:  # from a coarse trace of the same field: the beam's f-number and the spot's size
        probe = _sampling.field_pupils(camera, field_deg, pupil_samples=32, check=False,
                                       **{k: kwargs[k] for k in ("wavelengths_nm", "weights", "backend") if k in kwargs})
        dz = kwargs.get("defocus_mm", 0.0)
        ref = probe.reference_point(dz)
        pixel_um = MTF_PIXEL_OVER_LAMBDA_N * min(probe.wavelengths_nm) * 1e-3 * _working_f_number(probe, dz, ref)
        # an aberrated spot's halo must fit too: the grid spans three times the rays' spread on the film
        spread = max(max(float(np.ptp(w.film_x)), float(np.ptp(w.film_y)))
                     for w in (probe.samples(i, dz, ref) for i in range(len(probe.traces))))
        need = int(math.ceil(3.0 * spread * 1e3 / pixel_um)) | 1
        image_samples = min(max(image_samples, need), MAX_IMAGE_SAMPLES - 1)
    p = huygens_psf(camera, field_deg, image_samples=image_samples, pixel_um=pixel_um, **kwargs)
    return np.clip(np.abs(p.otf(nu, "y")), 0, 1), np.clip(np.abs(p.otf(nu, "x")), 0, 1), p
