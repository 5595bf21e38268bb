"""Repairs of lens files that do not describe a buildable lens, each explained.

The bundled library carries corrected copies of six published files
(docs/lens-formats.md, "The bundled library and its corrections"); the corrections are
made by this module, not by hand (``scripts/build_lens_library.py`` calls it):

- :func:`scale_apertures` -- every aperture scaled by the factor that reconciles the paraxial
  f-number with the stated one (2.00x: diameters written where semi-diameters were meant);
- :func:`stop_from_fnumber` -- the stop diameter set so the paraxial f-number is the stated
  one, when the file gives the entrance-pupil diameter EFL/N as the stop diameter (this also
  moves the stop inside its air gap);
- :func:`move_stop_clear` -- the stop plane moved inside its air gap (glass unchanged) so it
  clears the sag of its curved neighbours;
- :func:`clip_pair` -- the clear diameters of two neighbouring surfaces reduced to where
  they no longer cross;
- :func:`clamp_to_edge` -- a semi-diameter beyond its sphere or conic edge reduced to it.

:func:`propose` chooses the repairs a prescription needs (see its docstring for the rules) and
returns the repaired prescription with one :class:`Repair` per change, before and after numbers
included. Numbers are rounded the way the library's corrections always were (stop diameter and
position to 0.001 mm, clipped diameters down to 0.02 mm), so the repaired lens is reproducible.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field, replace

from ..errors import LensFileError
from .geometry import sag
from .prescription import Prescription, Surface, takes_prescription

__all__ = [
    "Repair", "paraxial_efl", "paraxial_f_number", "stated_focal_length", "stated_f_number", "scale_apertures",
    "stop_from_fnumber", "move_stop_clear", "clip_pair", "clamp_to_edge", "propose", "crossing", "with_corrections",
]

#: Gap kept between the stop plane or a clipped rim and its neighbour, mm.
CLEARANCE_MM = 0.05


@dataclass(frozen=True)
class Repair:
    """One change made to a prescription: what, where, the numbers before and after, and why."""

    kind: str  # scale_apertures, stop_from_fnumber, move_stop, clip_pair, clamp_to_edge
    surfaces: tuple[int, ...]
    message: str
    before: dict = field(default_factory=dict)
    after: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"kind": self.kind, "surfaces": list(self.surfaces), "message": self.message,
                "before": self.before, "after": self.after}


# ---- a minimal paraxial (y, nu) trace in the Y meridian at nd ------------------------------
def _trace_y(surfaces, y, u, upto):
    n = 1.0
    for s in surfaces[:upto]:
        n2 = s.medium.nd
        u = (n * u - y * s.curvature_y * (n2 - n)) / n2
        n = n2
        y += s.thickness * u
    return y, u


@takes_prescription
def paraxial_efl(p: Prescription) -> float:
    """Effective focal length (mm) in the Y meridian at nd; inf for an afocal lens."""
    y, u, n = 1.0, 0.0, 1.0
    s = p.surfaces
    for i, x in enumerate(s):
        n2 = x.medium.nd
        u = (n * u - y * x.curvature_y * (n2 - n)) / n2
        n = n2
        if i < len(s) - 1:
            y += x.thickness * u
    return math.inf if u == 0.0 else -1.0 / u


def _stop(p: Prescription) -> int:
    stops = [i for i, s in enumerate(p.surfaces) if s.is_stop]
    if len(stops) != 1:
        raise LensFileError(f"lens {p.name!r}: {len(stops)} aperture stops; no repair is defined without exactly one")
    return stops[0]


@takes_prescription
def paraxial_f_number(p: Prescription) -> float:
    """Paraxial f/# = EFL / entrance-pupil diameter with the file's stop (infinity focus, Y meridian, nd)."""
    s = p.surfaces
    k = _stop(p)
    y_stop, _ = _trace_y(s, 1.0, 0.0, k)  # marginal ray of unit height on the first surface
    if y_stop == 0.0 or s[k].semi_diameter <= 0:
        return math.nan
    epd = 2.0 * s[k].semi_diameter / abs(y_stop)
    return paraxial_efl(p) / epd


_MM = re.compile(r"(\d+(?:\.\d+)?)\s*mm", re.I)
_FNUM = re.compile(r"\bf\s*/\s*(\d+(?:\.\d+)?)|\bf(\d+(?:[._]\d+)?)\b", re.I)


@takes_prescription
def stated_focal_length(p: Prescription) -> tuple[float | None, str]:
    """The focal length the file states: ``[lens] focal_length`` or a number before "mm" in the name."""
    if p.metadata.focal_length:
        return p.metadata.focal_length, "focal_length in the file"
    m = _MM.findall(p.name or "")
    return (float(m[0]), f"the name {p.name!r}") if m else (None, "")


@takes_prescription
def stated_f_number(p: Prescription) -> tuple[float | None, str]:
    """The f-number the file states: ``[lens] max_fstop`` or "f/2.8" in the name."""
    if p.metadata.max_fstop:
        return p.metadata.max_fstop, "max_fstop in the file"
    m = _FNUM.search(p.name or "")
    if m:
        v = float((m.group(1) or m.group(2)).replace("_", "."))
        if v > 0:
            return v, f"the name {p.name!r}"
    return None, ""


def _set(p: Prescription, i: int, **kw) -> Prescription:
    s = list(p.surfaces)
    s[i] = replace(s[i], **kw)
    return p.with_surfaces(s)


# ---- the repairs ---------------------------------------------------------------------
@takes_prescription
def scale_apertures(p: Prescription, factor: float) -> tuple[Prescription, Repair]:
    """Every clear semi-diameter times ``factor`` (0.5: the file wrote diameters as semi-diameters)."""
    before = paraxial_f_number(p)
    q = p.with_surfaces(replace(s, semi_diameter=s.semi_diameter * factor) for s in p.surfaces)
    n_max = stated_f_number(p)[0]
    what = "halved" if factor == 0.5 else f"scaled by {factor:g}"
    times = "twice" if factor == 0.5 else f"{1 / factor:g} times"
    msg = (f"all 'aperture' values {what}: the file's values are {times} the clear diameters "
           f"(with them the paraxial f-number is f/{before:.2f} against the engraved f/{n_max:g}, and some "
           f"semi-diameters exceed their surface radius); {what}, f/{paraxial_f_number(q):.2f}")
    return q, Repair("scale_apertures", tuple(range(len(p.surfaces))), msg,
                     {"f_number": before, "semi_diameters": [s.semi_diameter for s in p.surfaces]},
                     {"f_number": paraxial_f_number(q), "semi_diameters": [s.semi_diameter for s in q.surfaces]})


def _stop_bounds(p: Prescription, clearance: float):
    s = p.surfaces
    k = _stop(p)
    if k == 0 or k == len(s) - 1:
        return None
    prev, stop, nxt = s[k - 1], s[k], s[k + 1]
    gap = prev.thickness + stop.thickness
    lower = max(0.0, max(sag(prev, min(prev.semi_diameter, stop.semi_diameter), a) for a in "xy")) + clearance
    upper = gap + min(0.0, min(sag(nxt, min(nxt.semi_diameter, stop.semi_diameter), a) for a in "xy")) - clearance
    return k, gap, lower, upper


@takes_prescription
def move_stop_clear(p: Prescription, clearance: float = CLEARANCE_MM) -> tuple[Prescription, Repair | None]:
    """Move the stop inside its air gap (glass unchanged) so its plane clears both neighbours by
    ``clearance`` at the stop's semi-diameter; ``(p, None)`` when it already does."""
    b = _stop_bounds(p, clearance)
    if b is None:
        return p, None
    k, gap, lower, upper = b
    if lower > upper:
        raise LensFileError(f"lens {p.name!r}: no room for the stop in its air gap ({gap:g} mm) at its "
                            f"semi-diameter {p.surfaces[k].semi_diameter:g} mm; no repair is defined")
    old = p.surfaces[k - 1].thickness
    z = round(min(max(old, lower), upper), 3)
    if z == old:
        return p, None
    q = _set(_set(p, k - 1, thickness=z), k, thickness=round(gap - z, 6))
    msg = (f"stop moved within its air gap from {old:g} mm to {z:g} mm behind surface {k - 1} (gap "
           f"{gap:g} mm kept) so the stop plane clears the curved neighbours at the stop's semi-diameter")
    return q, Repair("move_stop", (k - 1, k), msg, {"stop_behind_previous_mm": old}, {"stop_behind_previous_mm": z})


@takes_prescription
def stop_from_fnumber(p: Prescription, n_max: float | None = None) -> tuple[Prescription, Repair]:
    """Stop diameter such that the paraxial f-number is ``n_max`` (default: the stated one),
    moving the stop inside its air gap as needed (size and position interact: iterated)."""
    n_max = n_max or stated_f_number(p)[0]
    if not n_max:
        raise LensFileError(f"lens {p.name!r}: no stated f-number to set the stop from")
    k = _stop(p)
    old_d = 2 * p.surfaces[k].semi_diameter
    old_z = p.surfaces[k - 1].thickness
    gap = old_z + p.surfaces[k].thickness
    old_n = paraxial_f_number(p)
    q = p
    for _ in range(20):
        q = _set(q, k, semi_diameter=q.surfaces[k].semi_diameter * (paraxial_f_number(q) / n_max))
        q, _r = move_stop_clear(q)
    new_d = round(2 * q.surfaces[k].semi_diameter, 3)
    q = _set(q, k, semi_diameter=new_d / 2)
    new_z = q.surfaces[k - 1].thickness
    msg = (f"stop diameter {old_d:g} mm equals the entrance-pupil diameter EFL/N, but the front group magnifies "
           f"the stop; set to {new_d:g} mm so the paraxial f-number is the engraved f/{n_max:g} "
           f"(now f/{paraxial_f_number(q):.3f}); and the stop moved within its air gap from {old_z:g} mm to "
           f"{new_z:g} mm behind surface {k - 1} (gap {gap:g} mm and all glass "
           "unchanged) because at the file's position the stop plane lies inside the neighbouring curved "
           "surface's sag")
    return q, Repair("stop_from_fnumber", (k - 1, k), msg,
                     {"stop_diameter_mm": old_d, "f_number": old_n, "stop_behind_previous_mm": old_z},
                     {"stop_diameter_mm": new_d, "f_number": paraxial_f_number(q), "stop_behind_previous_mm": new_z})


def crossing(a: Surface, b: Surface, h: float, clearance: float = 0.0) -> float:
    """How far (mm) surface ``b`` (the next one) lies in front of ``a`` at height ``h``, plus
    ``clearance``; > 0 means they cross there."""
    from ..errors import require_type

    require_type("a", a, Surface, "a physcam.lens.prescription.Surface")
    require_type("b", b, Surface, "a physcam.lens.prescription.Surface")
    return max(sag(a, h, ax) - (a.thickness + sag(b, h, ax)) for ax in "xy") + clearance


@takes_prescription
def clip_pair(p: Prescription, i: int, clearance: float = CLEARANCE_MM) -> tuple[Prescription, Repair]:
    """Reduce the semi-diameters of surfaces ``i``, ``i + 1`` to where their edges clear by ``clearance``
    (the height found by bisection, rounded down to 0.01 mm)."""
    a, b = p.surfaces[i], p.surfaces[i + 1]
    lo, hi = 0.0, min(a.semi_diameter, b.semi_diameter)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if crossing(a, b, mid, clearance) < 0 else (lo, mid)
    h = int(lo * 100) / 100.0
    if h <= 0:
        raise LensFileError(f"lens {p.name!r}: surfaces {i} and {i + 1} cross at the axis; no repair is defined")
    old = (2 * a.semi_diameter, 2 * b.semi_diameter)
    q = p
    for j in (i, i + 1):
        q = _set(q, j, semi_diameter=min(q.surfaces[j].semi_diameter, h))
    msg = (f"clear diameters of surfaces {i} and {i + 1} reduced from {old[0]:g}/{old[1]:g} mm to "
           f"{2 * h:g} mm: at the file's values the two surfaces cross inside the aperture")
    return q, Repair("clip_pair", (i, i + 1), msg, {"diameters_mm": list(old)},
                     {"diameters_mm": [2 * q.surfaces[i].semi_diameter, 2 * q.surfaces[i + 1].semi_diameter]})


def edge_height(s: Surface) -> float:
    """The largest height a sphere or conic reaches (inf for flat, paraboloid, hyperboloid)."""
    from ..errors import require_type

    require_type("s", s, Surface, "a physcam.lens.prescription.Surface")
    c = s.curvature
    if c == 0.0:
        return math.inf
    k = s.conic if s.kind == "aspheric" else 0.0
    return math.inf if 1.0 + k <= 0 else 1.0 / (abs(c) * math.sqrt(1.0 + k))


@takes_prescription
def clamp_to_edge(p: Prescription, i: int) -> tuple[Prescription, Repair]:
    """Reduce the semi-diameter of surface ``i`` to 0.99 of its sphere's or conic's edge height."""
    s = p.surfaces[i]
    h = math.floor(0.99 * edge_height(s) * 100) / 100.0
    q = _set(p, i, semi_diameter=h)
    msg = (f"clear diameter of surface {i} reduced from {2 * s.semi_diameter:g} mm to {2 * h:g} mm: the file's "
           f"semi-diameter lies beyond the edge of its {'conic' if s.kind == 'aspheric' else 'sphere'} "
           f"(radius {abs(s.radius):g} mm)")
    return q, Repair("clamp_to_edge", (i,), msg, {"diameter_mm": 2 * s.semi_diameter}, {"diameter_mm": 2 * h})


def _beyond_edge(p: Prescription) -> list[int]:
    return [i for i, s in enumerate(p.surfaces) if s.semi_diameter > edge_height(s) * (1 + 1e-9)]


def _crossing_pairs(p: Prescription) -> list[int]:
    out = []
    for i in range(len(p.surfaces) - 1):
        a, b = p.surfaces[i], p.surfaces[i + 1]
        if crossing(a, b, min(a.semi_diameter, b.semi_diameter)) > 1e-6:
            out.append(i)
    return out


@takes_prescription
def aperture_factor(p: Prescription) -> float | None:
    """The factor stated f-number / paraxial f-number when it is 2 within 12 % (apertures written
    as diameters where semi-diameters were meant), else None."""
    n, _ = stated_f_number(p)
    try:
        fn = paraxial_f_number(p)
    except LensFileError:
        return None
    if not n or not math.isfinite(fn) or fn <= 0:
        return None
    r = n / fn
    return r if abs(r / 2.0 - 1.0) < 0.12 else None


@takes_prescription
def stop_is_entrance_pupil(p: Prescription, tolerance: float = 0.02) -> bool:
    """True when the stop diameter equals EFL/N (stated) within ``tolerance`` and the paraxial
    f-number misses the stated one by more than ``tolerance``: the file gave the entrance pupil."""
    n, _ = stated_f_number(p)
    f, _ = stated_focal_length(p)
    try:
        k = _stop(p)
        fn = paraxial_f_number(p)
    except LensFileError:
        return False
    if not n or not f or not math.isfinite(fn):
        return False
    d = 2 * p.surfaces[k].semi_diameter
    return abs(d / (f / n) - 1) < tolerance and abs(fn / n - 1) > tolerance


def _stop_inside_sag(p: Prescription) -> bool:
    b = _stop_bounds(p, 0.0)
    if b is None:
        return False
    k, gap, lower, upper = b
    return p.surfaces[k - 1].thickness < lower - 1e-6 or p.surfaces[k - 1].thickness > upper + 1e-6


@takes_prescription
def propose(p: Prescription) -> tuple[Prescription, list[Repair]]:
    """The minimal repairs that make ``p`` buildable and consistent with its stated f-number, in order:

    1. apertures written as diameters (stated / paraxial f-number = 2 within 12 %): all halved;
    2. a stop diameter equal to EFL/N that misses the stated f-number by > 2 %: the stop set from
       the f-number and moved inside its air gap;
    3. a stop plane inside a neighbour's sag: the stop moved inside its air gap;
    4. neighbouring surfaces that cross inside their apertures: both clear diameters reduced;
    5. a semi-diameter still beyond its sphere's edge: reduced to 0.99 of the edge height.

    Raises :class:`LensFileError` when no repair is defined (no stop, no room for the stop, surfaces
    that cross at the axis). A lens that needs nothing comes back unchanged with ``[]``.
    """
    repairs: list[Repair] = []
    q = p
    _stop(q)
    f = aperture_factor(q)
    if f is not None:
        q, r = scale_apertures(q, 0.5)
        repairs.append(r)
    if stop_is_entrance_pupil(q):
        q, r = stop_from_fnumber(q)
        repairs.append(r)
    if _stop_inside_sag(q):
        q, r = move_stop_clear(q)
        if r is not None:
            repairs.append(r)
    k = _stop(q)
    for i in _crossing_pairs(q):
        if k in (i, i + 1):
            continue  # the stop was moved above; a stop that still crosses has no room (raised there)
        q, r = clip_pair(q, i)
        repairs.append(r)
    for i in _beyond_edge(q):
        q, r = clamp_to_edge(q, i)
        repairs.append(r)
    return q, repairs


@takes_prescription
def with_corrections(p: Prescription, repairs: list[Repair], key: str = "provenance.corrections") -> Prescription:
    """``p`` with the repairs' messages appended to ``[provenance] corrections`` (and their numbers
    to ``[provenance] repairs``)."""
    from ..errors import WrongTypeError

    if not isinstance(repairs, (list, tuple)) or not all(isinstance(r, Repair) for r in repairs):
        raise WrongTypeError(f"repairs must be a list of physcam.lens.repair.Repair (from propose), got "
                             f"{type(repairs).__name__}")
    if not repairs:
        return p
    extras = dict(p.extras)
    old = json.loads(extras.get(key, "[]"))
    extras[key] = json.dumps(old + [r.message for r in repairs], ensure_ascii=False)
    old_r = json.loads(extras.get("provenance.repairs", "[]"))
    extras["provenance.repairs"] = json.dumps(old_r + [r.to_dict() for r in repairs], ensure_ascii=False,
                                              allow_nan=False, default=str)
    return replace(p, extras=tuple(sorted(extras.items())))
