"""Fields' pupils at one or more wavelengths, sampled finely enough (shared by wavefront, PSF, MTF).

Sampling rules (limits in :mod:`physcam.analysis.image_quality._pupil`):

- **phase**: the OPD may change by at most a given number of waves between neighbouring cells,
  at every wavelength and film plane asked for: a quarter wave for the wavefront and the PSF
  (beyond half a wave per cell the FFT PSF aliases, and the Strehl ratio's sum loses accuracy
  well before), one wave for the MTF, whose sums see only the *difference* of the OPD across a
  shear (measured on dgauss.50mm at f/2.8, 14 degrees: 32 cells at 1.4 waves per cell are within
  0.007 of 256 cells at 10 to 40 lp/mm);
- **frequency**: a pupil shear of one cell may span at most twice the lowest spatial frequency
  asked for, so the MTF there comes from at least half a cell of shear.

Without ``pupil_samples`` the grid starts at 64 cells and grows until the rules hold (up to
``MAX_PUPIL_SAMPLES``); a ``pupil_samples`` given that breaks a rule raises
:class:`~physcam.errors.InputError` naming the grid that would do.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InputError, OpticsError, require_finite
from . import _pupil as P
from ...optics.state import wavelengths_and_weights  # noqa: F401 (the analyses call it from here)


def pupil_samples_arg(value):
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or \
            not P.MIN_PUPIL_SAMPLES <= value <= P.MAX_PUPIL_SAMPLES:
        raise InputError(f"pupil_samples must be a whole number from {P.MIN_PUPIL_SAMPLES} to {P.MAX_PUPIL_SAMPLES}, "
                         f"got {value!r}")
    return int(value)


#: Phase rules (waves of OPD change between neighbouring cells) per use.
WAVES_PER_CELL_WAVEFRONT = 0.25
WAVES_PER_CELL_MTF = 1.0
#: Frequency rule: one cell of shear spans at most this many times the lowest frequency asked for.
CELL_OVER_FREQUENCY = 2.0


@dataclass
class FieldPupils:
    """Traced pupils of one field at each wavelength (same grid), and the setup they belong to."""

    setup: P.Setup
    field: P.Field  # at the primary wavelength
    fields: list  # per wavelength
    traces: list  # PupilTrace per wavelength
    wavelengths_nm: list
    weights: list
    n: int
    auto: bool

    def __post_init__(self):
        self._cache = {}

    def reference_point(self, defocus_mm: float):
        """The polychromatic reference: the primary wavelength's chief ray on the (moved) film."""
        return P.chief_point(self.traces[0], self.setup.film_z + defocus_mm)

    def samples(self, i: int, defocus_mm: float = 0.0, reference=None) -> P.WavefrontSamples:
        return P.wavefront_on(self.traces[i], self.setup.film_z + defocus_mm, reference)

    def pupil(self, i: int, defocus_mm: float = 0.0, reference=None) -> P.PupilFunction:
        key = (i, float(defocus_mm), None if reference is None else tuple(reference))
        if key not in self._cache:
            self._cache[key] = P.pupil_function(self.traces[i], self.samples(i, defocus_mm, reference))
        return self._cache[key]


def fields_pupils(camera, fields_deg, *, wavelengths_nm=None, weights=None, defocus_mm=(0.0,), pupil_samples=None,
                  min_frequency=None, waves_per_cell=WAVES_PER_CELL_WAVEFRONT, backend="auto",
                  st: P.Setup | None = None, check: bool = True, max_pupil_samples=None) -> list[FieldPupils]:
    """Trace the pupils of every field of ``fields_deg`` at every wavelength, each field on one grid
    that meets the sampling rules (``check=False``: the grid given or the default, unchecked, for the
    geometric MTF which needs no phase sampling). All fields and wavelengths are traced together.
    ``max_pupil_samples`` caps the grid the rules may choose (default ``MAX_PUPIL_SAMPLES``)."""
    cap = P.MAX_PUPIL_SAMPLES if max_pupil_samples is None else pupil_samples_arg(max_pupil_samples)
    wls, wts = wavelengths_and_weights(camera, wavelengths_nm, weights)
    n_user = pupil_samples_arg(pupil_samples)
    st = st or P.setup(camera, backend=backend)
    defocus = [require_finite("defocus_mm", d) for d in defocus_mm]
    if min_frequency is not None:
        min_frequency = require_finite("frequency", min_frequency)
    angles = P.field_angles(fields_deg)
    tracer = P._Tracer(st)
    per_wl = P.fields_at_wavelengths(st, angles, wls, tracer)  # [wavelength][field]
    boxes = P.pupil_boxes(st, per_wl[0], tracer)
    ns = [n_user or P.DEFAULT_PUPIL_SAMPLES] * len(angles)
    result: list = [None] * len(angles)
    todo = list(range(len(angles)))
    for _ in range(6):
        jobs = [(per_wl[w][i], ns[i], boxes[i]) for i in todo for w in range(len(wls))]
        traces = []
        for chunk in _chunks(jobs, lambda job: job[1] ** 2, RAYS_PER_BATCH):  # bounded memory per batch
            traces += P.trace_pupils(st, chunk, tracer)
        again = []
        for k, i in enumerate(todo):
            fp = FieldPupils(st, per_wl[0][i], [per_wl[w][i] for w in range(len(wls))],
                             traces[k * len(wls):(k + 1) * len(wls)], wls, wts, ns[i], n_user is None)
            need = _needed(fp, defocus, min_frequency, waves_per_cell) if check else None
            if need is None:
                result[i] = fp
                continue
            n_req, why = need
            if n_user is not None:
                raise InputError(f"pupil sampling too coarse: {why}; use at least {n_req} pupil samples "
                                 f"(or leave them out to have them chosen)")
            if n_req > cap:
                raise OpticsError(f"{why}; that needs {n_req} pupil samples, more than {cap}: the "
                                  "wavefront is too aberrated for a diffraction calculation here (use the geometric "
                                  "MTF)")
            ns[i] = n_req
            again.append(i)
        if not again:
            return result
        todo = again
    raise OpticsError("could not find a pupil sampling that meets the sampling rules")  # pragma: no cover


#: Cell-centre rays traced in one batch at most (bounds the memory of a chart with fine grids).
RAYS_PER_BATCH = 1_500_000


def _chunks(items, size, budget):
    """Consecutive runs of ``items`` whose ``size`` sums stay within ``budget`` (at least one item each)."""
    run, total = [], 0
    for it in items:
        s = size(it)
        if run and total + s > budget:
            yield run
            run, total = [], 0
        run.append(it)
        total += s
    if run:
        yield run


def field_pupils(lens, field_deg, **kwargs) -> FieldPupils:
    return fields_pupils(lens, [field_deg], **kwargs)[0]


def _needed(fp: FieldPupils, defocus, min_frequency, waves_per_cell):
    """None when the grid meets both rules, else (cells needed, why)."""
    worst_ratio, why = 1.0, ""
    for dz in defocus:
        ref = fp.reference_point(dz) if len(fp.traces) > 1 else None
        for i, pt in enumerate(fp.traces):
            pf = fp.pupil(i, dz, ref)
            dw = P.max_waves_per_cell(pf)
            r = dw / waves_per_cell
            if r > worst_ratio:
                worst_ratio = r
                why = (f"the wavefront of field {fp.field.field_deg:g} degrees at {pt.wavelength_nm:g} nm changes by "
                       f"{dw:.2f} waves between neighbouring cells of a {fp.n}-cell pupil grid (at most "
                       f"{waves_per_cell:g} here)")
            if min_frequency is not None and min_frequency > 0:
                step = max(pf.freq_per_cell_x, pf.freq_per_cell_y)
                r = step / (CELL_OVER_FREQUENCY * min_frequency)
                if r > worst_ratio:
                    worst_ratio = r
                    why = (f"one cell of a {fp.n}-cell pupil grid spans {step:.3g} lp/mm at {pt.wavelength_nm:g} nm, "
                           f"more than {CELL_OVER_FREQUENCY:g} times the {min_frequency:g} lp/mm asked for")
    if worst_ratio <= 1.0:
        return None
    n_req = int(math.ceil(fp.n * worst_ratio * 1.1 / 8.0) * 8)
    return max(n_req, fp.n + 8), why


MAX_FREQUENCIES = 512


def spatial_frequencies(frequencies, name="frequency"):
    """Spatial frequencies in lp/mm as a float array: 1 to :data:`MAX_FREQUENCIES` finite numbers from
    0 to 100000 (the MTF's and the Huygens MTF's one check)."""
    if isinstance(frequencies, (str, bytes)):
        raise InputError(f"frequencies must be numbers in lp/mm, got {frequencies!r:.60}")
    try:
        seq = np.atleast_1d(np.asarray(frequencies, dtype=object)).ravel().tolist()
    except Exception:  # noqa: BLE001 - anything that is not a sequence of numbers
        raise InputError(f"frequencies must be numbers in lp/mm, got {frequencies!r:.60}") from None
    f = [require_finite(name, v) for v in seq]
    if not 1 <= len(f) <= MAX_FREQUENCIES:
        raise InputError(f"give 1 to {MAX_FREQUENCIES} frequencies, got {len(f)}")
    if any(v < 0 or v > 1e5 for v in f):
        raise InputError("frequencies must lie between 0 and 100000 lp/mm")
    return np.array(f, dtype=float)
