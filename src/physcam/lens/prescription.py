"""The lens prescription: surfaces front to back, their media, apertures, focus groups.

A :class:`Prescription` is plain validated numbers. Readers (``physcam.lens.formats``)
build one; optics code (``physcam.optics.paraxial``, ``physcam.trace``) reads one and
never parses text.

Conventions (docs/conventions.md): millimetres; surfaces listed from the object
(scene) side to the image (film) side; light travels toward +z; the first vertex is
at z = 0; a radius is positive when its centre of curvature lies on the image side
(+z) of the vertex, 0 means flat; ``thickness`` is the axial distance from this
vertex to the next one (for the last surface: to the film plane at infinity focus,
0 when unknown); ``medium`` is what fills the gap *after* the surface.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
from collections.abc import Iterable

from .._record import field, record, replace
from ..errors import LensFileError

__all__ = [
    "SURFACE_KINDS",
    "Medium",
    "AIR",
    "Surface",
    "VariableGap",
    "Focus",
    "ZoomGap",
    "Zoom",
    "LensMetadata",
    "Prescription",
    "require_prescription",
    "takes_prescription",
    "first_argument_checked",
    "unvalidated",
    "OBJECT_DISTANCE_KEY",
]

#: ``Prescription.extras`` key of the object distance a finite-conjugate design images (mm, object
#: to first vertex; a Zemax file's object-surface DISZ). Absent for a lens working from infinity.
OBJECT_DISTANCE_KEY = "zemax.object_distance_mm"

#: Set inside :func:`unvalidated`: a list that ``validate`` appends ``(prescription, path, lines)``
#: to instead of checking (readers then hand back raw rows for ``physcam.lens.check``).
_RAW_SINK: contextvars.ContextVar[list | None] = contextvars.ContextVar("physcam_raw_sink", default=None)


@contextlib.contextmanager
def unvalidated():
    """Inside this block :meth:`Prescription.validate` checks nothing and records what it was
    given: ``with unvalidated() as seen: read_lens(f)`` returns the file's rows as written (the
    reader's own syntax checks still apply) and ``seen[-1]`` is ``(prescription, path, lines)``,
    ``lines`` mapping each surface to its file line. Used by :mod:`physcam.lens.check` and
    :mod:`physcam.lens.repair` to report and repair what validation refuses."""
    sink: list = []
    token = _RAW_SINK.set(sink)
    try:
        yield sink
    finally:
        _RAW_SINK.reset(token)

#: The surface types physcam understands, as stored in files.
SURFACE_KINDS = ("spherical", "flat", "stop", "aspheric", "cylindrical_x", "cylindrical_y")

#: Highest even-asphere term kept: A4, A6, ..., A16 (7 coefficients).
MAX_ASPHERIC_TERMS = 7

#: Physical bounds on a prescription's numbers (issue 8: no input may push NaN or inf through the
#: optics). Refractive indices of transmitting media lie between 1 (vacuum) and about 4 (germanium
#: in the infrared); optical glasses have Abbe numbers from about 17 to 95 (SCHOTT, OHARA
#: catalogues), 0 marks a medium treated as non-dispersive; no camera lens part is 100 m long.
MAX_INDEX = 5.0
MIN_ABBE, MAX_ABBE = 5.0, 200.0
MAX_LENGTH_MM = 1.0e5
MAX_CONIC = 1.0e4


@record(slots=True)
class Medium:
    """The optical medium after a surface.

    ``nd`` is the refractive index at the helium d line (587.5618 nm); ``vd`` the
    Abbe number (nd - 1) / (nF - nC), 0 for a medium treated as non-dispersive
    (air). ``glass`` is an optional catalogue name (e.g. ``"N-BK7"``), ``catalog`` the catalogue
    it comes from (e.g. ``"SCHOTT"``; None: the default search order of
    :func:`physcam.lens.catalog.find_glass`), ``dpgf`` a model glass's deviation of P_gF from the
    normal line (Zemax's model glass).
    """

    nd: float = 1.0
    vd: float = 0.0
    glass: str | None = None
    catalog: str | None = None
    dpgf: float = 0.0

    @property
    def is_air(self) -> bool:
        return self.nd == 1.0 and self.vd == 0.0 and self.glass is None


AIR = Medium()


@record(slots=True)
class Surface:
    """One refracting surface (or the aperture stop) of a sequential lens.

    radius: signed radius of curvature in mm, 0 = flat (see module notes).
    thickness: axial distance to the next vertex in mm (at infinity focus).
    medium: the medium after this surface.
    semi_diameter: clear semi-diameter in mm (half the clear aperture).
    kind: one of :data:`SURFACE_KINDS`.
    conic: conic constant k of an even asphere (0 sphere, -1 paraboloid).
    aspheric: even-polynomial coefficients (A4, A6, ... A16) of r**4, r**6, ...
      in mm**(1-2i); sag z(r) = c r^2 / (1 + sqrt(1 - (1+k) c^2 r^2)) + sum A_2i r^2i.
    """

    radius: float
    thickness: float
    medium: Medium = AIR
    semi_diameter: float = 0.0
    kind: str = "spherical"
    conic: float = 0.0
    aspheric: tuple[float, ...] = ()

    @property
    def curvature(self) -> float:
        """1 / radius in 1/mm, 0 for a flat surface or the stop."""
        return 0.0 if self.radius == 0.0 or self.kind in ("flat", "stop") else 1.0 / self.radius

    @property
    def curvature_x(self) -> float:
        """Curvature seen in the X-Z meridian (a cylinder in Y is flat there)."""
        return 0.0 if self.kind == "cylindrical_y" else self.curvature

    @property
    def curvature_y(self) -> float:
        """Curvature seen in the Y-Z meridian (a cylinder in X is flat there)."""
        return 0.0 if self.kind == "cylindrical_x" else self.curvature

    @property
    def is_stop(self) -> bool:
        return self.kind == "stop"


@record(slots=True)
class VariableGap:
    """An air gap that changes with focus: its thickness at infinity and at the close distance."""

    surface: int  # 0-based index of the surface whose following gap varies
    thickness_infinity: float
    thickness_close: float


@record(slots=True)
class Focus:
    """Internal focusing: gaps given at infinity and at ``close_distance``.

    ``close_distance`` is the object distance for the close set of gaps, in mm,
    measured from the front vertex (the patent convention of variable-distance
    tables). Several gaps may move (floating elements).
    """

    close_distance: float
    gaps: tuple[VariableGap, ...]


@record(slots=True)
class ZoomGap:
    """An air gap that changes with zoom: its thickness at each zoom position (infinity focus) and,
    where the source gives them, at each position's close focus (``thickness_close``)."""

    surface: int  # 0-based index of the surface whose following gap varies (the last: the back focus)
    thickness: tuple[float, ...]
    thickness_close: tuple[float, ...] | None = None


@record(slots=True)
class Zoom:
    """A zoom lens's tabulated positions (docs/zoom.md). The prescription's own surfaces are the first
    position; :func:`physcam.lens.zoom.prescription_at` gives any other.

    ``encoder``: the normalised zoom coordinate of each tabulated position, 0 at the first, 1 at the
    last, increasing (evenly spaced unless the source says otherwise). ``stop_semi_diameter``: the
    stop's full-open semi-diameter at each position where the source tabulates it (else the stop
    keeps its size across the zoom). ``close_distance``: each position's close-focus object
    distance (mm from the first vertex), with the gaps' ``thickness_close``: a zoom x focus grid.
    ``stated_focal_length``: the source's own focal-length labels, kept to compare, never used.
    """

    gaps: tuple[ZoomGap, ...]
    encoder: tuple[float, ...]
    stop_semi_diameter: tuple[float, ...] | None = None
    close_distance: tuple[float, ...] | None = None
    stated_focal_length: tuple[float, ...] | None = None

    @property
    def positions(self) -> int:
        return len(self.encoder)


@record(slots=True)
class LensMetadata:
    """What a lens is and where its numbers come from."""

    name: str = "unnamed lens"
    maker: str | None = None
    patent: str | None = None
    focal_length: float | None = None  # nominal, as engraved, mm
    max_fstop: float | None = None
    coating: str | None = None  # "none", "single", "multi" or free text
    #: the maker's minimum object distance (close focus), mm from the film plane, as engraved or
    #: published; None when the source gives none (then only the focusing model's own limit is known)
    minimum_object_distance: float | None = None
    t_stop: float | None = None  # the maker's stated T-stop wide open (transmission included)
    source: str | None = None  # provenance: file, book, patent table
    notes: str | None = None
    licence: str | None = None  # the prescription file's licence (SPDX identifier where one fits)


@record
class Prescription:
    """A sequential lens: surfaces front (scene side) to back (film side).

    ``squeeze`` is the anamorphic squeeze factor (1 for spherical lenses).
    ``wavelength_nm`` is the design wavelength used when none is asked for.
    ``extras`` holds file blocks physcam carries but does not model (see the field).
    Call :meth:`validate` (readers do) to check it describes a buildable lens.
    """

    surfaces: tuple[Surface, ...]
    metadata: LensMetadata = field(default_factory=LensMetadata)
    focus: Focus | None = None
    squeeze: float = 1.0
    wavelength_nm: float = 587.5618
    #: Blocks of a lens file that physcam does not model (ISET's microlens array, a
    #: file's provenance), carried unchanged as ``(key, JSON text)`` pairs so that
    #: write(read(file)) round-trips. Optics code ignores them. See docs/lens-formats.md.
    extras: tuple[tuple[str, str], ...] = ()
    #: The zoom table of a zoom lens (None for a prime); the surfaces are its first position.
    zoom: Zoom | None = None

    # ---- derived geometry -------------------------------------------------
    @property
    def name(self) -> str:
        return self.metadata.name

    @property
    def stop_index(self) -> int:
        """Index of the aperture stop surface."""
        for i, s in enumerate(self.surfaces):
            if s.is_stop:
                return i
        raise LensFileError(f"lens {self.name!r} has no aperture stop")

    @property
    def vertex_z(self) -> tuple[float, ...]:
        """Axial position of each vertex, mm from the first vertex (+z toward the film)."""
        z, out = 0.0, []
        for s in self.surfaces:
            out.append(z)
            z += s.thickness
        return tuple(out)

    @property
    def total_track(self) -> float:
        """First vertex to last vertex, mm (the glass length, without the back focus)."""
        return sum(s.thickness for s in self.surfaces[:-1])

    @property
    def object_distance_mm(self) -> float:
        """Object to first vertex (mm) of the conjugate the lens was designed for (``extras``
        :data:`OBJECT_DISTANCE_KEY`); ``inf`` for a lens designed for an object at infinity, as a
        camera lens is."""
        import json

        for k, v in self.extras:
            if k == OBJECT_DISTANCE_KEY:
                return float(json.loads(v))
        return math.inf

    @property
    def is_anamorphic(self) -> bool:
        return self.squeeze != 1.0 or any(s.kind.startswith("cylindrical") for s in self.surfaces)

    def with_surfaces(self, surfaces: Iterable[Surface]) -> "Prescription":
        return replace(self, surfaces=tuple(surfaces))

    def with_thicknesses(self, thicknesses: dict[int, float]) -> "Prescription":
        """A copy with some gaps changed (``{surface index: thickness}``)."""
        s = list(self.surfaces)
        for i, t in thicknesses.items():
            s[i] = replace(s[i], thickness=float(t))
        return self.with_surfaces(s)

    # ---- validation -------------------------------------------------------
    def validate(self, path: str | None = None, lines: list[int | None] | None = None) -> "Prescription":
        """Check the lens is buildable; raise :class:`LensFileError` naming the surface.

        ``lines`` (optional) maps each surface to the file line it came from, so the
        error points there. Checks: at least one surface, finite numbers within physical
        bounds (:data:`MAX_INDEX`, :data:`MIN_ABBE`..:data:`MAX_ABBE`, :data:`MAX_LENGTH_MM`,
        :data:`MAX_CONIC`), exactly one stop, positive semi-diameters that fit on their sphere, no
        negative gaps, neighbouring surfaces that do not cross inside their apertures,
        focus gaps that exist and are air.
        """

        sink = _RAW_SINK.get()
        if sink is not None:  # inside unvalidated(): record, do not check
            sink.append((self, path, None if lines is None else list(lines)))
            return self

        def fail(msg: str, i: int | None = None) -> LensFileError:
            line = lines[i] if (lines is not None and i is not None and i < len(lines)) else None
            where = f"surface {i}: " if i is not None else ""
            return LensFileError(f"lens {self.name!r}: {where}{msg}", path, line)

        if not self.surfaces:
            raise fail("no surfaces")
        if not (math.isfinite(self.squeeze) and self.squeeze > 0):
            raise fail(f"squeeze must be a positive number, got {self.squeeze}")
        stops = [i for i, s in enumerate(self.surfaces) if s.is_stop]
        if not stops:
            raise fail("no aperture stop (mark one surface as the stop)")
        if len(stops) > 1:
            raise fail(f"{len(stops)} aperture stops (surfaces {stops}); a lens has exactly one")
        for i, s in enumerate(self.surfaces):
            nums = (s.radius, s.thickness, s.semi_diameter, s.medium.nd, s.medium.vd, s.medium.dpgf, s.conic,
                    *s.aspheric)
            if not all(math.isfinite(v) for v in nums):
                raise fail("contains NaN or infinity", i)
            if s.kind not in SURFACE_KINDS:
                raise fail(f"unknown surface type {s.kind!r}; use one of {', '.join(SURFACE_KINDS)}", i)
            if s.semi_diameter <= 0:
                raise fail(f"clear semi-diameter must be > 0 mm, got {s.semi_diameter:g}", i)
            if not 1.0 <= s.medium.nd <= MAX_INDEX:
                raise fail(f"refractive index after the surface must lie between 1 and {MAX_INDEX:g} "
                           f"(optical glass is below 2.2, germanium 4), got {s.medium.nd:g}", i)
            if not (s.medium.vd == 0.0 or MIN_ABBE <= s.medium.vd <= MAX_ABBE):
                raise fail(f"Abbe number must be 0 (no dispersion) or between {MIN_ABBE:g} and {MAX_ABBE:g}, "
                           f"got {s.medium.vd:g}", i)
            for what, v in (("radius", s.radius), ("thickness", s.thickness), ("semi-diameter", s.semi_diameter)):
                if abs(v) > MAX_LENGTH_MM:
                    raise fail(f"{what} {v:g} mm is beyond any camera lens (at most {MAX_LENGTH_MM:g} mm)", i)
            if abs(s.conic) > MAX_CONIC:
                raise fail(f"conic constant {s.conic:g} is beyond +-{MAX_CONIC:g}", i)
            rim = [abs(a) * s.semi_diameter ** (2 * k + 4) for k, a in enumerate(s.aspheric)]
            if any(not (v <= MAX_LENGTH_MM) for v in rim):
                raise fail(f"an aspheric term adds more than {MAX_LENGTH_MM:g} mm of sag at the rim", i)
            if s.thickness < 0 and not (i == len(self.surfaces) - 1):
                raise fail(f"negative axial gap {s.thickness:g} mm", i)
            if s.kind in ("cylindrical_x", "cylindrical_y", "aspheric") and s.radius == 0:
                raise fail(f"a {s.kind} surface needs a non-zero radius", i)
            if (s.conic or s.aspheric) and s.kind != "aspheric":
                raise fail("conic or aspheric coefficients on a surface not marked aspheric", i)
            if len(s.aspheric) > MAX_ASPHERIC_TERMS:
                raise fail(f"at most {MAX_ASPHERIC_TERMS} aspheric terms (A4..A16), got {len(s.aspheric)}", i)
            c = s.curvature
            if c != 0.0 and s.kind != "aspheric" and abs(s.semi_diameter * c) > 1.0 + 1e-9:
                raise fail(
                    f"semi-diameter {s.semi_diameter:g} mm exceeds the radius {abs(s.radius):g} mm of its sphere", i
                )
            if s.kind == "aspheric" and c != 0.0 and (1.0 + s.conic) * (c * s.semi_diameter) ** 2 > 1.0 + 1e-9:
                raise fail(f"semi-diameter {s.semi_diameter:g} mm lies beyond the conic's edge", i)
        # Surfaces that cross: sag of the next surface at the common aperture must not
        # come before the sag of this one (measured from this vertex). A stop 0 mm before a face
        # is a stop on that face (Zemax's and CODE V's STOP on a lens surface): a concave face
        # curves in front of the stop's plane by design, the paraxial stop stays at the vertex,
        # and the tracer follows the face back (a virtual leg in the medium before it).
        from .geometry import sag  # local import: geometry depends on nothing but math

        for i in range(len(self.surfaces) - 1):
            a, b = self.surfaces[i], self.surfaces[i + 1]
            if a.is_stop and a.thickness == 0.0:
                continue
            r = min(a.semi_diameter, b.semi_diameter)
            for axis in ("x", "y"):
                za = sag(a, r, axis)
                zb = a.thickness + sag(b, r, axis)
                if zb < za - 1e-6:
                    raise fail(
                        f"crosses surface {i + 1} inside the clear aperture (at height {r:g} mm the next surface is "
                        f"{za - zb:.3g} mm in front of this one); check thickness and semi-diameters",
                        i,
                    )
        if self.focus is not None:
            f = self.focus
            if not (math.isfinite(f.close_distance) and f.close_distance > 0):
                raise fail(f"focus close_distance must be > 0 mm, got {f.close_distance}")
            for g in f.gaps:
                if not 0 <= g.surface < len(self.surfaces):
                    raise fail(f"focus group gap refers to surface {g.surface}, which does not exist")
                if not self.surfaces[g.surface].medium.is_air and self.surfaces[g.surface].medium.nd != 1.0:
                    raise fail("a focus gap must be an air gap", g.surface)
                if not (math.isfinite(g.thickness_close) and g.thickness_close >= 0):
                    raise fail(f"focus gap at close distance must be >= 0 mm, got {g.thickness_close}", g.surface)
        if self.zoom is not None:
            _check_zoom(self, fail)
        return self


def _check_zoom(p: "Prescription", fail) -> None:
    """The zoom table fits the lens: positions agree in number, the encoder runs 0..1 upward, every
    varying gap is an air gap with finite non-negative thicknesses, the surfaces hold the first
    position, and a zoom x focus grid comes with the lens's focus at its first position."""
    z, n = p.zoom, p.zoom.positions
    if n < 2:
        raise fail(f"a zoom table needs at least two positions, got {n}")
    enc = z.encoder
    if not all(math.isfinite(e) for e in enc) or enc[0] != 0.0 or enc[-1] != 1.0 or \
            any(b <= a for a, b in zip(enc, enc[1:])):
        raise fail(f"zoom encoder values must rise from 0 to 1, got {list(enc)}")
    if not z.gaps:
        raise fail("a zoom table needs at least one varying gap")
    seen = set()
    for g in z.gaps:
        if not 0 <= g.surface < len(p.surfaces) or g.surface in seen:
            raise fail(f"zoom gap refers to surface {g.surface}, which does not exist or is listed twice")
        seen.add(g.surface)
        if p.surfaces[g.surface].medium.nd != 1.0:
            raise fail("a zoom gap must be an air gap", g.surface)
        for what, values in (("thickness", g.thickness), ("thickness_close", g.thickness_close)):
            if values is None:
                continue
            if len(values) != n or not all(math.isfinite(t) and 0.0 <= t <= MAX_LENGTH_MM for t in values):
                raise fail(f"zoom gap {what} needs {n} finite values >= 0 mm, got {list(values)}", g.surface)
        if p.surfaces[g.surface].thickness != g.thickness[0]:
            raise fail(f"thickness {p.surfaces[g.surface].thickness:g} mm is not the zoom table's first position "
                       f"{g.thickness[0]:g} mm", g.surface)
    for what, values in (("stop_semi_diameter", z.stop_semi_diameter), ("close_distance", z.close_distance),
                         ("stated_focal_length", z.stated_focal_length)):
        if values is not None and (len(values) != n or not all(math.isfinite(v) and 0 < v <= MAX_LENGTH_MM
                                                               for v in values)):
            raise fail(f"zoom {what} needs {n} positive finite values, got {list(values)}")
    closes = [g for g in z.gaps if g.thickness_close is not None]
    if (z.close_distance is None) != (not closes):
        raise fail("a zoom x focus grid needs both close_distance and the gaps' thickness_close")
    if closes and (p.focus is None or p.focus.close_distance != z.close_distance[0]
                   or {g.surface for g in p.focus.gaps} != {g.surface for g in closes}):
        raise fail("the lens's focus must be the zoom table's first position (close distance and focus gaps)")
    if not closes and p.focus is not None and seen & {g.surface for g in p.focus.gaps}:
        raise fail("a focus gap that also zooms needs its close thickness at every zoom position (thickness_close)")
    for k in range(1, n):  # a gap is smallest at a tabulated position (the cams never overshoot): check each
        at_k = replace(p, zoom=None, focus=None,
                       surfaces=tuple(replace(s, thickness=next((g.thickness[k] for g in z.gaps if g.surface == i),
                                                                s.thickness)) for i, s in enumerate(p.surfaces)))
        try:
            at_k.validate()
        except LensFileError as exc:
            raise fail(f"at zoom position {k + 1}: {exc.args[0]}") from None


def require_prescription(value, name: str = "lens") -> Prescription:
    """``value`` if it is a :class:`Prescription`, else :class:`~physcam.errors.WrongTypeError`
    saying how to get one (a lens name or file goes through ``load_lens``)."""
    from ..errors import require_type

    hint = "load one with physcam.lens.library.load_lens(name or file)"
    return require_type(name, value, Prescription, hint)


def first_argument_checked(check):
    """Decorator factory: ``check(value, name)`` is called on the decorated function's first argument
    (positional or by keyword; ``name`` is that parameter's own name, also under other decorators)
    before the function runs. The one mechanism of :func:`takes_prescription` and
    :func:`physcam.optics.state.takes_camera`."""
    import functools

    from ..errors import WrongTypeError

    if not callable(check):
        raise WrongTypeError(f"check must be a function check(value, name), got {type(check).__name__}")

    def decorate(fn):
        inner = fn
        while hasattr(inner, "__wrapped__"):  # under another decorator: the function's own first parameter
            inner = inner.__wrapped__
        first = inner.__code__.co_varnames[0]

        @functools.wraps(fn)
        def checked(*args, **kwargs):
            if args:
                check(args[0], first)
            elif first in kwargs:
                check(kwargs[first], first)
            return fn(*args, **kwargs)

        return checked

    return decorate


def takes_prescription(fn):
    """Decorator: the function's first argument (``prescription`` or ``lens``) must be a
    :class:`Prescription`; anything else is a :class:`~physcam.errors.WrongTypeError`, not an
    AttributeError deep inside the optics."""
    return first_argument_checked(require_prescription)(fn)
