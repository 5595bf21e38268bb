"""Depth of field from real rays: where a prescription's blur spot on the film reaches the CoC.

The on-set report's near and far limits come from a principal-plane (thin-lens) model: the blur
is the entrance pupil's image, growing as |1/d - 1/s|. A real lens adds its own blur (spherical
aberration, coma, field curvature at a field point) and focuses best a little away from the
paraxial image plane, so its limits differ (docs/lens-report.md, "Depth of field from real rays").

Method: the camera state (:func:`physcam.optics.state.camera_state`) focuses the lens at the mark
(:func:`physcam.optics.focusing.focus`) and sets its iris to the f-stop (the one iris rule,
``CameraState.stop_semi_diameter``). Where the film then sits is the **focusing convention**:

* ``"collimated"`` (the default): the lens as a technician collimates it, the mark its best focus.
  The film is moved from the paraxial image of the mark to where an on-axis point at the mark blurs
  least (golden-section search on the film shift), so the sharp zone lies about the mark.
* ``"paraxial"``: the film stays at the paraxial image of the mark (Gaussian optics); a lens with
  spherical aberration then focuses best a little nearer or farther than its mark.

An object point at
distance d in front of the film lies on the real chief ray that reaches the film at
``image_height_mm`` (on the axis by default), so a field point keeps its direction as d changes. Its blur is measured by tracing a grid of rays over its beam
(:func:`physcam.analysis.centroid.image_moments`) as one of

* ``"moment"``: the second-moment diameter sqrt(8 E[r^2]) about the centroid (a uniform disk of
  diameter c has exactly c), or
* ``"energy"``: the diameter of the circle about the centroid that holds ``energy_fraction`` of
  the rays (of the power: each ray stands for the same area of the beam).

The blur against reciprocal distance u = 1/d is V-shaped (the thin lens's is |u - 1/s| times a
constant), so the sharpest distance is found by golden-section search on u and each limit by
bisection on u between it and the lens front (near) or infinity (far): to 1e-6 of the distance.

**Sampling until converged.** Each blur is traced on a square grid over the point's beam
(:data:`GRIDS` per side: 32, then 64, 128, 256). The limits are found on one grid, then on the next
finer one; the answer is the first pair of successive grids whose near and far limits agree within
:data:`CONVERGED` (0.1 % of each limit's distance: 2 mm at 2 m). On 32 x 32 rays the Distagon 35 at
f/4 and 2 m read its near limit 1876 mm where finer grids and an independent trace give 1886-1887
(issue 39); a limit that has not converged on the finest grid is said in ``notes``.

Lengths in mm, distances from the film plane (docs/conventions.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InputError, OpticsError, require_finite, require_positive
from ...optics.state import CameraState, OfACamera, takes_camera

__all__ = ["RealDepthOfField", "real_depth_of_field", "blur_diameter_mm", "MEASURES"]

MEASURES = ("moment", "energy")
#: Where the film sits (module notes): best focus at the mark (default), or the mark's paraxial image.
FOCUSING = ("collimated", "paraxial")
#: The farthest object distance tried (mm): beyond it the far limit counts as infinite.
FAR_AWAY_MM = 1.0e9
#: Pupil grids (samples per side of each beam's box) tried in turn, and the relative change of both
#: limits between successive grids below which the answer has converged (module notes).
GRIDS = (32, 64, 128, 256)
CONVERGED = 1e-3


@dataclass(frozen=True)
class RealDepthOfField(OfACamera):
    """Near and far limits (mm from the film) where the real blur of ``camera`` reaches ``coc_mm`` (module notes)."""

    lens_name: str
    camera: CameraState  # the camera traced: its focus (.focus_from_film_mm) and f-stop (.fstop)
    coc_mm: float
    image_height_mm: float
    measure: str  # "moment" or "energy 80 %"
    sharpest_from_film_mm: float  # the object distance of the smallest blur
    sharpest_blur_mm: float
    near_from_film_mm: float
    far_from_film_mm: float  # inf when the blur stays below the CoC out to infinity
    focusing: str = "collimated"  # where the film sits (module notes)
    film_shift_mm: float = 0.0  # the film from the paraxial image of the mark, + away from the lens
    pupil_grid: int = 32  # samples per side of each beam's box on the grid the answer was found with
    converged: bool = True  # the last two grids agreed within CONVERGED
    notes: tuple[str, ...] = ()

    @property
    def far_is_infinite(self) -> bool:
        return math.isinf(self.far_from_film_mm)

    @property
    def total_mm(self) -> float:
        return self.far_from_film_mm - self.near_from_film_mm

    def to_dict(self) -> dict:
        fin = lambda v: None if math.isinf(v) else v  # noqa: E731
        return {"lens": self.lens_name, "fstop": self.fstop, "focus_from_film_mm": fin(self.focus_from_film_mm),
                "coc_mm": self.coc_mm, "image_height_mm": self.image_height_mm, "measure": self.measure,
                "sharpest_from_film_mm": fin(self.sharpest_from_film_mm), "sharpest_blur_mm": self.sharpest_blur_mm,
                "near_from_film_mm": self.near_from_film_mm, "far_from_film_mm": fin(self.far_from_film_mm),
                "far_is_infinite": self.far_is_infinite, "total_mm": fin(self.total_mm),
                "focusing": self.focusing, "film_shift_mm": self.film_shift_mm, "pupil_grid": self.pupil_grid,
                "converged": self.converged, "notes": list(self.notes),
                "definition": "object distances from the film where the real blur (measure) equals the CoC, on the "
                              "real chief ray of image_height_mm; the lens focused at the mark, the iris at the f-stop; "
                              "focusing collimated: the film where a point at the mark blurs least (best focus at "
                              "the mark), paraxial: at the mark's paraxial image; film_shift_mm from the paraxial image, "
                              "+ away from the lens; pupil_grid: rays per side of each beam, doubled until the limits "
                              "changed by less than 0.1 %"}


class _Blur:
    """The blur diameter on the film of object points along one chief ray, for one focused lens."""

    def __init__(self, cam: CameraState, image_height_mm, measure, energy_fraction, backend, *, grid: int = GRIDS[0],
                 film_shift_mm: float = 0.0):
        from ...trace import RayBatch, trace_through
        from .._chief import aim_from_film

        self.q, self.film_z, self.backend, self.grid = cam.focused, cam.film_z + film_shift_mm, backend, grid
        self.wl = float(cam.wavelengths_nm[0])  # the state's primary (default: the design wavelength)
        self.iris = cam.stop_semi_diameter
        self.z_ep = cam.entrance_pupil_z
        self.r_ep = cam.gaussian.entrance_pupil_diameter / 2 * self.iris / self.q.surfaces[self.q.stop_index].semi_diameter
        self.front = cam.film_z  # the front vertex (z = 0) lies film_z in front of the film
        self.measure, self.fraction = measure, energy_fraction
        aimed = aim_from_film(self.q, [[0.0, -image_height_mm]], self.film_z, wavelength_nm=self.wl, backend=backend)
        out = trace_through(self.q, RayBatch.from_arrays(aimed.start, aimed.direction, self.wl), reverse=True,
                            backend=backend)
        if not (bool(aimed.ok[0]) and bool(out.ok[0]) and out.N[0] < 0):
            raise OpticsError(f"no chief ray of {cam.lens_name!r} reaches the film {image_height_mm:g} mm from the centre")
        self.ray = np.array([out.x[0], out.y[0], out.z[0], out.L[0], out.M[0], out.N[0]])

    def __call__(self, d_from_film: float) -> float:
        from ..centroid import image_moments

        x, y, z, L, M, N = self.ray
        z_obj = self.film_z - d_from_film
        t, s = (z_obj - z) / N, (self.z_ep - z) / N
        obj = np.array([[x + t * L, y + t * M, z_obj]])
        crossing = np.array([[x + s * L, y + s * M]])
        out = image_moments(self.q, self.film_z, obj, at_infinity=False, crossing=crossing, z_ep=self.z_ep,
                            pupil_radius=self.r_ep, stop_semi_diameter=self.iris, wavelength_nm=self.wl,
                            backend=self.backend, energy_fraction=self.fraction, grid=self.grid)
        return float(math.sqrt(8.0 * out[1][0])) if self.measure == "moment" else float(2.0 * out[2][0])


def _measure(measure, energy_fraction):
    if measure not in MEASURES:
        raise InputError(f"the blur measure is one of {', '.join(MEASURES)}, got {measure!r}")
    if measure == "moment":
        return None
    f = require_finite("energy fraction", energy_fraction)
    if not 0.05 <= f <= 0.99:
        raise InputError(f"the energy fraction must lie between 0.05 and 0.99, got {f:g}")
    return f


def _camera(camera: CameraState) -> CameraState:
    """The camera (through the door): focused by hand at a finite mark."""
    if camera.film_from_analysis:
        raise InputError("give focus_mm and fstop: a camera focused by hand, physcam.optics.state.camera_state(lens, "
                         "focus_mm=..., fstop=...)")
    require_positive("focus mark", camera.focus_from_film_mm)
    return camera


@takes_camera
def blur_diameter_mm(camera: CameraState, light_from_film_mm: float, *, image_height_mm: float = 0.0, measure: str = "moment",
                     energy_fraction: float = 0.8, film_shift_mm: float = 0.0, grid: int = GRIDS[0],
                     backend: str = "auto") -> float:
    """The real blur diameter (mm, module notes) of a point ``light_from_film_mm`` in front of the film;
    ``camera`` a :class:`~physcam.optics.state.CameraState` (focused at a mark, stopped);
    ``film_shift_mm``: the film moved from the mark's paraxial image (a collimated lens's
    ``RealDepthOfField.film_shift_mm``); ``grid``: pupil samples per side of the beam."""
    f = _measure(measure, energy_fraction)
    blur = _Blur(_camera(camera), require_finite("image height", image_height_mm), measure, f, backend,
                 grid=_grid(grid), film_shift_mm=require_finite("film shift", film_shift_mm))
    d = require_positive("light distance", light_from_film_mm)
    if not d > blur.front:
        raise InputError(f"the light at {d:g} mm from the film is not in front of the lens ({blur.front:g} mm)")
    return blur(d)


def _golden(fn, lo, hi, tol):
    """(argmin, min) of a unimodal ``fn`` on [lo, hi] by golden-section search, to ``tol``."""
    r = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = hi - r * (hi - lo), lo + r * (hi - lo)
    fa, fb = fn(a), fn(b)
    while hi - lo > tol:
        if fa < fb:
            hi, b, fb = b, a, fa
            a = hi - r * (hi - lo)
            fa = fn(a)
        else:
            lo, a, fa = a, b, fb
            b = lo + r * (hi - lo)
            fb = fn(b)
    x = 0.5 * (lo + hi)
    return x, fn(x)


def _golden_near(fn, lo, hi, tol, guess, half_width):
    """:func:`_golden` on [lo, hi], searched first within ``half_width`` of ``guess`` (a coarser pupil grid's
    answer): kept when its minimum lies inside that bracket (more than 2 ``tol`` from an end that is not
    [lo, hi]'s own), which for a unimodal ``fn`` is the minimum on [lo, hi] (to ``tol``); else the whole search."""
    if guess is None:
        return _golden(fn, lo, hi, tol)
    a, b = max(lo, guess - half_width), min(hi, guess + half_width)
    if b - a > 4.0 * tol:
        x, fx = _golden(fn, a, b, tol)
        if (a == lo or x - a > 2.0 * tol) and (b == hi or b - x > 2.0 * tol):
            return x, fx
    return _golden(fn, lo, hi, tol)


def _collimate(cam: CameraState, measure, fraction, backend, grid, guess=None) -> float:
    """The film shift (mm, + away from the lens) that puts the best focus of an on-axis point at the mark on
    the film: the smallest blur of that point over film positions (golden-section search; within 1 % of
    the reach of ``guess``, a coarser grid's shift, first: :func:`_golden_near`)."""
    from ..centroid import image_moments

    mark = cam.focus_from_film_mm
    reach = max(2.0, 0.05 * cam.gaussian.efl)  # best focus lies well within 5 % of the EFL of the paraxial one
    base = _Blur(cam, 0.0, measure, fraction, backend, grid=grid)

    def blur_at(dz):
        z_film = base.film_z + dz
        out = image_moments(base.q, z_film, np.array([[0.0, 0.0, z_film - mark]]), at_infinity=False,
                            crossing=np.zeros((1, 2)), z_ep=base.z_ep, pupil_radius=base.r_ep,
                            stop_semi_diameter=base.iris, wavelength_nm=base.wl, backend=backend,
                            energy_fraction=fraction, grid=grid)
        return float(math.sqrt(8.0 * out[1][0])) if measure == "moment" else float(2.0 * out[2][0])

    dz, _ = _golden_near(blur_at, -reach, reach, 1e-6 * reach, guess, 0.01 * reach)
    if abs(dz) > 0.99 * reach:
        raise OpticsError(f"{cam.lens_name!r} has no best focus within {reach:.2g} mm of the paraxial image of its "
                          "mark: cannot collimate it there")
    return dz


def _limits(blur: _Blur, c: float, what: str, name: str, fstop: float, hint=None):
    """(sharpest u, its blur, near, far) of one traced lens at the CoC ``c`` (module notes). ``hint``: a coarser
    pupil grid's (sharpest u, near, far), where each search looks first (within 2 % of the sharpest u, 1 % of
    each limit's u; the same search, from a bracket verified to hold the answer, else from the whole range)."""
    u_front = 1.0 / (blur.front + 1.0)  # 1 mm in front of the front vertex
    b = lambda u: blur(1.0 / u) if u > 0 else blur(FAR_AWAY_MM)  # noqa: E731
    tol = 1e-7 * u_front
    u_best, best = _golden_near(b, 0.0, u_front, tol, None if hint is None else hint[0],
                                None if hint is None else 0.02 * hint[0] + 2.0 * tol)
    if best >= c:
        raise OpticsError(f"{name!r} at f/{fstop:g} blurs a point to {best * 1e3:.1f} µm ({what}) even at its "
                          f"sharpest distance: more than the {c * 1e3:.1f} µm CoC, so no depth of field")

    def limit(u_in, u_out, guess=None):  # bisection on u: blur(u_in) < c <= blur(u_out)
        if guess is not None and guess > 0.0:  # 1 % about a coarser grid's limit, when the blur brackets c there
            lo, hi = min(u_in, u_out), max(u_in, u_out)
            near_in = guess + 0.01 * guess * math.copysign(1.0, u_in - guess)
            near_out = guess + 0.01 * guess * math.copysign(1.0, u_out - guess)
            if lo < near_in < hi and lo < near_out < hi and b(near_in) < c <= b(near_out):
                u_in, u_out = near_in, near_out
        for _ in range(200):
            mid = 0.5 * (u_in + u_out)
            if b(mid) < c:
                u_in = mid
            else:
                u_out = mid
            if abs(u_out - u_in) <= 1e-6 * max(u_in, u_out):
                break
        return 0.5 * (u_in + u_out)

    near_hint, far_hint = (None, None) if hint is None else (1.0 / hint[1], 0.0 if math.isinf(hint[2]) else 1.0 / hint[2])
    near = 1.0 / limit(u_best, u_front, near_hint) if b(u_front) >= c else 1.0 / u_front
    far = math.inf if b(0.0) < c else 1.0 / limit(u_best, 0.0, far_hint)
    return u_best, best, near, far


def _agree(a, b) -> bool:
    """Two limits agree within CONVERGED (both infinite counts)."""
    if math.isinf(a) or math.isinf(b):
        return math.isinf(a) and math.isinf(b)
    return abs(a - b) <= CONVERGED * max(a, b)


@takes_camera
def real_depth_of_field(camera: CameraState, *, coc_mm: float, image_height_mm: float = 0.0, measure: str = "moment",
                        energy_fraction: float = 0.8, focusing: str = "collimated", grid: int | None = None,
                        backend: str = "auto") -> RealDepthOfField:
    """Near and far limits of ``camera`` (a :class:`~physcam.optics.state.CameraState`: the lens focused at
    a mark from the film, its iris at an f-stop) where the real blur reaches
    ``coc_mm`` (module notes). ``focusing``: "collimated" (best focus at the mark, default) or "paraxial";
    ``grid``: one pupil grid (samples per side) instead of sampling until converged. Raises
    :class:`OpticsError` when the lens's own blur at its sharpest already exceeds the CoC."""
    cam = _camera(camera)
    lens, fstop = cam.lens, cam.fstop
    c = require_positive("circle of confusion", coc_mm)
    h = require_finite("image height", image_height_mm)
    frac = _measure(measure, energy_fraction)
    if focusing not in FOCUSING:
        raise InputError(f"focusing is one of {', '.join(FOCUSING)}, got {focusing!r}")
    grids = GRIDS if grid is None else (_grid(grid),)
    what = "second-moment diameter" if measure == "moment" else f"{frac:.0%} energy diameter"
    prev, notes = None, []
    for g in grids:  # each finer grid's searches start about the coarser grid's answers
        dz = _collimate(cam, measure, frac, backend, g, None if prev is None else prev[0]) \
            if focusing == "collimated" else 0.0
        got = (dz, *_limits(_Blur(cam, h, measure, frac, backend, grid=g, film_shift_mm=dz), c, what, lens.name, fstop,
                            None if prev is None else (prev[1], prev[3], prev[4])))
        if prev is not None and _agree(prev[3], got[3]) and _agree(prev[4], got[4]):
            break
        prev = got
    converged = grid is not None or (prev is not got)
    if not converged:
        notes.append(f"the limits moved by more than {CONVERGED:.2%} between the {grids[-2]} and {grids[-1]} "
                     "pupil grids: sampling-limited")
    dz, u_best, best, near, far = got
    return RealDepthOfField(lens.name, cam, c, h, "moment" if measure == "moment" else f"energy {frac:.0%}",
                            1.0 / u_best if u_best > 0 else math.inf, best, near, far, focusing, float(dz), g,
                            converged, tuple(notes))


def _grid(v) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 8 <= v <= 1024:
        raise InputError(f"the pupil grid must be a whole number from 8 to 1024, got {v!r}")
    return int(v)
