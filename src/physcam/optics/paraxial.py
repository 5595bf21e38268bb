"""Gaussian (paraxial, first-order) optics of a lens prescription.

A y-nu paraxial trace (equivalently, 2x2 ABCD matrices acting on the ray height
``y`` and the reduced angle ``n u``), run separately in the X-Z and Y-Z meridians:
a ``cylindrical_x`` surface has power only in X, a ``cylindrical_y`` surface only in
Y, every other curved surface in both (aspheres by their vertex curvature).
Sources: W. J. Smith, *Modern Optical Engineering*, 4th ed., ch. 2-3 (y-nu trace,
cardinal points, Lagrange invariant); Kingslake & Johnson, *Lens Design
Fundamentals*, 2nd ed., ch. 3 and 7.1 (pupils); Zemax OpticStudio definitions of
EFL, BFL, paraxial working F/#.

Reference planes (docs/conventions.md): every position is first a signed ``z`` in
lens space, millimetres, +z toward the film, z = 0 at the first (front) vertex.
:meth:`GaussianData.relative_to` gives ``z - z_ref`` (positive = behind the
reference, toward the film) for ``front_vertex``, ``rear_vertex``, ``film`` and
``flange``; :meth:`GaussianData.in_front_of` gives ``z_ref - z`` (positive = in
front of the reference, toward the subject), the on-set convention.
"""

from __future__ import annotations

import math
from functools import lru_cache

from .._record import asdict, field, record
from ..errors import InputError, OpticsError, require_finite, require_positive
from ..lens.prescription import Prescription, takes_prescription
from ._memo import IdentityMemo, same_items

__all__ = [
    "AXES",
    "REFERENCES",
    "CARDINAL_POINTS",
    "media_indices",
    "surface_powers",
    "paraxial_trace",
    "system_matrix",
    "GaussianData",
    "gaussian",
    "gaussian_xy",
    "stop_semi_diameter_for_fstop",
    "field_angle",
]

AXES = ("x", "y")
REFERENCES = ("front_vertex", "rear_vertex", "film", "flange")
CARDINAL_POINTS = (
    "front_focal_point",
    "rear_focal_point",
    "front_principal_plane",
    "rear_principal_plane",
    "front_nodal_point",
    "rear_nodal_point",
    "entrance_pupil",
    "exit_pupil",
    "object",
    "film",
)

#: Tolerance beyond the file's stop when opening to an asked f-number (engraved
#: f-numbers are rounded: pbrt's "f/2" double Gauss is f/2.03 at its file stop).
STOP_OPENING_TOLERANCE = 0.05


def _wavelength(prescription: Prescription, wavelength_nm) -> float:
    if wavelength_nm is None:
        return float(prescription.wavelength_nm)
    from .glass import require_wavelength

    return float(require_wavelength(require_positive("wavelength_nm", wavelength_nm, unit="nm")))


def _axis(axis: str) -> str:
    if axis not in AXES:
        raise InputError(f"meridian must be 'x' or 'y', got {axis!r}")
    return axis


@takes_prescription
def media_indices(prescription: Prescription, wavelength_nm=None) -> list[float]:
    """Refractive index of object space followed by the medium after each surface.

    Object space is air (n = 1). Indices come from the medium's dispersion model
    (:func:`physcam.optics.glass.medium_index`: catalogue Sellmeier or normal line) at
    ``wavelength_nm`` (default: the prescription's design wavelength).
    """
    return list(_indices(prescription, _wavelength(prescription, wavelength_nm)))


def _indices(prescription: Prescription, lam: float) -> tuple[float, ...]:
    """:func:`media_indices` at wavelength ``lam`` (nm, checked), remembered by the surfaces' identity."""
    surfaces = prescription.surfaces
    key = (id(surfaces), lam)
    n = _BY_SURFACES.get(key, surfaces)
    return n if n is not None else _BY_SURFACES.put(key, surfaces, _by_media(tuple(s.medium for s in surfaces), lam))


#: The media's indices of the last surface tuples asked about, by the tuple's identity (the tuple kept,
#: so its id is not reused): a zoom's or a focus search's thousands of paraxial solves ask again and again
#: for the same lens, and keying :func:`_media_indices` by value rehashed every medium each time (2.6
#: million record hashes building one zoom lens's Blender tables; 10 % of its CPU).
_BY_SURFACES_MAX = 256
_BY_SURFACES = IdentityMemo(_BY_SURFACES_MAX)


def _by_media(media: tuple, lam: float) -> tuple[float, ...]:
    """:func:`_media_indices`, first looked up by the media objects' identities (kept with the answer): a new
    focus or zoom state's surfaces are new, their media the lens's own, and the memo's key by value hashed
    every medium again (a quarter of the paraxial work of a Blender extension build)."""
    key = (tuple(map(id, media)), lam)
    n = _BY_MEDIA.get(key, media)
    return n if n is not None else _BY_MEDIA.put(key, media, _media_indices(media, lam))


_BY_MEDIA = IdentityMemo(_BY_SURFACES_MAX, same_items)


@lru_cache(maxsize=1024)
def _media_indices(media: tuple, lam: float) -> tuple[float, ...]:
    # Memoised: one Gaussian computation asks for the same lens's indices nine times, and the
    # dispersion formulas were two thirds of its time (issue 14). Media are frozen, so the key is exact.
    from .glass import medium_index

    out = [1.0]
    for m in media:
        n = float(medium_index(m, lam))
        if not (math.isfinite(n) and n > 0):
            raise OpticsError(f"medium after a surface has no usable index at {lam:g} nm (got {n})")
        out.append(n)
    return tuple(out)


@takes_prescription
def surface_powers(prescription: Prescription, axis: str = "y", wavelength_nm=None) -> list[float]:
    """Paraxial power (1/mm) of each surface in the ``axis`` meridian: phi = c (n' - n)."""
    _axis(axis)
    return list(_powers(prescription, axis, _wavelength(prescription, wavelength_nm)))


def _powers(prescription: Prescription, axis: str, lam: float) -> tuple[float, ...]:
    """:func:`surface_powers` at wavelength ``lam`` (nm), remembered by the surfaces' identity like the
    indices (:data:`_BY_SURFACES`): a Blender extension build asks for the same state's powers tens of
    thousands of times (every system matrix, pupil and conjugate of every focus and zoom state)."""
    surfaces = prescription.surfaces
    key = (id(surfaces), axis, lam)
    phi = _POWERS.get(key, surfaces)
    if phi is None:
        n = _indices(prescription, lam)
        if axis == "x":
            phi = tuple(s.curvature_x * (n[i + 1] - n[i]) for i, s in enumerate(surfaces))
        else:
            phi = tuple(s.curvature_y * (n[i + 1] - n[i]) for i, s in enumerate(surfaces))
        _POWERS.put(key, surfaces, phi)
    return phi


#: The surfaces' powers by the surfaces tuple's identity, meridian and wavelength (:func:`_powers`).
_POWERS = IdentityMemo(_BY_SURFACES_MAX)


@takes_prescription
def paraxial_trace(prescription: Prescription, y0: float, nu0: float, axis: str = "y", wavelength_nm=None):
    """Trace one paraxial ray from the first vertex to the last.

    ``y0`` is the height (mm) at the first vertex plane, ``nu0`` the reduced angle
    n*u in object space (n = 1, air). Returns ``(y, nu)``: lists with the height at
    each vertex and the reduced angle after each surface (Smith, eqs. 2.31-2.32:
    n'u' = nu - y phi, y_next = y + t u').
    """
    _axis(axis)
    return _paraxial_trace(prescription, y0, nu0, axis, _wavelength(prescription, wavelength_nm))


def _paraxial_trace(prescription: Prescription, y0: float, nu0: float, axis: str, lam: float):
    """:func:`paraxial_trace` at wavelength ``lam`` (nm, checked)."""
    phi = _powers(prescription, axis, lam)
    n = _indices(prescription, lam)
    ys, nus = [], []
    y, nu = float(y0), float(nu0)
    last = len(prescription.surfaces) - 1
    for i, s in enumerate(prescription.surfaces):
        nu = nu - y * phi[i]
        ys.append(y)
        nus.append(nu)
        if i < last:
            y = y + s.thickness * nu / n[i + 1]
    return ys, nus


def _mul(a, b):
    return (
        a[0] * b[0] + a[1] * b[2],
        a[0] * b[1] + a[1] * b[3],
        a[2] * b[0] + a[3] * b[2],
        a[2] * b[1] + a[3] * b[3],
    )


@takes_prescription
def system_matrix(prescription: Prescription, axis: str = "y", wavelength_nm=None, first: int = 0, last: int | None = None):
    """ABCD matrix (A, B, C, D) on (y, n u) from just before surface ``first`` to just after ``last``.

    Defaults: the whole lens, first vertex to last vertex. Power is ``-C``.
    Gaps between the surfaces are included; the gap after ``last`` is not.
    """
    _axis(axis)
    return _system_matrix(prescription, axis, _wavelength(prescription, wavelength_nm), first, last)


def _system_matrix(prescription: Prescription, axis: str, lam: float, first: int = 0, last: int | None = None):
    """:func:`system_matrix` at wavelength ``lam``: each surface's refraction (1, 0, -phi, 1) and each gap's
    transfer (1, t / n', 0, 1) multiplied on the left, written out: the products of :func:`_mul`, term for
    term in its order (the same numbers), without a call and a tuple per step."""
    phi = _powers(prescription, axis, lam)
    n = _indices(prescription, lam)
    surfaces = prescription.surfaces
    if last is None:
        last = len(surfaces) - 1
    m0, m1, m2, m3 = 1.0, 0.0, 0.0, 1.0
    for i in range(first, last + 1):
        c = -phi[i]
        m0, m1, m2, m3 = 1.0 * m0 + 0.0 * m2, 1.0 * m1 + 0.0 * m3, c * m0 + 1.0 * m2, c * m1 + 1.0 * m3
        if i < last:
            b = surfaces[i].thickness / n[i + 1]
            m0, m1, m2, m3 = 1.0 * m0 + b * m2, 1.0 * m1 + b * m3, 0.0 * m0 + 1.0 * m2, 0.0 * m1 + 1.0 * m3
    return (m0, m1, m2, m3)


def _propagate(m, y, nu):
    return m[0] * y + m[1] * nu, m[2] * y + m[3] * nu


def _inverse(m):
    det = m[0] * m[3] - m[1] * m[2]  # = n_in / n_out ... 1 on (y, nu)
    return (m[3] / det, -m[1] / det, -m[2] / det, m[0] / det)


@record
class GaussianData:
    """First-order data of one lens configuration in one meridian.

    Lengths in mm. ``z_*`` are lens-space positions (z = 0 at the first vertex,
    +z toward the film). Focal lengths: ``efl`` = 1/power (in air the same as the
    rear focal length ``n'/power``); ``ffl`` is the distance from the first vertex
    forward to the front focal point F (positive when F is in front of the lens);
    ``bfl`` the distance from the last vertex back to the rear focal point F'
    (positive when F' is behind it). Pupils are the images of the stop through the
    groups in front of and behind it; diameters at the f-number ``f_number``
    (= efl / entrance pupil diameter, object at infinity). ``magnification`` and
    ``working_f_number`` are for the object at ``z_object`` imaged at ``z_image``
    (the paraxial image plane; -inf / F' for an object at infinity).
    """

    axis: str
    wavelength_nm: float
    efl: float
    front_focal_length: float  # f = -n/phi convention: reported as n/phi (positive for a converging lens)
    rear_focal_length: float  # f' = n'/phi
    ffl: float
    bfl: float
    z_front_vertex: float
    z_rear_vertex: float
    z_front_focal_point: float
    z_rear_focal_point: float
    z_front_principal_plane: float
    z_rear_principal_plane: float
    z_front_nodal_point: float
    z_rear_nodal_point: float
    z_stop: float
    stop_semi_diameter: float
    z_entrance_pupil: float
    entrance_pupil_diameter: float
    z_exit_pupil: float
    exit_pupil_diameter: float
    pupil_magnification: float
    f_number: float
    z_object: float
    z_image: float
    magnification: float
    working_f_number: float
    z_film: float
    flange_focal_distance: float | None = None
    object_index: float = 1.0
    image_index: float = 1.0
    thicknesses: tuple[float, ...] = field(default=(), repr=False)
    #: The best-match pinhole (mm): a pinhole at the entrance pupil with this focal length frames
    #: like the lens on the film at ``z_film``. The paraxial chief ray (through the stop centre)
    #: leaves object space at reduced angle n u through the entrance pupil and meets the film at
    #: height y; a pinhole at the pupil images the same ray at u f, so f_pin = |y / u|
    #: (Smith, *Modern Optical Engineering*, 4th ed., 3.5). Equivalently n (z_film - z_X) /
    #: (n' m_p) with m_p the signed pupil magnification (Lagrange invariant between the pupils).
    #: A thin lens focused on its film gives s'; infinity focus gives the EFL; dgauss.50mm focused
    #: 1.5 m from the film gives 52.048 mm. ``None`` when the film lies on the exit pupil.
    pinhole_focal_length: float | None = None

    # ---- reference planes -------------------------------------------------
    def reference_z(self, reference: str) -> float:
        """Lens-space z of ``front_vertex``, ``rear_vertex``, ``film`` or ``flange``."""
        if reference == "front_vertex":
            return self.z_front_vertex
        if reference == "rear_vertex":
            return self.z_rear_vertex
        if reference == "film":
            return self.z_film
        if reference == "flange":
            if self.flange_focal_distance is None:
                raise InputError("positions from the flange need the flange focal distance (e.g. 52 mm for PL)")
            return self.z_film - self.flange_focal_distance
        raise InputError(f"unknown reference plane {reference!r}; use one of {', '.join(REFERENCES)}")

    def z(self, point: str) -> float:
        """Lens-space z of a cardinal point named in :data:`CARDINAL_POINTS`."""
        if point not in CARDINAL_POINTS:
            raise InputError(f"unknown point {point!r}; use one of {', '.join(CARDINAL_POINTS)}")
        if point == "object":
            return self.z_object
        return getattr(self, f"z_{point}")

    def relative_to(self, point: str, reference: str = "front_vertex") -> float:
        """``z(point) - z(reference)``: positive when the point lies behind the reference (toward the film)."""
        return self.z(point) - self.reference_z(reference)

    def in_front_of(self, point: str, reference: str = "film") -> float:
        """``z(reference) - z(point)``: the on-set convention, positive toward the subject."""
        return self.reference_z(reference) - self.z(point)

    def positions(self, reference: str) -> dict[str, float]:
        """Every cardinal point relative to ``reference``.

        Vertex references: signed ``relative_to`` (+ toward the film); film and
        flange: ``in_front_of`` (+ toward the subject), as the on-set report uses.
        Infinite positions (object at infinity) are ``None``.
        """
        out = {}
        for p in CARDINAL_POINTS:
            v = self.relative_to(p, reference) if reference in ("front_vertex", "rear_vertex") else self.in_front_of(p, reference)
            out[p] = v if math.isfinite(v) else None
        return out

    def to_dict(self) -> dict:
        """Plain numbers for JSON (infinite values become ``None``)."""
        d = asdict(self)
        d["thicknesses"] = list(self.thicknesses)
        for k, v in list(d.items()):
            if isinstance(v, float) and not math.isfinite(v):
                d[k] = None
        d["positions"] = {
            ref: self.positions(ref)
            for ref in REFERENCES
            if ref != "flange" or self.flange_focal_distance is not None
        }
        d["conventions"] = (
            "lengths mm; z: lens space, 0 at the first vertex, + toward the film; positions from "
            "front_vertex/rear_vertex: + toward the film; from film/flange: distance in front, + toward the subject"
        )
        return d


def _check_lens(prescription: Prescription) -> None:
    if not prescription.surfaces:
        raise InputError("the lens has no surfaces")
    for i, s in enumerate(prescription.surfaces):
        for name, v in (("radius", s.radius), ("thickness", s.thickness), ("semi-diameter", s.semi_diameter)):
            if not math.isfinite(v):
                raise InputError(f"surface {i}: {name} is {v}; fix the lens file")


@takes_prescription
def stop_semi_diameter_for_fstop(prescription: Prescription, fstop: float, axis: str = "y", wavelength_nm=None) -> float:
    """Stop semi-diameter (mm) that makes ``prescription``, exactly as given, f/``fstop`` (EFL over entrance
    pupil diameter, object at infinity).

    For a lens that focuses, the iris is sized once, at infinity focus, and keeps that size at every
    focus: use :func:`physcam.optics.focusing.iris_semi_diameter`, the one rule every consumer
    follows, rather than this function on a focused state."""
    base = gaussian(prescription, axis=axis, wavelength_nm=wavelength_nm)
    fstop = require_positive("f-number", fstop, unit="")
    scale = base.f_number / fstop
    file_stop = prescription.surfaces[prescription.stop_index].semi_diameter
    if scale > 1.0 + STOP_OPENING_TOLERANCE:
        raise OpticsError(
            f"f/{fstop:g} is faster than this lens opens: its widest aperture is f/{base.f_number:.3g} "
            f"(stop as in the file); ask for f/{base.f_number:.3g} or slower"
        )
    return file_stop * scale


def _cardinal_points(prescription: Prescription, axis: str, lam: float, n_obj: float, n_img: float) -> dict:
    """Focal lengths, focal, principal and nodal points from the system matrix (Smith 3.3), as GaussianData fields."""
    z_last = prescription.vertex_z[-1]
    A, B, C, D = _system_matrix(prescription, axis, lam)
    phi = -C
    if abs(phi) < 1e-12:
        raise OpticsError(f"lens {prescription.name!r} is afocal in the {axis.upper()} meridian (no focal length)")
    efl = 1.0 / phi
    f_front = n_obj / phi
    f_rear = n_img / phi
    bfl = n_img * A / phi  # last vertex -> F'
    ffl = n_obj * D / phi  # F -> first vertex
    z_F = -ffl
    z_F2 = z_last + bfl
    return dict(
        efl=efl, front_focal_length=f_front, rear_focal_length=f_rear, ffl=ffl, bfl=bfl,
        z_front_focal_point=z_F, z_rear_focal_point=z_F2,
        z_front_principal_plane=z_F + f_front, z_rear_principal_plane=z_F2 - f_rear,
        # nodal points: N is f' behind F, N' is f in front of F'
        z_front_nodal_point=z_F + f_rear, z_rear_nodal_point=z_F2 - f_front,
    )


def _stop_semi(prescription: Prescription, axis: str, lam: float, fstop, stop_semi_diameter) -> float:
    """The stop's semi-diameter: as in the file, scaled to ``fstop`` at infinity, or given directly."""
    stop_semi = prescription.surfaces[prescription.stop_index].semi_diameter
    if fstop is not None and stop_semi_diameter is not None:
        raise InputError("give the f-stop or the stop's semi-diameter, not both")
    if fstop is not None:
        stop_semi = stop_semi_diameter_for_fstop(prescription, fstop, axis, lam)
    elif stop_semi_diameter is not None:
        stop_semi = require_positive("stop semi-diameter", stop_semi_diameter)
    return stop_semi


@record
class _Pupils:
    """The entrance and exit pupils (images of the stop) and the chief ray that defines them."""

    z_ep: float
    ep_semi: float
    z_xp: float
    xp_semi: float
    chief_nu_object: float  # reduced object-space angle of the chief ray leaving the stop centre at unit slope
    chief_y_last: float  # its height at the last vertex
    chief_nu_image: float  # its reduced image-space angle


def _pupils(prescription: Prescription, axis: str, lam: float, n: tuple, stop_semi: float) -> _Pupils:
    """Images of the stop through the front and back groups (paraxial chief and stop-edge rays)."""
    surfaces = prescription.surfaces
    n_obj, n_img = n[0], n[-1]
    z_last = prescription.vertex_z[-1]
    k = prescription.stop_index
    # front group: first vertex -> stop vertex (the stop has no power)
    front = _mul((1.0, surfaces[k - 1].thickness / n[k], 0.0, 1.0), _system_matrix(prescription, axis, lam, 0, k - 1)) if k > 0 else (1.0, 0.0, 0.0, 1.0)
    back = _system_matrix(prescription, axis, lam, k, len(surfaces) - 1)
    inv = _inverse(front)
    # chief ray: through the stop centre; in object space it crosses the axis at the EP
    y0, nu0 = _propagate(inv, 0.0, 1.0)
    if abs(nu0) < 1e-15:
        raise OpticsError("the entrance pupil is at infinity (object-space telecentric lens)")
    z_ep = -y0 * n_obj / nu0
    # a ray from the stop edge, parallel to the axis at the stop: its object-space
    # line passes through the image of the edge point, at the EP plane
    y1, nu1 = _propagate(inv, stop_semi, 0.0)
    ep_semi = abs(y1 + nu1 / n_obj * z_ep)
    y2, nu2 = _propagate(back, 0.0, 1.0)
    if abs(nu2) < 1e-15:
        raise OpticsError("the exit pupil is at infinity (image-space telecentric lens)")
    z_xp = z_last - y2 * n_img / nu2
    y3, nu3 = _propagate(back, stop_semi, 0.0)
    xp_semi = abs(y3 + nu3 / n_img * (z_xp - z_last))
    if ep_semi <= 0 or xp_semi <= 0:
        raise OpticsError("the pupils have no size (stop of zero semi-diameter)")
    return _Pupils(z_ep, ep_semi, z_xp, xp_semi, nu0, y2, nu2)


def _conjugate(prescription: Prescription, axis: str, lam: float, n: tuple, object_z: float, pupils: _Pupils,
               z_rear_focal_point: float) -> tuple[float, float, float]:
    """(image z, lateral magnification, image-space reduced angle of the marginal ray) of the object plane."""
    n_obj, n_img = n[0], n[-1]
    z_last = prescription.vertex_z[-1]
    z_ep, ep_semi = pupils.z_ep, pupils.ep_semi
    if math.isinf(object_z):
        z_img = z_rear_focal_point
        mag = 0.0
        # marginal ray from infinity at the EP edge
        ys, nus = _paraxial_trace(prescription, ep_semi, 0.0, axis, lam)
    else:
        if object_z >= 0:
            raise InputError(f"the object must lie in front of the first vertex (z < 0), got z = {object_z:g} mm")
        # ray from the axial object point to the EP edge
        u = ep_semi / (z_ep - object_z)
        y_first = u * (0.0 - object_z)
        ys, nus = _paraxial_trace(prescription, y_first, n_obj * u, axis, lam)
        if abs(nus[-1]) < 1e-15:
            raise OpticsError("the object is at the front focal point: its image is at infinity")
        z_img = z_last - ys[-1] * n_img / nus[-1]
        # lateral magnification = (n u) / (n' u') for the axial ray (Lagrange invariant)
        mag = (n_obj * u) / nus[-1]
    return z_img, mag, nus[-1]


def _pinhole_focal_length(pupils: _Pupils, n_obj: float, n_img: float, z_last: float, z_film: float):
    """The best-match pinhole: the chief ray (reduced object-space angle nu0) meets the film at y_film; None on axis."""
    y2, nu2, nu0 = pupils.chief_y_last, pupils.chief_nu_image, pupils.chief_nu_object
    y_film = y2 + nu2 / n_img * (z_film - z_last)
    return abs(y_film * n_obj / nu0) if abs(y_film) > 1e-12 * abs(z_film - z_last + 1.0) else None


@takes_prescription
def gaussian(
    prescription: Prescription,
    *,
    axis: str = "y",
    wavelength_nm=None,
    fstop=None,
    object_z: float = -math.inf,
    film_z: float | None = None,
    flange_focal_distance_mm: float | None = None,
    stop_semi_diameter: float | None = None,
) -> GaussianData:
    """Gaussian data of ``prescription`` in the ``axis`` meridian.

    ``object_z``: lens-space z of the object plane (negative: in front of the first
    vertex; ``-inf`` for infinity). ``film_z``: lens-space z of the film (sensor)
    plane; default the paraxial image of the object (F' at infinity).
    ``fstop``: evaluate the pupils at this f-number by scaling the stop
    semi-diameter (default: the stop as given in the file) so that this prescription, as given, is
    f/``fstop`` at infinity. ``stop_semi_diameter`` sets the stop's size directly instead (the iris of
    :func:`physcam.optics.focusing.iris_semi_diameter` for a focused state of a focusing lens).
    ``flange_focal_distance_mm``: the flange lies this far in front of the film.
    Raises :class:`OpticsError` for an afocal lens or an object at the front focal point.
    """
    key = _memo_key(prescription, (axis, wavelength_nm, fstop, object_z, film_z, flange_focal_distance_mm,
                                   stop_semi_diameter))
    g = _GAUSSIAN.get(key, prescription) if key is not None else None
    if g is None:
        g = _gaussian(prescription, axis, wavelength_nm, fstop, object_z, film_z, flange_focal_distance_mm,
                      stop_semi_diameter)
        if key is not None:
            _GAUSSIAN.put(key, prescription, g)
    return g


#: The last Gaussian solves by the prescription's identity (kept with the answer, so its id is not reused) and
#: the arguments: a lens model asks again and again for the same state's data (every mark's f-number ratio
#: solves the lens at infinity again, every report row both meridians at infinity; two thirds of the solves
#: building the Blender extension were repeats). Prescriptions and :class:`GaussianData` are frozen.
_GAUSSIAN_MAX = 512
_GAUSSIAN = IdentityMemo(_GAUSSIAN_MAX)


def _memo_key(prescription: Prescription, args: tuple):
    """``(id, arguments)`` for :data:`_GAUSSIAN`, each float by its type and exact bits (``-0.0`` is not
    ``0.0``), or None (no memo) when an argument is neither a number, a string nor None."""
    key = [id(prescription)]
    for v in args:
        if v is None or type(v) is str:
            key.append(v)
        elif isinstance(v, float):
            key.append((type(v), float.hex(v)))
        elif type(v) is int:
            key.append((int, v))
        else:
            return None
    return tuple(key)


def _gaussian(prescription: Prescription, axis, wavelength_nm, fstop, object_z, film_z, flange_focal_distance_mm,
              stop_semi_diameter) -> GaussianData:
    """:func:`gaussian`, solved."""
    _axis(axis)
    _check_lens(prescription)
    lam = _wavelength(prescription, wavelength_nm)
    object_z = float(object_z)
    if math.isnan(object_z) or object_z == math.inf:
        raise InputError(f"object plane must be in front of the lens (z < 0) or at -inf, got {object_z}")
    if flange_focal_distance_mm is not None:
        flange_focal_distance_mm = require_positive("flange focal distance", flange_focal_distance_mm)
    n = media_indices(prescription, lam)
    n_obj, n_img = n[0], n[-1]
    z_last = prescription.vertex_z[-1]

    cardinal = _cardinal_points(prescription, axis, lam, n_obj, n_img)
    efl, bfl = cardinal["efl"], cardinal["bfl"]
    stop_semi = _stop_semi(prescription, axis, lam, fstop, stop_semi_diameter)
    pupils = _pupils(prescription, axis, lam, n, stop_semi)
    z_img, mag, nu_img = _conjugate(prescription, axis, lam, n, object_z, pupils, cardinal["z_rear_focal_point"])
    if abs(nu_img) < 1e-15:
        raise OpticsError("the image is at infinity: no working f-number")
    working_n = 1.0 / (2.0 * abs(nu_img))
    z_film = z_img if film_z is None else require_finite("film plane z", film_z)
    pinhole = _pinhole_focal_length(pupils, n_obj, n_img, z_last, z_film)
    for name, v in (("EFL", efl), ("BFL", bfl), ("entrance pupil", pupils.z_ep), ("exit pupil", pupils.z_xp),
                    ("image", z_img)):
        if not math.isfinite(v):
            raise OpticsError(f"paraxial {name} position is not finite for lens {prescription.name!r}")
    return GaussianData(
        axis=axis,
        wavelength_nm=lam,
        **cardinal,
        z_front_vertex=0.0,
        z_rear_vertex=z_last,
        z_stop=prescription.vertex_z[prescription.stop_index],
        stop_semi_diameter=stop_semi,
        z_entrance_pupil=pupils.z_ep,
        entrance_pupil_diameter=2.0 * pupils.ep_semi,
        z_exit_pupil=pupils.z_xp,
        exit_pupil_diameter=2.0 * pupils.xp_semi,
        pupil_magnification=pupils.xp_semi / pupils.ep_semi,
        f_number=abs(efl) / (2.0 * pupils.ep_semi),
        z_object=object_z,
        z_image=z_img,
        magnification=mag,
        working_f_number=working_n,
        z_film=z_film,
        flange_focal_distance=flange_focal_distance_mm,
        object_index=n_obj,
        image_index=n_img,
        thicknesses=tuple(s.thickness for s in prescription.surfaces),
        pinhole_focal_length=pinhole,
    )


@takes_prescription
def gaussian_xy(prescription: Prescription, **kwargs) -> dict[str, GaussianData]:
    """Gaussian data in both meridians: ``{"x": ..., "y": ...}`` (they differ for anamorphic lenses)."""
    return {a: gaussian(prescription, axis=a, **kwargs) for a in AXES}


@takes_prescription
def field_angle(prescription: Prescription, image_height: float, film_z: float, axis: str = "y", wavelength_nm=None) -> float:
    """Object-space field angle (radians) of the paraxial chief ray reaching ``image_height`` (mm) on the film.

    The chief ray passes through the centre of the stop; ``film_z`` is the
    lens-space z of the film plane. Paraxially tan(angle) = the chief ray's
    object-space slope (Smith 3.5), so an infinitely distant object gives
    ``atan(h / efl)``. Used for the field of view and focus breathing.
    """
    _axis(axis)
    lam = _wavelength(prescription, wavelength_nm)
    n = media_indices(prescription, lam)
    surfaces = prescription.surfaces
    k = prescription.stop_index
    back = system_matrix(prescription, axis, lam, k, len(surfaces) - 1)
    y_last, nu_last = _propagate(back, 0.0, 1.0)
    y_film = y_last + nu_last / n[-1] * (float(film_z) - prescription.vertex_z[-1])
    if abs(y_film) < 1e-15:
        raise OpticsError("the chief ray meets the axis at the film plane (film at the exit pupil)")
    front = _mul((1.0, surfaces[k - 1].thickness / n[k], 0.0, 1.0), system_matrix(prescription, axis, lam, 0, k - 1)) if k > 0 else (1.0, 0.0, 0.0, 1.0)
    _, nu0 = _propagate(_inverse(front), 0.0, 1.0)
    return math.atan(float(image_height) * (nu0 / n[0]) / y_film)
