"""Modulation transfer function the way lens makers publish it.

Diffraction MTF (:func:`mtf`): the optical transfer function is the autocorrelation of the
pupil function (Goodman, *Introduction to Fourier Optics*, 6.3): OTF(nu) = sum P(u) P*(u - s) /
sum |P|^2, with the pupil sheared by s = nu lambda / (n' |dL/dx|) along x for the sagittal MTF
and by nu lambda / (n' |dM/dy|) along y for the tangential one (the slopes of the reference
directions over the pupil grid, :mod:`physcam.analysis.image_quality._pupil`). The sum runs over sub-cells of
the pupil (a binary mask resolved to a quarter cell at the pupil's edge, so the sheared overlap
measures area), with the sheared copy between sub-cells interpolated linearly in amplitude and
OPD: the MTF at any frequency comes straight from the shear, with no FFT grid to interpolate.
Sagittal: frequency along x, lines radial for a field in the Y meridian; tangential
(meridional): frequency along y, lines tangential to circles about the centre. Polychromatic:
the OTFs of the wavelengths, each normalised, summed with the weights (complex, so lateral
colour costs contrast), with every wavelength's OPD measured against the reference sphere
centred on the **primary** (first) wavelength's chief ray (Zemax's convention).

Geometric MTF (:func:`geometric_mtf`): the Fourier transform of the spot (the rays' film
positions weighted by their pupil area), good when aberrations are many waves and diffraction
no longer matters (Smith, *Modern Optical Engineering*, 11.9).

Through focus (:func:`through_focus_mtf`): the MTF at chosen frequencies as the film moves; the
rays are traced once and only their last leg changes. The vendor chart (:func:`mtf_chart`):
sagittal and tangential MTF at 10, 20 and 40 lp/mm against image height, in the d, F and C lines
(equal weights, d the primary) unless told otherwise: white light where the prescription gives its
glasses dispersion, monochromatic where it gives none (:func:`spectrum_words` says which), the fields
placed by real chief rays aimed back from each image height on the film.

Frequencies in cycles (line pairs) per mm on the film; lengths in mm; see docs/image-quality.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...data.default_sensor import DEFAULT_SENSOR_HALF_DIAGONAL_MM
from ...errors import InputError, OpticsError, require_finite
from ...figures import PALETTE, fit_title, styled
from ...optics.state import CameraState, OfACamera, takes_camera
from ._sampling import MAX_FREQUENCIES, spatial_frequencies

__all__ = ["MTFCurve", "ThroughFocusMTF", "MTFChart", "mtf", "geometric_mtf", "through_focus_mtf", "mtf_chart",
           "diffraction_limited_mtf", "CHART_FREQUENCIES", "WHITE_LIGHT_NM", "spectrum_words"]

#: The frequencies of a lens maker's MTF chart (lp/mm): contrast (10), resolution (20, 40).
CHART_FREQUENCIES = (10.0, 20.0, 40.0)
@takes_camera
def spectrum_words(camera: CameraState, wavelengths_nm) -> str:
    """What light an MTF is in, in words that follow the lens data: "white light (d, F, C)" only where
    the prescription gives its glasses dispersion; "monochromatic: the prescription gives no dispersion"
    where none of them has any (the wavelengths then differ in diffraction alone); a note of how many
    glasses have none where some do (:func:`physcam.optics.glass.glasses_without_dispersion`)."""
    from ...optics.glass import glasses_without_dispersion

    wls = tuple(float(w) for w in np.atleast_1d(wavelengths_nm))
    listed = ", ".join(f"{w:g}" for w in wls) + " nm"
    if len(wls) == 1:
        return f"{listed} (one wavelength)"
    flat, n = glasses_without_dispersion(camera.lens)
    if n and flat == n:
        return f"monochromatic: the prescription gives no dispersion; {listed} differ in diffraction only"
    light = "white light (d, F, C)" if wls == WHITE_LIGHT_NM else listed
    if flat:
        return f"{light}; {flat} of {n} glasses have no dispersion in the prescription (no colour from them)"
    return light


#: White light for charts: the d, F and C lines, equal weights (d first: the primary, whose chief ray
#: is the reference of the polychromatic OTF).
WHITE_LIGHT_NM = (587.5618, 486.1327, 656.2725)
MAX_FIELDS = 41


def diffraction_limited_mtf(frequency, cutoff):
    """MTF of an aberration-free circular pupil: (2/pi)(acos x - x sqrt(1 - x^2)), x = nu / nu_c
    (Goodman, *Introduction to Fourier Optics*, eq. 6-32); 0 beyond the cut-off."""
    nu = np.asarray(frequency, dtype=float)
    c = require_finite("cut-off frequency", cutoff)
    if not c > 0:
        raise InputError(f"cut-off frequency must be > 0, got {c:g}")
    x = np.clip(np.abs(nu) / c, 0.0, 1.0)
    out = (2.0 / np.pi) * (np.arccos(x) - x * np.sqrt(1.0 - x * x))
    return float(out) if out.ndim == 0 else out


def _otf(fp, freqs, axis: int, dz: float, *, aberrated: bool = True) -> np.ndarray:
    """Polychromatic complex OTF at ``freqs`` along ``axis`` (0 tangential / y, 1 sagittal / x)."""
    from . import _pupil as P

    ref = fp.reference_point(dz) if len(fp.traces) > 1 else None
    out = np.zeros(len(freqs), dtype=complex)
    for i, w in enumerate(fp.weights):
        pf = fp.pupil(i, dz, ref)
        step = pf.freq_per_cell_y if axis == 0 else pf.freq_per_cell_x
        for k, nu in enumerate(freqs):
            out[k] += w * (1.0 if nu == 0 else P.shear_otf(pf, nu / step, axis, aberrated=aberrated))
    return out


def _cutoffs(fp, dz):
    from . import _pupil as P

    pf = [fp.pupil(i, dz, fp.reference_point(dz) if len(fp.traces) > 1 else None) for i in range(len(fp.traces))]
    t = max(P.cutoff_cells(p, 0) * p.freq_per_cell_y for p in pf)
    s = max(P.cutoff_cells(p, 1) * p.freq_per_cell_x for p in pf)
    return float(t), float(s)


@dataclass
class MTFCurve(OfACamera):
    """Tangential and sagittal MTF of one field against frequency (module notes), of ``camera``."""

    lens_name: str
    field_deg: float
    chief_image_height_mm: float
    wavelengths_nm: tuple[float, ...]
    weights: tuple[float, ...]
    camera: CameraState  # the camera analysed: its focus and f-stop (.focus_from_film_mm, .fstop)
    defocus_mm: float
    method: str  # "diffraction" or "geometric"
    pupil_samples: int
    frequencies_lpmm: np.ndarray = field(repr=False)
    tangential: np.ndarray = field(repr=False)
    sagittal: np.ndarray = field(repr=False)
    diffraction_limit_tangential: np.ndarray | None = field(default=None, repr=False)
    diffraction_limit_sagittal: np.ndarray | None = field(default=None, repr=False)
    cutoff_tangential_lpmm: float | None = None
    cutoff_sagittal_lpmm: float | None = None

    def to_dict(self) -> dict:
        def lst(a):
            return None if a is None else [float(v) for v in a]

        return {"lens": self.lens_name, "field_deg": self.field_deg, "chief_image_height_mm": self.chief_image_height_mm,
                "wavelengths_nm": list(self.wavelengths_nm), "weights": list(self.weights), "fstop": self.fstop,
                "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
                "defocus_mm": self.defocus_mm, "method": self.method, "pupil_samples": self.pupil_samples,
                "frequencies_lpmm": lst(self.frequencies_lpmm), "tangential": lst(self.tangential),
                "sagittal": lst(self.sagittal), "diffraction_limit_tangential": lst(self.diffraction_limit_tangential),
                "diffraction_limit_sagittal": lst(self.diffraction_limit_sagittal),
                "cutoff_tangential_lpmm": self.cutoff_tangential_lpmm, "cutoff_sagittal_lpmm": self.cutoff_sagittal_lpmm,
                "definition": "tangential: frequency along y (the field's meridian), sagittal: along x; "
                              "frequencies in lp/mm on the film"}

    @styled
    def plot(self, path=None, *, force: bool = False):
        from .._plot import figure, save

        fig, ax = figure(5.4, 3.8)
        f = self.frequencies_lpmm
        if self.diffraction_limit_tangential is not None:
            ax.plot(f, self.diffraction_limit_tangential, color="0.6", lw=0.8, label="diffraction limit (T)")
        ax.plot(f, self.tangential, color=PALETTE[0], ls="--", label="tangential")
        ax.plot(f, self.sagittal, color=PALETTE[0], ls="-", label="sagittal")
        ax.set_ylim(0, 1.02)
        ax.set_xlim(0, float(f.max()) if f.size else 1.0)
        ax.set_xlabel("spatial frequency (lp/mm)")
        ax.set_ylabel("MTF")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        wl = ", ".join(f"{w:g}" for w in self.wavelengths_nm)
        ax.set_title(f"{self.lens_name}\n{self.method} MTF, {self.field_deg:g} deg ({self.chief_image_height_mm:.2f} mm), "
                     f"f/{self.fstop:.3g}, {wl} nm", fontsize=8)
        return save(fig, path, force)


def _common(camera, field_deg, wavelengths_nm, weights, defocus_mm, pupil_samples, backend, frequencies,
            min_frequency, max_pupil_samples):
    from . import _sampling

    dz = require_finite("defocus_mm", defocus_mm)
    fp = _sampling.field_pupils(camera, field_deg, wavelengths_nm=wavelengths_nm, weights=weights,
                                defocus_mm=[dz], pupil_samples=pupil_samples, min_frequency=min_frequency,
                                waves_per_cell=_sampling.WAVES_PER_CELL_MTF, backend=backend,
                                max_pupil_samples=max_pupil_samples)
    return fp, dz


def _default_freqs(fp, dz, points):
    t, s = _cutoffs(fp, dz)
    return np.linspace(0.0, max(t, s), points)


def _points(points):
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)) or not 2 <= points <= MAX_FREQUENCIES:
        raise InputError(f"points must be a whole number from 2 to {MAX_FREQUENCIES}, got {points!r}")
    return int(points)


@takes_camera
def mtf(
    camera: CameraState,
    field_deg=0.0,
    *,
    frequencies=None,
    wavelengths_nm=None,
    weights=None,
    defocus_mm=0.0,
    pupil_samples=None,
    points: int = 65,
    backend: str = "auto",
    max_pupil_samples=None,
) -> MTFCurve:
    """Diffraction MTF of ``camera`` (:func:`physcam.optics.state.camera_state`: the lens focused and
    stopped, its iris shape) at ``field_deg`` (degrees, Y meridian), tangential and sagittal.

    ``frequencies`` (lp/mm; default ``points`` from 0 to the cut-off), ``wavelengths_nm`` and
    ``weights`` (default the camera's; the first is the primary), ``defocus_mm`` (film moved away
    from the lens), ``pupil_samples`` (default chosen by the sampling rules), ``max_pupil_samples``
    (cap on the grid the rules may choose, default 1024). Also returns the diffraction limit of the
    same (vignetted) pupil.
    """
    freqs = None if frequencies is None else spatial_frequencies(frequencies)
    pts = _points(points)
    fmin = None if freqs is None or not (freqs > 0).any() else float(freqs[freqs > 0].min())
    fp, dz = _common(camera, field_deg, wavelengths_nm, weights, defocus_mm, pupil_samples, backend, freqs, fmin,
                     max_pupil_samples)
    if freqs is None:
        freqs = _default_freqs(fp, dz, pts)
    t = np.abs(_otf(fp, freqs, 0, dz))
    s = np.abs(_otf(fp, freqs, 1, dz))
    dt = np.abs(_otf(fp, freqs, 0, dz, aberrated=False))
    ds = np.abs(_otf(fp, freqs, 1, dz, aberrated=False))
    ct, cs = _cutoffs(fp, dz)
    st = fp.setup
    h = fp.samples(0, dz).chief_film_xy[1]
    return MTFCurve(st.lens_name, fp.field.field_deg, h, tuple(fp.wavelengths_nm), tuple(fp.weights), st.state,
                    dz, "diffraction", fp.n, freqs, np.clip(t, 0, 1), np.clip(s, 0, 1),
                    np.clip(dt, 0, 1), np.clip(ds, 0, 1), ct, cs)


@takes_camera
def geometric_mtf(
    camera: CameraState,
    field_deg=0.0,
    *,
    frequencies=None,
    wavelengths_nm=None,
    weights=None,
    defocus_mm=0.0,
    pupil_samples=None,
    points: int = 65,
    backend: str = "auto",
) -> MTFCurve:
    """Geometric MTF (the Fourier transform of the spot): |sum w exp(-2 pi i nu y)| / sum w over the
    rays' film positions y (x for sagittal) from the primary chief ray's point, w their pupil area.
    Arguments as :func:`mtf`; the default frequencies run to the diffraction cut-off."""
    from . import _sampling

    freqs = None if frequencies is None else spatial_frequencies(frequencies)
    pts = _points(points)
    dz = require_finite("defocus_mm", defocus_mm)
    n = _sampling.pupil_samples_arg(pupil_samples) or 64
    fp = _sampling.field_pupils(camera, field_deg, wavelengths_nm=wavelengths_nm, weights=weights, defocus_mm=[dz],
                                pupil_samples=n, backend=backend, check=False)
    if freqs is None:
        freqs = _default_freqs(fp, dz, pts)
    ref = fp.reference_point(dz)
    t = np.zeros(len(freqs), dtype=complex)
    s = np.zeros(len(freqs), dtype=complex)
    for i, w in enumerate(fp.weights):
        pt = fp.traces[i]
        ws = fp.samples(i, dz, ref)
        wt = pt.weight * pt.rays.amplitude ** 2
        wt = wt / wt.sum()
        y = ws.film_y - ref[1]
        x = ws.film_x - ref[0]
        t += w * (np.exp(-2j * np.pi * np.outer(freqs, y)) @ wt)
        s += w * (np.exp(-2j * np.pi * np.outer(freqs, x)) @ wt)
    st = fp.setup
    return MTFCurve(st.lens_name, fp.field.field_deg, float(ref[1]), tuple(fp.wavelengths_nm), tuple(fp.weights),
                    st.state, dz, "geometric", fp.n, freqs, np.clip(np.abs(t), 0, 1),
                    np.clip(np.abs(s), 0, 1))


@dataclass
class ThroughFocusMTF(OfACamera):
    """MTF at fixed frequencies against film position (``defocus_mm``: film moved away from the lens), of
    ``camera``."""

    lens_name: str
    field_deg: float
    wavelengths_nm: tuple[float, ...]
    weights: tuple[float, ...]
    camera: CameraState  # the camera analysed: its focus and f-stop (.focus_from_film_mm, .fstop)
    pupil_samples: int
    frequencies_lpmm: np.ndarray = field(repr=False)
    defocus_mm: np.ndarray = field(repr=False)
    tangential: np.ndarray = field(repr=False)  # (frequencies, defocus)
    sagittal: np.ndarray = field(repr=False)

    def best_focus_mm(self) -> dict:
        """Defocus (mm) of the highest mean of tangential and sagittal MTF, per frequency."""
        m = 0.5 * (self.tangential + self.sagittal)
        return {float(f): float(self.defocus_mm[int(np.argmax(row))]) for f, row in zip(self.frequencies_lpmm, m)}

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "field_deg": self.field_deg, "wavelengths_nm": list(self.wavelengths_nm),
                "weights": list(self.weights), "fstop": self.fstop,
                "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
                "pupil_samples": self.pupil_samples, "frequencies_lpmm": [float(v) for v in self.frequencies_lpmm],
                "defocus_mm": [float(v) for v in self.defocus_mm],
                "tangential": [[float(v) for v in r] for r in self.tangential],
                "sagittal": [[float(v) for v in r] for r in self.sagittal],
                "best_focus_mm": {str(k): v for k, v in self.best_focus_mm().items()},
                "definition": "defocus: the film moved away from the lens (+) from the focus plane, mm"}

    @styled
    def plot(self, path=None, *, force: bool = False):
        from .._plot import figure, save

        fig, ax = figure(5.4, 3.8)
        for k, f in enumerate(self.frequencies_lpmm):
            ax.plot(self.defocus_mm * 1e3, self.tangential[k], color=PALETTE[k % len(PALETTE)], ls="--", label=f"{f:g} lp/mm T")
            ax.plot(self.defocus_mm * 1e3, self.sagittal[k], color=PALETTE[k % len(PALETTE)], ls="-", label=f"{f:g} lp/mm S")
        ax.set_ylim(0, 1.02)
        ax.set_xlabel("film shift from focus (µm, + away from the lens)")
        ax.set_ylabel("MTF")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        ax.set_title(f"{self.lens_name}\nthrough-focus MTF, {self.field_deg:g} deg, f/{self.fstop:.3g}", fontsize=8)
        return save(fig, path, force)


@takes_camera
def through_focus_mtf(
    camera: CameraState,
    field_deg=0.0,
    frequencies=CHART_FREQUENCIES,
    *,
    defocus_mm=None,
    wavelengths_nm=None,
    weights=None,
    pupil_samples=None,
    backend: str = "auto",
    max_pupil_samples=None,
) -> ThroughFocusMTF:
    """MTF at ``frequencies`` (lp/mm) as the film moves by ``defocus_mm`` (a sequence, mm; default
    41 steps over +-20 lambda N^2 about the focus plane, ten times the Rayleigh depth of focus
    +-2 lambda N^2, enough to hold the best focus of a lens with spherical aberration). Other
    arguments as :func:`mtf`."""
    from . import _sampling

    freqs = spatial_frequencies(frequencies)
    st = None
    if defocus_mm is None:
        from . import _pupil as P

        st = P.setup(camera, backend=backend)
        wls, _ = _sampling.wavelengths_and_weights(camera, wavelengths_nm, weights)
        span = 20.0 * wls[0] * 1e-6 * st.fstop ** 2
        dzs = np.linspace(-span, span, 41)
    else:
        if isinstance(defocus_mm, (str, bytes)):
            raise InputError(f"defocus_mm must be numbers in mm, got {defocus_mm!r:.60}")
        try:
            seq = np.atleast_1d(np.asarray(defocus_mm, dtype=object)).ravel().tolist()
        except Exception:  # noqa: BLE001
            raise InputError(f"defocus_mm must be numbers in mm, got {defocus_mm!r:.60}") from None
        dzs = np.array([require_finite("defocus_mm", v) for v in seq], dtype=float)
        if not 1 <= dzs.size <= 401 or (np.abs(dzs) > 100.0).any():
            raise InputError("give 1 to 401 film shifts within +-100 mm")
    fmin = float(freqs[freqs > 0].min()) if (freqs > 0).any() else None
    fp = _sampling.field_pupils(camera, field_deg, wavelengths_nm=wavelengths_nm, weights=weights,
                                defocus_mm=[float(dzs.min()), float(dzs.max())], pupil_samples=pupil_samples,
                                min_frequency=fmin, waves_per_cell=_sampling.WAVES_PER_CELL_MTF, backend=backend,
                                st=st, max_pupil_samples=max_pupil_samples)
    t = np.array([np.abs(_otf(fp, freqs, 0, float(dz))) for dz in dzs]).T
    s = np.array([np.abs(_otf(fp, freqs, 1, float(dz))) for dz in dzs]).T
    st = fp.setup
    return ThroughFocusMTF(st.lens_name, fp.field.field_deg, tuple(fp.wavelengths_nm), tuple(fp.weights), st.state,
                           fp.n, freqs, dzs, np.clip(t, 0, 1), np.clip(s, 0, 1))


@dataclass
class MTFChart(OfACamera):
    """The lens maker's chart of ``camera``: MTF at ``frequencies_lpmm`` against image height (module notes).

    ``sagittal`` and ``tangential`` have shape (fields, frequencies)."""

    lens_name: str
    camera: CameraState  # the camera analysed: its focus and f-stop (.focus_from_film_mm, .fstop)
    wavelengths_nm: tuple[float, ...]
    weights: tuple[float, ...]
    frequencies_lpmm: tuple[float, ...]
    image_heights_mm: np.ndarray = field(repr=False)
    fields_deg: np.ndarray = field(repr=False)
    sagittal: np.ndarray = field(repr=False)
    tangential: np.ndarray = field(repr=False)
    pupil_samples: np.ndarray = field(repr=False)
    notes: tuple[str, ...] = ()
    #: the film's place: moved this far (mm, + away from the lens) from the paraxial image plane of the
    #: focus mark, by ``focus_rule``
    defocus_mm: float = 0.0
    focus_rule: str = "the paraxial image plane of the focus mark"
    #: the light in words (:func:`spectrum_words`): "white light (d, F, C)" only where the lens has dispersion
    spectrum: str = ""

    def focus_words(self) -> str:
        """Which focus the chart is at, in words (its title and its JSON's ``film``)."""
        if self.defocus_mm == 0.0:
            return self.focus_rule
        return f"{self.focus_rule}, {self.defocus_mm * 1e3:+.1f} µm from the paraxial image plane"

    def to_dict(self) -> dict:
        return {
            "lens": self.lens_name, "fstop": self.fstop,
            "film": {"defocus_mm": self.defocus_mm, "shift_um": self.defocus_mm * 1e3, "rule": self.focus_rule,
                     "words": self.focus_words()},
            "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
            "wavelengths_nm": list(self.wavelengths_nm), "weights": list(self.weights), "spectrum": self.spectrum,
            "frequencies_lpmm": list(self.frequencies_lpmm),
            "rows": [{"image_height_mm": float(h), "field_deg": float(a), "pupil_samples": int(n),
                      "sagittal": {f"{f:g}": float(v) for f, v in zip(self.frequencies_lpmm, s)},
                      "tangential": {f"{f:g}": float(v) for f, v in zip(self.frequencies_lpmm, t)}}
                     for h, a, n, s, t in zip(self.image_heights_mm, self.fields_deg, self.pupil_samples,
                                              self.sagittal, self.tangential)],
            "points": self.points(),
            "notes": list(self.notes),
            "definition": "diffraction MTF at the film plane focused at the mark; sagittal: lines radial, "
                          "tangential: lines tangential to circles about the centre; image height of the real "
                          "chief ray at the primary wavelength",
        }

    def points(self) -> list[dict]:
        """The chart as flat rows, one per image height and frequency (what ``physcam mtf --csv`` prints):
        ``image_height_mm``, ``field_deg``, ``frequency_lpmm``, ``sagittal``, ``tangential``, ``pupil_samples``."""
        return [{"image_height_mm": float(h), "field_deg": float(a), "frequency_lpmm": float(f), "sagittal": float(sv),
                 "tangential": float(tv), "pupil_samples": int(n)}
                for h, a, n, s, t in zip(self.image_heights_mm, self.fields_deg, self.pupil_samples, self.sagittal,
                                         self.tangential)
                for f, sv, tv in zip(self.frequencies_lpmm, s, t)]

    def table(self) -> str:
        """The chart as a text table (one row per image height)."""
        head = f"{'height mm':>9} {'field deg':>9}" + "".join(f" {f'{f:g} S':>7} {f'{f:g} T':>7}" for f in
                                                            self.frequencies_lpmm)
        lines = [head]
        for h, a, s, t in zip(self.image_heights_mm, self.fields_deg, self.sagittal, self.tangential):
            lines.append(f"{h:9.2f} {a:9.2f}" + "".join(f" {sv:7.3f} {tv:7.3f}" for sv, tv in zip(s, t)))
        return "\n".join(lines)

    def text_chart(self, width: int = 60, height: int = 16) -> str:
        """The chart drawn in characters: MTF 0-1 up, image height across; per frequency a letter,
        upper case sagittal, lower case tangential (a/A for the first frequency...)."""
        grid = [[" "] * width for _ in range(height)]
        hmax = float(self.image_heights_mm.max()) or 1.0
        xs = np.linspace(0.0, hmax, width)
        for k in range(len(self.frequencies_lpmm)):
            for vals, ch in ((self.tangential[:, k], "abcdefghij"[k % 10]), (self.sagittal[:, k], "ABCDEFGHIJ"[k % 10])):
                ys = np.interp(xs, self.image_heights_mm, vals)
                for c, v in enumerate(ys):
                    r = height - 1 - int(round(float(np.clip(v, 0, 1)) * (height - 1)))
                    grid[r][c] = ch
        out = []
        for r, row in enumerate(grid):
            v = 1.0 - r / (height - 1)
            label = f"{v:4.1f} |" if r % 3 == 0 or r == height - 1 else "     |"
            out.append(label + "".join(row))
        out.append("     +" + "-" * width)
        out.append(f"      0{'image height (mm)':^{width - 10}}{hmax:>8.1f}")
        keys = ", ".join(f"{'ABCDEFGHIJ'[k % 10]}/{'abcdefghij'[k % 10]} {f:g} lp/mm"
                         for k, f in enumerate(self.frequencies_lpmm))
        out.append(f"      {keys} (upper case sagittal, lower case tangential)")
        return "\n".join(out)

    @styled
    def plot(self, path=None, *, force: bool = False, units: str = "m"):
        """The vendor chart: solid sagittal, dashed tangential, thicker lines for lower frequencies; the
        focus in the title in ``units`` (m, or ft for feet and inches; image heights stay in mm)."""
        from ...units import format_distance
        from .._plot import figure, per_unit, save

        per_unit(units)

        fig, ax = figure(6.0, 4.0)
        nf = len(self.frequencies_lpmm)
        for k, f in enumerate(self.frequencies_lpmm):
            lw = 2.2 - 1.4 * k / max(1, nf - 1)
            ax.plot(self.image_heights_mm, self.sagittal[:, k], color=PALETTE[k % len(PALETTE)], lw=lw, ls="-", label=f"{f:g} lp/mm S")
            ax.plot(self.image_heights_mm, self.tangential[:, k], color=PALETTE[k % len(PALETTE)], lw=lw, ls="--",
                    label=f"{f:g} lp/mm T")
        ax.set_xlim(0, float(self.image_heights_mm.max()))
        ax.set_ylim(0, 1.0)
        ax.set_xlabel("image height (mm from the centre)")
        ax.set_ylabel("MTF")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=2, loc="lower left")
        foc = "infinity" if math.isinf(self.focus_from_film_mm) else format_distance(self.focus_from_film_mm, units)
        wl = self.spectrum or ", ".join(f"{w:g}" for w in self.wavelengths_nm) + " nm"
        shift = "" if self.defocus_mm == 0.0 else f", film {self.defocus_mm * 1e3:+.1f} µm (best focus)"
        ax.set_title(fit_title(f"{self.lens_name}: MTF at f/{self.fstop:.3g}, focus {foc}{shift}, {wl} "
                               "(solid sagittal, dashed tangential)", 5.6, fontsize=8), fontsize=8)
        return save(fig, path, force)


@takes_camera
def mtf_chart(
    camera: CameraState,
    *,
    max_image_height_mm=DEFAULT_SENSOR_HALF_DIAGONAL_MM,
    n_fields: int = 15,
    image_heights_mm=None,
    frequencies=CHART_FREQUENCIES,
    wavelengths_nm=WHITE_LIGHT_NM,
    weights=None,
    pupil_samples=None,
    backend: str = "auto",
    max_pupil_samples=256,
    progress=None,
    best_focus=None,
    best_focus_rule: str = "axis",
    method: str = "fft",
) -> MTFChart:
    """The vendor MTF chart of ``camera``: sagittal and tangential MTF at ``frequencies`` (default 10,
    20, 40 lp/mm) against image height, ``n_fields`` heights from 0 to ``max_image_height_mm``
    (default 15.55 mm, the corner of the default sensor, Super 35 24.89 x 18.66 mm:
    :data:`physcam.data.default_sensor.DEFAULT_SENSOR`, as the CLI; 21.63 mm is a 36 x 24 mm corner) or the ``image_heights_mm`` given; the d, F and C lines by
    default. The pupil grids follow the MTF sampling rules up to ``max_pupil_samples`` (default 256,
    so a chart takes seconds). ``progress(done, total)`` is called after each field.

    The film is at the paraxial image plane of the focus mark unless ``best_focus`` (a frequency,
    lp/mm) moves it to where the MTF there is highest (:func:`best_focus_mm`): ``best_focus_rule``
    "axis" (the mean of S and T on the axis) or "field" (that mean averaged over the image, each
    height weighted by the area of its ring, as lens makers weigh a chart). The chart says which
    (``focus_rule``, ``defocus_mm``). ``method`` "huygens" computes each field's MTF from its Huygens PSF
    (:func:`physcam.analysis.image_quality.huygens.huygens_mtf`; slower, no pupil-to-direction map) instead of the
    pupil's autocorrelation ("fft")."""
    from . import _pupil as P
    from . import _sampling

    freqs = spatial_frequencies(frequencies)
    if image_heights_mm is not None:
        if isinstance(image_heights_mm, (str, bytes)):
            raise InputError(f"image heights must be numbers in mm, got {image_heights_mm!r:.60}")
        try:
            seq = np.atleast_1d(np.asarray(image_heights_mm, dtype=object)).ravel().tolist()
        except Exception:  # noqa: BLE001
            raise InputError(f"image heights must be numbers in mm, got {image_heights_mm!r:.60}") from None
        hs = np.array([require_finite("image height", v) for v in seq], dtype=float)
        if not 1 <= hs.size <= MAX_FIELDS:
            raise InputError(f"give 1 to {MAX_FIELDS} image heights, got {hs.size}")
    else:
        top = require_finite("max_image_height_mm", max_image_height_mm)
        if not 0 < top <= 500:
            raise InputError(f"the largest image height must lie between 0 and 500 mm, got {top:g}")
        if isinstance(n_fields, bool) or not isinstance(n_fields, (int, np.integer)) or not 2 <= n_fields <= MAX_FIELDS:
            raise InputError(f"n_fields must be a whole number from 2 to {MAX_FIELDS}, got {n_fields!r}")
        hs = np.linspace(0.0, top, int(n_fields))
    if (hs < 0).any() or (hs > 500).any():
        raise InputError("image heights must lie between 0 and 500 mm from the centre")
    wls, wts = _sampling.wavelengths_and_weights(camera, wavelengths_nm, weights)
    cap = _sampling.pupil_samples_arg(max_pupil_samples)
    n_user = _sampling.pupil_samples_arg(pupil_samples)
    if n_user is not None and cap is not None and n_user > cap:
        raise InputError(f"pupil_samples {n_user} exceeds the chart's max_pupil_samples {cap}")
    if method not in ("fft", "huygens"):
        raise InputError(f"the MTF method is 'fft' or 'huygens', got {method!r}")
    st = P.setup(camera, backend=backend)
    fmin = float(freqs[freqs > 0].min()) if (freqs > 0).any() else None
    try:  # every height at once; past the image circle, one at a time to say where it ends
        angles = P.fields_for_image_heights(st, hs, wls[0])
    except OpticsError:
        angles = np.zeros(hs.size)
        for i, h in enumerate(hs):
            try:
                angles[i] = P.field_for_image_height(st, float(h), wls[0])
            except OpticsError as exc:
                edge = P.image_circle_radius(st, wls[0], float(h))
                raise OpticsError(f"{exc}; the image circle ends near {edge:.1f} mm: chart up to there "
                                  f"(max_image_height_mm, --max-height)") from None
    dz, rule = 0.0, "the paraxial image plane of the focus mark"
    if best_focus is not None:
        dz, rule = best_focus_mm(camera, best_focus, heights_mm=hs, angles_deg=angles, rule=best_focus_rule,
                                 wavelengths_nm=wls, weights=wts, st=st, max_pupil_samples=max_pupil_samples)
    if progress is not None:
        progress(0, hs.size)
    sag = np.zeros((hs.size, freqs.size))
    tan = np.zeros((hs.size, freqs.size))
    ns = np.zeros(hs.size, dtype=int)
    n_guess = pupil_samples if isinstance(pupil_samples, (int, np.integer)) and pupil_samples > 0 else 64
    per_field = n_guess ** 2 * len(wls)
    done = 0
    if method == "huygens":
        from .huygens import huygens_mtf

        for i, a in enumerate(angles):
            tan[i], sag[i], p = huygens_mtf(camera, float(a), frequencies=freqs, wavelengths_nm=wls, weights=wts,
                                            defocus_mm=dz, backend=backend)
            ns[i] = p.pupil_samples
            if progress is not None:
                progress(i + 1, hs.size)
        return MTFChart(st.lens_name, st.state, tuple(wls), tuple(wts),
                        tuple(float(f) for f in freqs), hs, angles, np.clip(sag, 0, 1), np.clip(tan, 0, 1), ns,
                        ("method: Huygens PSF per field (physcam.analysis.image_quality.huygens)",), float(dz), rule,
                        spectrum_words(camera, wls))
    # fields in runs that fit one tracing batch; each run's pupils are freed before the next
    for run in _sampling._chunks(list(range(hs.size)), lambda i: per_field, _sampling.RAYS_PER_BATCH):
        fps = _sampling.fields_pupils(camera, angles[run], wavelengths_nm=wls, weights=wts, pupil_samples=pupil_samples,
                                      min_frequency=fmin, waves_per_cell=_sampling.WAVES_PER_CELL_MTF, st=st,
                                      max_pupil_samples=max_pupil_samples, defocus_mm=[dz])
        for k, i in enumerate(run):
            tan[i] = np.abs(_otf(fps[k], freqs, 0, dz))
            sag[i] = np.abs(_otf(fps[k], freqs, 1, dz))
            ns[i] = fps[k].n
            fps[k] = None  # its sub-cell arrays are large: free them before the next field's
            done += 1
            if progress is not None:
                progress(done, hs.size)
    return MTFChart(st.lens_name, st.state, tuple(wls), tuple(wts),
                    tuple(float(f) for f in freqs), hs, angles, np.clip(sag, 0, 1), np.clip(tan, 0, 1), ns,
                    defocus_mm=float(dz), focus_rule=rule, spectrum=spectrum_words(camera, wls))


#: Fields the field-weighted best focus averages over, as fractions of the chart's largest height.
BEST_FOCUS_HEIGHTS = (0.0, 0.3, 0.55, 0.75, 0.9)


def _least_spread_mm(fps) -> float:
    """The film shift (mm) of the smallest second moment of the rays' film positions about their centroid,
    summed over the pupils given: each ray's film point moves by its slope times the shift, so the moment
    is a quadratic in the shift and its minimum is closed-form (Smith, *Modern Optical Engineering*, 11.2)."""
    num = den = 0.0
    for fp in fps:
        for i in range(len(fp.traces)):
            pt = fp.traces[i]
            w = pt.weight * pt.rays.amplitude ** 2
            w = w / w.sum()
            ws = fp.samples(i, 0.0)
            for pos, slope in ((ws.film_x, pt.rays.L / pt.rays.N), (ws.film_y, pt.rays.M / pt.rays.N)):
                p0, sl = pos - w @ pos, slope - w @ slope
                num += float(w @ (p0 * sl))
                den += float(w @ (sl * sl))
    return -num / den if den > 0 else 0.0


def best_focus_mm(camera, frequency, *, heights_mm, angles_deg, rule, wavelengths_nm, weights, st,
                  max_pupil_samples=256) -> tuple[float, str]:
    """(film shift mm, its rule in words): where the mean of S and T MTF at ``frequency`` is highest,
    on the axis (``rule`` "axis") or averaged over the image with ring-area weights ("field"). The
    search scans 41 film positions over +-20 lambda N^2 (ten Rayleigh depths of focus) about the
    film shift of the least geometric spread (:func:`_least_spread_mm`, closed form), then 21 between
    the best one's neighbours; the pupils are traced once per stage and each film position costs
    only their last leg."""
    from . import _pupil as P
    from . import _sampling

    nu = spatial_frequencies([frequency], "best-focus frequency")
    if not nu[0] > 0:
        raise InputError("the best-focus frequency must be above 0 lp/mm")
    if rule not in ("axis", "field"):
        raise InputError(f"the best-focus rule is 'axis' or 'field', got {rule!r}")
    if rule == "axis":
        ws = np.array([1.0])
        angles = [0.0]
    else:
        top = float(np.max(heights_mm))
        hs = np.array(BEST_FOCUS_HEIGHTS) * top
        edges = np.concatenate([[0.0], 0.5 * (hs[1:] + hs[:-1]), [top]])
        ws = edges[1:] ** 2 - edges[:-1] ** 2  # the area of each height's ring
        angles = [0.0] + [P.field_for_image_height(st, float(h), wavelengths_nm[0]) for h in hs[1:]]
    kw = dict(wavelengths_nm=wavelengths_nm, weights=weights, st=st)

    def merit(fps, dz):
        m = [0.5 * (abs(_otf(fp, nu, 0, dz)[0]) + abs(_otf(fp, nu, 1, dz)[0])) for fp in fps]
        return float(np.dot(ws, m) / ws.sum())

    lam_n2 = wavelengths_nm[0] * 1e-6 * st.fstop ** 2
    # 1. the scan: 41 film positions over +-20 lambda N^2 about the least geometric spread, on a 64-cell
    #    grid whose sampling is not checked so far from focus (it is where the MTF matters: step 2)
    coarse_fps = _sampling.fields_pupils(camera, angles, pupil_samples=64, check=False, **kw)
    centre = _least_spread_mm(coarse_fps)
    coarse = centre + np.linspace(-20.0, 20.0, 41) * lam_n2
    k = int(np.argmax([merit(coarse_fps, d) for d in coarse]))
    # 2. 21 positions between the best one's neighbours, on grids that meet the sampling rules there
    lo, hi = coarse[max(k - 1, 0)], coarse[min(k + 1, coarse.size - 1)]
    fps = _sampling.fields_pupils(camera, angles, min_frequency=float(nu[0]), waves_per_cell=_sampling.WAVES_PER_CELL_MTF,
                                  defocus_mm=[lo, hi], max_pupil_samples=max_pupil_samples, **kw)
    fine = np.linspace(lo, hi, 21)
    best = float(fine[int(np.argmax([merit(fps, d) for d in fine]))])
    where = "on the axis" if rule == "axis" else "averaged over the image by ring area"
    return best, f"best focus for {nu[0]:g} lp/mm {where}"
