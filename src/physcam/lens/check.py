"""``physcam lens check``: what is inconsistent in a lens file, where, by how much, and what it implies.

:func:`check` takes a lens file (read *without* validation, so a file that
:meth:`Prescription.validate` refuses can still be examined), a bundled lens name or a
:class:`Prescription`, and returns :class:`Finding` s, each with a severity:

- ``error``: the lens cannot be traced as written (a semi-diameter beyond its sphere, surfaces
  that cross inside their apertures, a stop plane inside a neighbour's sag, bad numbers);
- ``warning``: it can be traced but contradicts itself or its stated data (EFL or f-number
  against the name or ``[lens]`` table, a stop wider than the beam its neighbours pass,
  ``[focus]`` gaps that push the image away from the film, a T-stop faster than the f-number, glass
  off the glass map);
- ``note``: worth knowing (a duplicate of a bundled lens, a small mismatch, a maker's close focus
  closer than the focus model reaches, numbers not compared with their primary source or a licence
  nobody established, as the ``[provenance]`` record says).

Every finding names the surface (0-based, as in physcam) and the file line. The checks here
use only the prescription (paraxial optics at nd, exact sags); ray-traced checks (the on-axis
beam clipped by rims, vignetting at a sensor corner, the image circle) belong to higher layers
and are passed in as ``probes`` (``physcam lens check`` adds them; see docs/lens-check.md).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable

from ..errors import LensFileError, PhysCamError
from .geometry import sag
from .prescription import MAX_ABBE, MAX_INDEX, MIN_ABBE, Prescription
from .raw import RawLens, read_raw
from .repair import (
    aperture_factor,
    crossing,
    edge_height,
    stated_f_number,
    stated_focal_length,
    stop_is_entrance_pupil,
)

__all__ = ["Finding", "RawLens", "read_raw", "check", "SEVERITIES"]

SEVERITIES = ("error", "warning", "note")


@dataclass(frozen=True)
class Finding:
    """One thing :func:`check` found: severity, a stable code, where, the numbers and what they imply."""

    severity: str  # error | warning | note
    code: str
    message: str
    implication: str = ""
    surface: int | None = None
    line: int | None = None
    file: str | None = None
    values: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"severity": self.severity, "code": self.code, "surface": self.surface, "line": self.line,
                "file": self.file, "message": self.message, "implication": self.implication,
                "values": {k: (v if not isinstance(v, float) or math.isfinite(v) else None)
                           for k, v in self.values.items()}}

    def __str__(self) -> str:
        where = self.file or "<lens>"
        if self.line is not None:
            where += f":{self.line}"
        surf = f"surface {self.surface}: " if self.surface is not None else ""
        tail = f" -> {self.implication}" if self.implication else ""
        return f"{where}: {self.severity}: {surf}{self.message}{tail}"


# ---- small paraxial helpers (Y or X meridian, nd) ------------------------------------
def _curv(s, axis):
    return s.curvature_x if axis == "x" else s.curvature_y


def _marginal(p: Prescription, axis: str = "y", y0: float = 1.0, u0: float = 0.0):
    """Heights at each surface and the final angle of a ray entering at (y0, u0)."""
    ys, y, u, n = [], y0, u0, 1.0
    for i, s in enumerate(p.surfaces):
        ys.append(y)
        n2 = s.medium.nd
        u = (n * u - y * _curv(s, axis) * (n2 - n)) / n2
        n = n2
        if i < len(p.surfaces) - 1:
            y += s.thickness * u
    return ys, y, u


def _efl(p: Prescription, axis: str) -> float:
    _, _, u = _marginal(p, axis)
    return math.inf if u == 0 else -1.0 / u


def _fnum(p: Prescription, axis: str) -> float:
    k = p.stop_index
    ys, _, _ = _marginal(p, axis)
    if ys[k] == 0:
        return math.nan
    return _efl(p, axis) / (2 * p.surfaces[k].semi_diameter / abs(ys[k]))


def _image_distance(p: Prescription, object_distance: float, axis: str = "y") -> float:
    """Paraxial image distance after the last vertex for an object ``object_distance`` mm in front."""
    if math.isinf(object_distance):
        _, y, u = _marginal(p, axis)
    else:
        u0 = 1.0 / object_distance
        _, y, u = _marginal(p, axis, y0=object_distance * u0, u0=u0)
    return math.inf if u == 0 else -y / u


# ---- the checks ------------------------------------------------------------------------
class _Ctx:
    def __init__(self, p: Prescription, raw: RawLens | None, slug: str | None):
        self.p, self.raw, self.slug = p, raw, slug
        self.out: list[Finding] = []

    def add(self, severity, code, message, implication="", surface=None, **values):
        line = self.raw.line(surface) if self.raw is not None else None
        self.out.append(Finding(severity, code, message, implication, surface, line,
                                self.raw.path if self.raw is not None else None, values))


def _structure(c: _Ctx) -> bool:
    """Bounds and counts; False when the numbers are too broken for geometric checks."""
    p = c.p
    if not p.surfaces:
        c.add("error", "no_surfaces", "the file has no surfaces", "nothing to trace; no repair is defined")
        return False
    stops = [i for i, s in enumerate(p.surfaces) if s.is_stop]
    if len(stops) != 1:
        c.add("error", "stop_count", f"{len(stops)} aperture stops (surfaces {stops})",
              "a lens has exactly one stop: mark one surface as type = stop; no repair is defined", count=len(stops))
    ok = len(stops) == 1
    for i, s in enumerate(p.surfaces):
        nums = (s.radius, s.thickness, s.semi_diameter, s.medium.nd, s.medium.vd, s.conic, *s.aspheric)
        if not all(math.isfinite(v) for v in nums):
            c.add("error", "not_finite", "contains NaN or infinity", "no repair is defined", i)
            ok = False
            continue
        if s.semi_diameter <= 0:
            c.add("error", "semi_diameter", f"clear semi-diameter {s.semi_diameter:g} mm is not positive",
                  "give the clear aperture; no repair is defined", i, semi_diameter_mm=s.semi_diameter)
            ok = False
        if not 1.0 <= s.medium.nd <= MAX_INDEX:
            c.add("error", "index", f"refractive index {s.medium.nd:g} is outside 1..{MAX_INDEX:g}",
                  "no transmitting medium has it; no repair is defined", i, nd=s.medium.nd)
            ok = False
        if not (s.medium.vd == 0 or MIN_ABBE <= s.medium.vd <= MAX_ABBE):
            c.add("error", "abbe", f"Abbe number {s.medium.vd:g} is outside {MIN_ABBE:g}..{MAX_ABBE:g}",
                  "no glass has it; no repair is defined", i, vd=s.medium.vd)
            ok = False
        if s.thickness < 0 and i < len(p.surfaces) - 1:
            c.add("error", "negative_gap", f"negative axial gap {s.thickness:g} mm",
                  "thickness is vertex to next vertex; a position-after-previous convention was probably mixed in",
                  i, thickness_mm=s.thickness)
            ok = False
        if max((abs(s.radius), abs(s.thickness), abs(s.semi_diameter))) > 1e5:
            c.add("error", "too_long", "a length beyond 100 m", "no repair is defined", i)
            ok = False
    return ok


def _edges(c: _Ctx) -> None:
    for i, s in enumerate(c.p.surfaces):
        h = edge_height(s)
        if s.semi_diameter > h * (1 + 1e-9):
            what = "conic's edge" if s.kind == "aspheric" else f"sphere (radius {abs(s.radius):g} mm)"
            c.add("error", "beyond_edge",
                  f"semi-diameter {s.semi_diameter:g} mm lies beyond its {what}: {s.semi_diameter / h:.2f}x the "
                  f"largest height {h:.4g} mm", "rays there cannot meet the surface; if most apertures are about 2x "
                  "too large the file gives diameters where semi-diameters are meant (see the f-number finding)",
                  i, semi_diameter_mm=s.semi_diameter, edge_height_mm=h, ratio=s.semi_diameter / h)


def _cross_height(a, b, hmax) -> float:
    lo, hi = 0.0, hmax
    if crossing(a, b, 0.0) > 1e-6:
        return 0.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if crossing(a, b, mid) <= 1e-6 else (lo, mid)
    return hi


def _crossings(c: _Ctx) -> None:
    s = c.p.surfaces
    for i in range(len(s) - 1):
        a, b = s[i], s[i + 1]
        hmax = min(a.semi_diameter, b.semi_diameter, edge_height(a), edge_height(b))
        over = crossing(a, b, hmax)
        if not over > 1e-6:
            continue
        if a.is_stop or b.is_stop:
            k = i if a.is_stop else i + 1
            j = i + 1 if a.is_stop else i
            nb = s[j]
            sg = max(abs(sag(nb, min(nb.semi_diameter, s[k].semi_diameter), ax)) for ax in "xy")
            if k > 0 and k < len(s) - 1:
                gap = s[k - 1].thickness + s[k].thickness
                dist = s[k - 1].thickness if j == k - 1 else s[k].thickness
                c.add("error", "stop_in_sag",
                      f"the stop plane lies inside the sag of surface {j}: it is {dist:g} mm from that vertex but the "
                      f"surface curves {sg:.3f} mm toward it at the stop's semi-diameter {s[k].semi_diameter:g} mm",
                      f"move the stop inside its {gap:g} mm air gap (glass unchanged), or the stop diameter is wrong "
                      "(see the f-number finding); `physcam lens fix` does this", k, distance_mm=dist, sag_mm=sg,
                      neighbour=j, air_gap_mm=gap)
            continue
        h = _cross_height(a, b, hmax)
        c.add("error", "surfaces_cross",
              f"surfaces {i} and {i + 1} cross inside their clear apertures: they meet at height {h:.3f} mm and at "
              f"{hmax:g} mm surface {i + 1} lies {over:.3f} mm in front of surface {i}",
              f"the clear diameters can be at most {2 * h:.2f} mm (less a clearance); check the thickness or the "
              "apertures", i, crossing_height_mm=h, overlap_mm=over, at_height_mm=hmax)


def _stop_beam(c: _Ctx) -> None:
    p = c.p
    k = p.stop_index
    for axis in (("x", "y") if p.is_anamorphic else ("y",)):
        ys, _, _ = _marginal(p, axis)
        if ys[k] == 0:
            return
        scale = p.surfaces[k].semi_diameter / abs(ys[k])
        worst, wi = 1.0, None
        for i, s in enumerate(p.surfaces):
            if i == k or ys[i] == 0:
                continue
            r = s.semi_diameter / (abs(ys[i]) * scale)
            if r < worst:
                worst, wi = r, i
        if wi is not None and worst < 0.995:
            n_file = _fnum(p, axis)
            c.add("warning" if worst < 0.95 else "note", "stop_wider_than_beam",
                  f"the stop (semi-diameter {p.surfaces[k].semi_diameter:g} mm) is wider than the axial beam surface "
                  f"{wi} passes ({axis.upper()} meridian): that rim limits the beam to {100 * worst:.1f} % of the "
                  f"stop's diameter", f"the paraxial f-number at full aperture is f/{n_file / worst:.2f}, not "
                  f"f/{n_file:.2f} as the stop says; surface {wi} is the real aperture stop wide open", k,
                  limiting_surface=wi, fraction=worst, f_number_stop=n_file, f_number_effective=n_file / worst)
            return


def _stated(c: _Ctx) -> None:
    p = c.p
    axes = ("x", "y") if p.is_anamorphic else ("y",)
    efl = {a: _efl(p, a) for a in axes}
    f, fsrc = stated_focal_length(p)
    if f:
        a = min(axes, key=lambda a: abs(efl[a] / f - 1) if math.isfinite(efl[a]) else math.inf)
        r = efl[a] / f
        if math.isfinite(r) and abs(r - 1) > 0.01:
            sev = "warning" if abs(r - 1) > 0.03 else "note"
            other = ""
            if c.raw is not None and c.raw.path:
                m = re.findall(r"(\d+(?:\.\d+)?)\s*mm", Path(c.raw.path).name.replace("_", " "), re.I)
                if m and abs(float(m[-1]) / efl[a] - 1) < 0.01:
                    other = f"; the file name says {m[-1]} mm, which matches"
            c.add(sev, "focal_length",
                  f"computed EFL {efl[a]:.3f} mm ({a.upper()} meridian) against the stated {f:g} mm ({fsrc}): "
                  f"factor {r:.3f}{other}",
                  "the lens is a different focal length than labelled (a scaled design, or a wrong label); "
                  "field of view and focus follow the computed EFL", None, efl_mm=efl[a], stated_mm=f, factor=r)
    n, nsrc = stated_f_number(p)
    if not n:
        return
    fn = {a: _fnum(p, a) for a in axes}
    a = min(axes, key=lambda a: abs(fn[a] / n - 1) if math.isfinite(fn[a]) else math.inf)
    if not math.isfinite(fn[a]):
        return
    r = n / fn[a]
    k = p.stop_index
    vals = dict(f_number=fn[a], stated=n, factor=r)
    if aperture_factor(p) is not None:
        c.add("warning", "apertures_doubled",
              f"paraxial f-number f/{fn[a]:.2f} against the stated f/{n:g} ({nsrc}): every aperture is {r:.2f}x "
              "what the f-number needs: diameters written as semi-diameters?",
              "halve every aperture (`physcam lens fix` does; then f/"
              f"{fn[a] * 2:.2f})", None, **vals)
    elif stop_is_entrance_pupil(p):
        f0 = stated_focal_length(p)[0]
        c.add("warning", "stop_is_entrance_pupil",
              f"the stop diameter {2 * p.surfaces[k].semi_diameter:g} mm equals EFL/N = {f0:g}/{n:g} = {f0 / n:.3f} mm, "
              f"the entrance pupil, but the front group magnifies the stop: paraxial f/{fn[a]:.2f} against the "
              f"stated f/{n:g}", f"scale the stop diameter by {fn[a] / n:.3f} so the lens is f/{n:g} "
              "(`physcam lens fix` does, moving the stop inside its air gap)", k, **vals)
    elif abs(r - 1) > 0.01:
        sev = "warning" if abs(r - 1) > 0.05 else "note"
        c.add(sev, "f_number",
              f"paraxial f-number f/{fn[a]:.2f} ({a.upper()} meridian, the file's stop) against the stated f/{n:g} "
              f"({nsrc}): factor {r:.3f}", f"the stop diameter would have to be {fn[a] / n:.3f}x for the stated "
              "f-number" + (" (the EFL differs from the stated one too)" if f and abs(efl[a] / f - 1) > 0.01 else ""),
              k, **vals)


#: A ``[focus]`` table whose gaps push the close object's image away from the film by more than this
#: fraction of the distance unit focusing would move it is focusing the wrong way (module notes of _focus).
WRONG_WAY_FRACTION = 0.5


def _focus(c: _Ctx) -> None:
    """Judge a ``[focus]`` table the way physcam focuses the lens (physcam.optics.focusing): the gaps move
    to their close values and the back focus is then whatever images the close object on the film.

    Unit focusing would move the film ``need`` mm (the close object's image behind the infinity image,
    gaps held); with the close gaps the lens extends ``extension`` mm instead. The gaps do the fraction
    ``(need - extension) / need`` of the focusing: about 1 for a focusing group (the back focus stays),
    about 0 for a floating group that corrects aberrations while the whole lens extends (the patents of
    Sigma 40/50 mm and Nikkor 28 mm state a close back focus that grows; their groups push the image a
    few per cent *away*), and about -1 for a table with its travel reversed or its columns swapped. Below
    -:data:`WRONG_WAY_FRACTION` the gaps work against focusing (the lens would extend over 1.5x what unit
    focusing needs): a warning. Between 0.1 and 0.9 they do part of it and the extension the rest: a note.
    """
    p = c.p
    if p.focus is None or not p.focus.gaps:
        return
    d = p.focus.close_distance
    close = p.with_thicknesses({g.surface: g.thickness_close for g in p.focus.gaps
                                if 0 <= g.surface < len(p.surfaces)})
    b_inf = _image_distance(p, math.inf)  # the back focus at infinity, as physcam focuses (not the file's gap)
    need = _image_distance(p, d) - b_inf  # unit focusing: the film moves this far back
    extension = _image_distance(close, d) - b_inf  # with the close gaps: how far the back focus grows
    if not (math.isfinite(need) and math.isfinite(extension)) or need <= 0:
        return
    done = (need - extension) / need
    g0 = p.focus.gaps[0].surface
    vals = dict(unit_extension_mm=need, extension_mm=extension, fraction_by_gaps=done)
    if done < -WRONG_WAY_FRACTION:
        c.add("warning", "focus_wrong_way",
              f"[focus]: an object {d:g} mm away images {need:.3f} mm behind the film with the gaps held (unit "
              f"focusing), but {extension:.3f} mm behind it with the close-focus gaps: the gaps push the image "
              f"away by {-done:.0%} of the focusing they should do",
              "the lens would extend more than 1.5x a unit-focusing lens; swap thickness and thickness_close, "
              "or check the sign of the group's travel", g0, **vals)
    elif 0.1 < done < 0.9 and abs(extension) > 0.05:
        c.add("note", "focus_incomplete",
              f"[focus]: the close-focus gaps do {done:.0%} of the focusing for an object {d:g} mm away; the back "
              f"focus grows {extension:.3f} mm for the rest (unit focusing: {need:.3f} mm)",
              "physcam solves the back focus at every mark, so the lens focuses; a table meant to focus by its "
              "gaps alone has an approximate close distance", g0, **vals)


def _closest_mark(p: Prescription) -> tuple[float, str]:
    """The closest focus mark (mm from the film) physcam's focus model reaches, and how: the ``[focus]``
    gaps at their close values with the back focus that images that object, or, without a ``[focus]``
    table, unit focusing's 1:1 conjugate (physcam.optics.focusing.closest_focus, here at nd)."""
    if p.focus is not None and p.focus.gaps:
        d = p.focus.close_distance
        close = p.with_thicknesses({g.surface: g.thickness_close for g in p.focus.gaps
                                    if 0 <= g.surface < len(p.surfaces)})
        return d + close.total_track + _image_distance(close, d), "the [focus] table's close position"
    # a ray leaving the first vertex at height 1 with angle t ends with u' = a + b t: magnification t / u' = -1
    _, _, a = _marginal(p, u0=0.0)
    _, _, u1 = _marginal(p, u0=1.0)
    t = -a / (1.0 + (u1 - a))
    if not t > 0:
        return math.nan, "unit focusing's 1:1 limit"
    return 1.0 / t + p.total_track + _image_distance(p, 1.0 / t), "unit focusing's 1:1 limit"


def _maker_data(c: _Ctx) -> None:
    """The maker's statements in ``[lens]`` against the prescription: a T-stop faster than the paraxial
    f-number (a T-stop counts the light the glass loses, so T >= N), and a minimum object distance closer
    than physcam's focus model reaches (close focus, breathing and the lens card then stop at the model's
    limit; the MOD stays the maker's statement, the file is not wrong)."""
    m = c.p.metadata
    if m.t_stop is not None:
        n = _fnum(c.p, "y")
        if math.isfinite(n) and m.t_stop < n * (1 - 5e-3):
            c.add("warning", "t_stop_faster", f"[lens] t_stop T{m.t_stop:g} is faster than the paraxial f-number "
                  f"f/{n:.2f} (the file's stop)", "a T-stop is the f-number with the glass's losses counted, so it is "
                  "never below it: check the T-stop or the stop's semi-diameter", None, t_stop=m.t_stop, f_number=n)
    mod = m.minimum_object_distance
    if mod is None or c.p.zoom is not None:
        return
    limit, how = _closest_mark(c.p)
    if math.isfinite(limit) and mod < limit - 1.0:  # 1 mm: the model at nd against a number printed to cm
        c.add("note", "mod_beyond_focus_model",
              f"[lens] minimum_object_distance {mod:g} mm (the maker's close focus) is closer than physcam's focus "
              f"model reaches: {limit:.1f} mm from the film ({how})",
              f"close focus, breathing and the lens card stop at {limit:.0f} mm; the file keeps the maker's MOD as "
              "stated, which the prescription's focusing (a patent example's table, say) does not reach",
              minimum_object_distance_mm=mod, closest_mark_mm=limit)


#: A generous outline of the glass map (nd, Vd) of optical glasses from the SCHOTT, OHARA, HOYA and
#: CDGM catalogues: Vd at most 95 - 110 (nd - 1.45) and at least max(15, 45 - 85 (nd - 1.45)).
def _glass_ok(nd: float, vd: float) -> bool:
    return 1.40 <= nd <= 2.05 and max(15.0, 45 - 85 * (nd - 1.45)) <= vd <= 95 - 110 * (nd - 1.45)


def _glass(c: _Ctx) -> None:
    seen = set()
    for i, s in enumerate(c.p.surfaces):
        m = s.medium
        if m.nd == 1.0 or (m.nd, m.vd) in seen:
            continue
        seen.add((m.nd, m.vd))
        if m.vd == 0:
            c.add("note", "glass_no_dispersion", f"glass nd {m.nd:g} has no Abbe number (Vd 0)",
                  "it is treated as non-dispersive: colour analyses will show no colour from it", i, nd=m.nd)
        elif not _glass_ok(m.nd, m.vd):
            c.add("warning", "glass_off_map",
                  f"glass nd {m.nd:g}, Vd {m.vd:g} lies outside the map of optical glasses",
                  "a typing error in nd or Vd, or the two columns swapped; dispersion and colour follow these numbers",
                  i, nd=m.nd, vd=m.vd)


def _duplicates(c: _Ctx) -> None:
    from .library import _index

    p = c.p
    for rec, q in _index():
        if rec.slug == c.slug or len(q.surfaces) != len(p.surfaces):
            continue
        if any(a.kind != b.kind for a, b in zip(p.surfaces, q.surfaces)):
            continue
        if any(abs(a.medium.nd - b.medium.nd) > 1e-4 for a, b in zip(p.surfaces, q.surfaces)):
            continue
        sq = sum(abs(b.radius) for b in q.surfaces)
        if sq == 0:
            continue
        k = sum(abs(a.radius) for a in p.surfaces) / sq
        lengths = [(a.radius, b.radius) for a, b in zip(p.surfaces, q.surfaces)]
        lengths += [(a.thickness, b.thickness) for a, b in zip(p.surfaces[:-1], q.surfaces[:-1])]
        if all(abs(x - k * y) <= 2e-3 * (abs(x) + 1e-3 * k) + 1e-6 for x, y in lengths):
            if abs(k - 1) < 1e-6:
                same_ap = all(abs(a.semi_diameter - b.semi_diameter) < 1e-6 for a, b in zip(p.surfaces, q.surfaces))
                what = "the same prescription" if same_ap else "the same radii, gaps and glass (other apertures)"
                c.add("note", "duplicate", f"{what} as the {_whose(rec)} lens {rec.slug!r}",
                      f"load it by name (`physcam lens show --lens {rec.slug}`)" + (
                          f"; the {_whose(rec)} copy is corrected (`physcam lens check --lens {rec.slug}`)"
                          if rec.corrected else ""), None, slug=rec.slug, scale=1.0)
            else:
                c.add("note", "duplicate_scaled", f"the {_whose(rec)} lens {rec.slug!r} scaled by {k:.4f}",
                      f"the same design at {k:.4f}x the size", None, slug=rec.slug, scale=k)


def _whose(rec) -> str:
    """How a finding names a library lens: "bundled", or "installed" for one of the user's library."""
    return "installed" if rec.library == "user" else "bundled"


def _provenance(c: _Ctx) -> None:
    """What a lens file's provenance record says about trusting and sharing it (only for a file that has one)."""
    from .provenance import primary_source_claim_gaps, provenance_of

    prov = provenance_of(c.p)
    if prov == type(prov)():
        return
    gaps = primary_source_claim_gaps(prov)
    if gaps:
        c.add("warning", "provenance_check_unstated",
              "primary_source_checked is true, but " + "; ".join(gaps),
              "nobody can tell what was compared with the primary source: state it in [provenance] checks, or set "
              "primary_source_checked = false", None, gaps=gaps)
    if prov.primary_source_checked is False:
        c.add("note", "provenance_unchecked",
              f"its numbers were not compared with the primary source ({prov.source or 'not named'})",
              f"they are as transcribed from {prov.transcribed_from or 'a source the file does not name'}")
    if prov.licence and not prov.licence_resolved:
        c.add("note", "licence_unresolved", f"licence {prov.licence}: nobody has established the file's licence",
              "others may not be free to use or share the file")


CHECKS = (_edges, _crossings, _stop_beam, _stated, _focus, _maker_data, _glass, _duplicates, _provenance)


def check(lens, *, format: str | None = None, probes: Iterable[Callable[[Prescription], list]] = ()) -> list[Finding]:
    """Findings about ``lens``: a file path (read without validation), a bundled lens name or a
    :class:`Prescription`. ``probes`` are extra checks ``probe(prescription) -> [Finding]`` run on a
    lens that can be traced (as written, or repaired when only repairable errors were found).

    Never raises for a bad file: a file that cannot be read at all is one ``error`` finding.
    """
    raw, slug = None, None
    if isinstance(lens, Prescription):
        p = lens
    else:
        s = str(lens)
        path = Path(s)
        try:
            if path.is_file():
                raw = read_raw(path, format)
            else:
                from .library import find_lens

                rec = find_lens(s)
                raw, slug = read_raw(rec.path, "physcam"), rec.slug
        except PhysCamError as exc:
            return [Finding("error", "unreadable", str(exc).splitlines()[0] if str(exc) else type(exc).__name__,
                            "the file is not a lens physcam can read; no repair is defined", None,
                            getattr(exc, "line", None), getattr(exc, "path", None) or s)]
        p = raw.prescription
    c = _Ctx(p, raw, slug)
    if not _structure(c):
        return c.out
    for fn in CHECKS:
        try:
            fn(c)
        except (ArithmeticError, ValueError, LensFileError) as exc:
            c.add("note", "not_evaluated", f"check {fn.__name__.strip('_')} could not be evaluated ({exc})")
    if probes:
        target, note = p, ""
        if any(f.severity == "error" for f in c.out):
            note = " (traced on the lens as `physcam lens fix` repairs it)"
            from .repair import propose

            try:
                target, _ = propose(p)
                target.validate()
            except (PhysCamError, ArithmeticError, ValueError):
                target = None
        if target is not None:
            for probe in probes:
                try:
                    for f in probe(target):
                        c.out.append(Finding(f.severity, f.code, f.message + note, f.implication,
                                             f.surface, raw.line(f.surface) if raw else None,
                                             raw.path if raw else None, f.values))
                except (PhysCamError, ArithmeticError, ValueError) as exc:
                    c.add("note", "not_evaluated", f"ray check could not be evaluated ({str(exc).splitlines()[0]})")
    order = {s: i for i, s in enumerate(SEVERITIES)}
    return sorted(c.out, key=lambda f: order[f.severity])
