"""A zoom lens between its tabulated positions: cam curves, the prescription at a zoom position,
and single-position files of one design joined into one zoom lens (docs/zoom.md).

**The cam curves.** A source tabulates the moving gaps at a few zoom positions (a patent's wide,
middle and tele; a Zemax file's configurations). Between them physcam follows each gap (and a
tabulated stop size, close-focus gap or close distance) along a monotone piecewise cubic Hermite
curve in the normalised zoom coordinate u (:attr:`physcam.lens.prescription.Zoom.encoder`): the
Fritsch-Carlson construction as C. Moler gives it (*Numerical Computing with MATLAB*, SIAM 2004,
3.4 "pchip"; F. N. Fritsch and R. E. Carlson, SIAM J. Numer. Anal. 17 (1980) 238). Why this curve:
it passes through every tabulated value exactly; it has a continuous slope, as a cut cam does; and
it never overshoots: between two positions a gap stays between its two tabulated values, and where
the table rises (or falls) monotonically so does the curve, so a gap never goes negative and a
group never runs backwards between stations, which a cubic spline or a polynomial through the
stations can do. It is not the designer's cam (which holds the image exactly on the film between
stations); the image-plane shift it leaves is what ``physcam lens zoom`` reports as parfocality.

**The encoder.** u places the tabulated positions evenly from 0 to 1 unless the source gives their
places (the physcam TOML ``encoder`` list). A zoom position is asked for as u or as a focal length,
which :mod:`physcam.optics.zoom` solves for u on the paraxial EFL.
"""

from __future__ import annotations

import json
from dataclasses import replace

from ..errors import InputError, LensFileError, require_type
from .prescription import Focus, Prescription, VariableGap, Zoom, ZoomGap, takes_prescription

__all__ = ["pchip", "prescription_at", "tabulated_encoders", "join_positions", "varying_gaps", "ZOOM_ENCODER_KEY"]

#: ``Prescription.extras`` key of the encoder value a prescription was taken at from its zoom lens.
ZOOM_ENCODER_KEY = "zoom.encoder"


def _slopes(x: list[float], y: list[float]) -> list[float]:
    """Fritsch-Carlson derivatives at the knots (Moler's pchip: weighted harmonic mean inside, a
    one-sided three-point formula at the ends, zero where the data turn)."""
    n = len(x)
    h = [x[k + 1] - x[k] for k in range(n - 1)]
    delta = [(y[k + 1] - y[k]) / h[k] for k in range(n - 1)]
    if n == 2:
        return [delta[0], delta[0]]
    d = [0.0] * n
    for k in range(1, n - 1):
        if delta[k - 1] * delta[k] > 0.0:
            w1, w2 = 2.0 * h[k] + h[k - 1], h[k] + 2.0 * h[k - 1]
            d[k] = (w1 + w2) / (w1 / delta[k - 1] + w2 / delta[k])
    d[0] = _end_slope(h[0], h[1], delta[0], delta[1])
    d[-1] = _end_slope(h[-1], h[-2], delta[-1], delta[-2])
    return d


def _end_slope(h0: float, h1: float, del0: float, del1: float) -> float:
    """Moler's shape-preserving end slope (pchip's ``pchipend``)."""
    d = ((2.0 * h0 + h1) * del0 - h0 * del1) / (h0 + h1)
    if d * del0 <= 0.0:
        return 0.0
    if del0 * del1 < 0.0 and abs(d) > abs(3.0 * del0):
        return 3.0 * del0
    return d


def pchip(x, y, xq: float) -> float:
    """The monotone piecewise cubic Hermite interpolant of the knots ``(x, y)`` at ``xq`` (module notes).

    ``x`` strictly increasing, ``xq`` within ``[x[0], x[-1]]``; a knot gives back its own ``y``
    exactly."""
    x, y, xq = [float(v) for v in x], [float(v) for v in y], float(xq)
    if not x[0] <= xq <= x[-1]:
        raise InputError(f"{xq:g} lies outside the tabulated range {x[0]:g}..{x[-1]:g}")
    for k, xk in enumerate(x):
        if xq == xk:
            return y[k]
    k = max(i for i in range(len(x) - 1) if x[i] <= xq)
    d = _slopes(x, y)
    h = x[k + 1] - x[k]
    t = (xq - x[k]) / h
    h00, h10 = (1 + 2 * t) * (1 - t) ** 2, t * (1 - t) ** 2
    h01, h11 = t * t * (3 - 2 * t), t * t * (t - 1)
    return h00 * y[k] + h10 * h * d[k] + h01 * y[k + 1] + h11 * h * d[k + 1]


def _zoom_of(p: Prescription) -> Zoom:
    if p.zoom is None:
        raise InputError(f"lens {p.name!r} is not a zoom lens (its file has no zoom table)")
    return p.zoom


@takes_prescription
def tabulated_encoders(prescription: Prescription) -> tuple[float, ...]:
    """The encoder value of each tabulated zoom position of a zoom lens."""
    return _zoom_of(prescription).encoder


def _encoder(value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"a zoom encoder value is a number from 0 to 1, got {value!r}")
    u = float(value)
    if not 0.0 <= u <= 1.0:  # NaN fails too
        raise InputError(f"a zoom encoder value lies from 0 (the first position) to 1 (the last), got {value!r}")
    return u


@takes_prescription
def prescription_at(prescription: Prescription, encoder: float) -> Prescription:
    """The plain prescription of a zoom lens at the normalised zoom coordinate ``encoder`` (0..1):
    every zoom gap on its cam curve (module notes), the stop at its tabulated size there (when the
    source tabulates it), and the lens's focus groups at that position (when the source gives a
    zoom x focus grid). The result has no zoom table; ``extras`` records the encoder value under
    :data:`ZOOM_ENCODER_KEY`. Everything that takes a Prescription takes it."""
    z = _zoom_of(prescription)
    u = _encoder(encoder)
    enc = z.encoder
    gaps = {g.surface: pchip(enc, g.thickness, u) for g in z.gaps}
    surfaces = list(prescription.surfaces)
    for i, t in gaps.items():
        surfaces[i] = replace(surfaces[i], thickness=t)
    if z.stop_semi_diameter is not None:
        k = prescription.stop_index
        surfaces[k] = replace(surfaces[k], semi_diameter=pchip(enc, z.stop_semi_diameter, u))
    focus = prescription.focus
    if z.close_distance is not None:
        focus = Focus(pchip(enc, z.close_distance, u),
                      tuple(VariableGap(g.surface, gaps[g.surface], pchip(enc, g.thickness_close, u))
                            for g in z.gaps if g.thickness_close is not None))
    extras = tuple(kv for kv in prescription.extras if kv[0] != ZOOM_ENCODER_KEY) + ((ZOOM_ENCODER_KEY, json.dumps(u)),)
    return replace(prescription, surfaces=tuple(surfaces), focus=focus, zoom=None, extras=tuple(sorted(extras))).validate()


def _same_surface(a, b) -> bool:
    return (a.radius, a.medium, a.kind, a.conic, a.aspheric) == (b.radius, b.medium, b.kind, b.conic, b.aspheric)


def varying_gaps(prescriptions) -> list[int]:
    """The surfaces whose following gap differs between single-position prescriptions of one design."""
    if isinstance(prescriptions, (str, bytes)) or not hasattr(prescriptions, "__iter__"):
        from ..errors import WrongTypeError

        raise WrongTypeError(f"prescriptions must be a list of Prescription, got {type(prescriptions).__name__}")
    prescriptions = list(prescriptions)
    for k, q in enumerate(prescriptions):
        require_type(f"prescriptions[{k}]", q, Prescription, "load each position with physcam.lens.library.load_lens")
    if not prescriptions:
        raise InputError("give at least one prescription")
    first = prescriptions[0]
    return [i for i in range(len(first.surfaces)) if len({q.surfaces[i].thickness for q in prescriptions}) > 1]


def join_positions(prescriptions, *, encoder=None, stated_focal_length=None, names=None) -> Prescription:
    """One zoom lens from single-position prescriptions of one design, in zoom order (first = the
    zoom table's first position, encoder 0).

    They must be the same design: the same surfaces (radius, kind, medium, asphere) in the same
    order, the same semi-diameters except the stop's (a differing stop size becomes the tabulated
    stop), the same thicknesses except air gaps (which become the zoom gaps); focus groups, if any,
    on the same gaps in every file (their close distances and gaps become the zoom x focus grid).
    ``names`` (the files) name the one that differs. Raises :class:`LensFileError` saying which surface
    differs and how."""
    if isinstance(prescriptions, (str, bytes)) or not hasattr(prescriptions, "__iter__"):
        from ..errors import WrongTypeError

        raise WrongTypeError(f"prescriptions must be a list of Prescription, got {type(prescriptions).__name__}")
    ps = list(prescriptions)
    for k, q in enumerate(ps):
        require_type(f"prescriptions[{k}]", q, Prescription, "load each position with physcam.lens.library.load_lens")
    names = list(names) if names is not None else [f"position {k + 1}" for k in range(len(ps))]
    if len(ps) < 2:
        raise InputError("joining zoom positions needs at least two prescriptions, one per position")
    first = ps[0]
    for q, where in zip(ps[1:], names[1:]):
        _check_same_design(first, q, where, names[0])
    moving = varying_gaps(ps)
    if not moving:
        raise LensFileError(f"the {len(ps)} files are the same lens: no gap differs between them", names[0])
    stop = [q.surfaces[q.stop_index].semi_diameter for q in ps]
    focus = _joined_focus(ps, names)
    close_gaps = {} if focus is None else focus[1]
    moving = sorted(set(moving) | set(close_gaps))
    gaps = tuple(ZoomGap(i, tuple(q.surfaces[i].thickness for q in ps), close_gaps.get(i)) for i in moving)
    n = len(ps)
    zoom = Zoom(gaps, tuple(encoder) if encoder is not None else tuple(k / (n - 1) for k in range(n)),
                None if len(set(stop)) == 1 else tuple(stop), None if focus is None else focus[0],
                None if stated_focal_length is None else tuple(float(f) for f in stated_focal_length))
    return replace(first, zoom=zoom).validate(names[0])


def _check_same_design(a: Prescription, b: Prescription, where, ref) -> None:
    if len(a.surfaces) != len(b.surfaces):
        raise LensFileError(f"{len(b.surfaces)} surfaces where {ref} has {len(a.surfaces)}: not one design", where)
    if a.stop_index != b.stop_index or a.squeeze != b.squeeze:
        raise LensFileError(f"the stop (or the squeeze) differs from {ref}: not one design", where)
    for i, (sa, sb) in enumerate(zip(a.surfaces, b.surfaces)):
        if not _same_surface(sa, sb):
            raise LensFileError(f"surface {i} differs from {ref} (radius, type, glass or asphere): not one design",
                                where)
        if sa.semi_diameter != sb.semi_diameter and not sa.is_stop:
            raise LensFileError(f"surface {i}: semi-diameter {sb.semi_diameter:g} mm where {ref} has "
                                f"{sa.semi_diameter:g} mm (only the stop's may change with zoom)", where)
        if sa.thickness != sb.thickness and sa.medium.nd != 1.0:
            raise LensFileError(f"surface {i}: glass thickness {sb.thickness:g} mm where {ref} has {sa.thickness:g} mm "
                                "(only air gaps move in a zoom)", where)


def _joined_focus(ps, names):
    """(close distances, {surface: close thicknesses}) of single-position files with focus groups."""
    has = [q.focus is not None for q in ps]
    if not any(has):
        return None
    if not all(has):
        raise LensFileError("some positions have focus groups and others none: give every position's close focus",
                            names[has.index(False)])
    surfaces = [tuple(g.surface for g in q.focus.gaps) for q in ps]
    if len(set(surfaces)) != 1:
        raise LensFileError("the focus groups move different gaps at different positions", names[0])
    for q, where in zip(ps, names):
        for g in q.focus.gaps:
            if g.thickness_infinity != q.surfaces[g.surface].thickness:
                raise LensFileError(f"focus gap after surface {g.surface}: its infinity thickness "
                                    f"{g.thickness_infinity:g} mm is not the surface's {q.surfaces[g.surface].thickness:g} mm",
                                    where)
    close = {s: tuple(next(g.thickness_close for g in q.focus.gaps if g.surface == s) for q in ps) for s in surfaces[0]}
    return tuple(q.focus.close_distance for q in ps), close
