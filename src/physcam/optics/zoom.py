"""A zoom lens across its range: the zoom position from a focal length, and what changes along the
zoom (docs/zoom.md).

A zoom position is the normalised zoom coordinate u of :mod:`physcam.lens.zoom` (0 the first
tabulated position, 1 the last) or a focal length, solved for u on the paraxial EFL (d line unless
asked, Y meridian, infinity focus) by regula falsi (Illinois) inside the bracket where EFL(u) crosses it; a focal
length outside the lens's paraxial range is refused, naming the range. The EFL must run
monotonically across the zoom for a focal length to name one position (checked on 33 samples).

Per position (:func:`zoom_table`), at infinity focus with the stop full open (its tabulated size
where the source gives one, else the size in the file at every position: the iris rule across the
zoom): the EFL, f-number (EFL over entrance-pupil diameter, ISO 517), the entrance pupil (its
diameter, and where it lies from the front vertex and from the film), the paraxial back focal
length, and the **image-plane shift**: the paraxial image of infinity minus the film plane, which
the lens file puts at its last gap (tabulated where the back focus moves). A parfocal zoom keeps it
near zero at every position; between tabulated positions it shows how far the interpolated cams
drift from the designer's (``+``: the image lies behind the film). Breathing over zoom x focus
(:func:`zoom_breathing`) is :func:`physcam.optics.focusing.breathing_table` at each position.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from ..data.default_sensor import DEFAULT_SENSOR_WIDTH_MM
from ..errors import InputError, OpticsError, require_positive
from ..lens.prescription import Prescription, takes_prescription
from ..lens.zoom import prescription_at, tabulated_encoders
from . import focusing, paraxial
from ._memo import IdentityMemo
from ._roots import bracketed_root

__all__ = ["ZoomRow", "encoder_for_focal_length", "at_zoom", "named_at_zoom", "zoom_encoder", "efl_at", "zoom_table",
           "zoom_breathing", "default_encoders"]

#: Samples of EFL(u) that check monotonicity and bracket a requested focal length.
_SAMPLES = 33


@dataclass(frozen=True)
class ZoomRow:
    """One zoom position at infinity focus, stop full open (lengths mm, angle degrees; module notes)."""

    encoder: float
    tabulated: bool  # a position the source tabulates (else on the interpolated cams)
    stated_focal_length_mm: float | None  # the source's label, where it tabulates one
    efl_mm: float
    f_number: float
    stop_semi_diameter_mm: float
    entrance_pupil_diameter_mm: float
    entrance_pupil_from_front_vertex_mm: float  # + toward the film
    entrance_pupil_from_film_mm: float  # in front of the film, + toward the subject
    bfl_mm: float  # last vertex to the paraxial image of infinity
    film_distance_mm: float  # last vertex to the film plane (the lens file's last gap here)
    image_shift_mm: float  # bfl - film distance: + behind the film
    front_vertex_to_film_mm: float
    hfov_deg: float  # horizontal field of view on the sensor width, X meridian

    def to_dict(self) -> dict:
        return asdict(self)


@takes_prescription
def efl_at(lens: Prescription, encoder: float, wavelength_nm=None) -> float:
    """Paraxial EFL (Y meridian) of a zoom lens at the normalised zoom coordinate ``encoder``, remembered by the
    lens's identity (the lens kept with it; prescriptions are frozen), the encoder and the wavelength: a focal
    length's search asks the zoom's samples again for every position, a take its ends for every frame."""
    key = (id(lens), encoder, wavelength_nm) if isinstance(encoder, (int, float)) else None
    efl = None if key is None else _EFLS.get(key, lens)
    if efl is None:
        efl = paraxial.gaussian(prescription_at(lens, encoder), wavelength_nm=wavelength_nm).efl
        if key is not None:
            _EFLS.put(key, lens, efl)
    return efl


#: :func:`efl_at`'s answers (64 lenses' :data:`_SAMPLES` samples and the searches' positions between them)
_EFLS = IdentityMemo(4096)


def _samples(lens, wavelength_nm):
    """(encoders, EFLs) at :data:`_SAMPLES` points across the zoom."""
    us = [k / (_SAMPLES - 1) for k in range(_SAMPLES)]
    return us, [efl_at(lens, u, wavelength_nm) for u in us]


#: a focal length this close outside a zoom's paraxial range names its end (the range is printed to 0.01 mm)
ZOOM_END_TOLERANCE_MM = 0.005


@takes_prescription
def encoder_for_focal_length(lens: Prescription, focal_length_mm: float, *, wavelength_nm=None) -> float:
    """The normalised zoom coordinate where the zoom lens's paraxial EFL is ``focal_length_mm``
    (module notes); :class:`InputError` outside the range, :class:`OpticsError` for a non-monotone EFL."""
    f = require_positive("focal length", focal_length_mm)
    us, efls = _samples(lens, wavelength_nm)
    steps = [b - a for a, b in zip(efls, efls[1:])]
    if not (all(s > 0 for s in steps) or all(s < 0 for s in steps)):
        raise OpticsError(f"the EFL of {lens.name!r} does not run monotonically across its zoom: a focal length "
                          "names no single position; give the zoom as an encoder value 0..1")
    lo, hi = min(efls), max(efls)
    # an end as the range is printed (0.01 mm) is that end: 196 mm on a zoom whose long end is 195.9996
    if not lo - ZOOM_END_TOLERANCE_MM <= f <= hi + ZOOM_END_TOLERANCE_MM:
        stated = lens.zoom.stated_focal_length
        said = f"; the source labels it {stated[0]:g}-{stated[-1]:g} mm" if stated else ""
        raise InputError(f"{f:g} mm is outside the zoom range of {lens.name!r}: {lo:.2f} to {hi:.2f} mm (paraxial "
                         f"EFL){said}")
    f = min(max(f, lo), hi)
    k = next(i for i in range(len(us) - 1) if (efls[i] - f) * (efls[i + 1] - f) <= 0)
    a, b, fa, fb = us[k], us[k + 1], efls[k] - f, efls[k + 1] - f
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    sign = 1.0 if fa < 0 else -1.0  # EFL is monotone inside the bracket: the residual rising from a to b
    return bracketed_root(lambda u: sign * (efl_at(lens, u, wavelength_nm) - f), a, sign * fa, b,
                          sign * fb, 1e-13)


def zoom_encoder(lens: Prescription, zoom, *, wavelength_nm=None) -> float:
    """The encoder value of a zoom position given as an encoder value (a number 0..1), a focal length
    in text (``"135mm"``), or the text of an encoder value (``"0.5"``)."""
    if isinstance(zoom, str):
        text = zoom.strip().lower()
        if text.endswith("mm"):
            try:
                f = float(text[:-2])
            except ValueError:
                raise InputError(f"zoom {zoom!r}: give a focal length such as 135mm or an encoder value 0..1") from None
            return encoder_for_focal_length(lens, f, wavelength_nm=wavelength_nm)
        try:
            zoom = float(text)
        except ValueError:
            raise InputError(f"zoom {zoom!r}: give a focal length such as 135mm or an encoder value 0..1") from None
    if isinstance(zoom, bool) or not isinstance(zoom, (int, float)) or not 0.0 <= zoom <= 1.0:
        raise InputError(f"zoom {zoom!r}: an encoder value lies from 0 to 1; give a focal length with its unit (135mm)")
    return float(zoom)


@takes_prescription
def at_zoom(lens: Prescription, zoom, *, wavelength_nm=None) -> Prescription:
    """The plain prescription of a zoom lens at ``zoom`` (:func:`zoom_encoder`'s forms)."""
    return prescription_at(lens, zoom_encoder(lens, zoom, wavelength_nm=wavelength_nm))


@takes_prescription
def named_at_zoom(lens: Prescription, zoom, *, wavelength_nm=None) -> tuple[Prescription, dict]:
    """(the prescription of a zoom ``lens`` at ``zoom``, its ``zoom`` block): the prescription named with its
    position (``"<name> at 135.0 mm (zoom 0.5)"``, the paraxial EFL and the encoder value, as tables, cards and
    ST-map headers carry it), and the block the commands' JSON documents hold: ``{"asked": the position as
    given, "encoder": 0..1, "efl_mm": the paraxial EFL there}``. ``zoom``: :func:`zoom_encoder`'s forms; a focal
    length outside the zoom range (the error names the range) and a prime lens are InputErrors."""
    from .._record import replace

    u = zoom_encoder(lens, zoom, wavelength_nm=wavelength_nm)
    q = prescription_at(lens, u)
    block = {"asked": str(zoom), "encoder": u, "efl_mm": paraxial.gaussian(q).efl}
    name = f"{lens.name} at {block['efl_mm']:.1f} mm (zoom {u:.4g})"
    return replace(q, metadata=replace(q.metadata, name=name)), block


@takes_prescription
def default_encoders(lens: Prescription) -> list[float]:
    """The tabulated positions and the midpoints between them (where interpolated cams stray most)."""
    enc = tabulated_encoders(lens)
    return sorted(set(enc) | {0.5 * (a + b) for a, b in zip(enc, enc[1:])})


@takes_prescription
def zoom_table(lens: Prescription, encoders=None, *, sensor_width_mm: float = DEFAULT_SENSOR_WIDTH_MM,
               wavelength_nm=None) -> list[ZoomRow]:
    """One :class:`ZoomRow` per encoder value (default :func:`default_encoders`; module notes)."""
    w = require_positive("sensor width", sensor_width_mm)
    z = lens.zoom
    us = default_encoders(lens) if encoders is None else [zoom_encoder(lens, u) for u in encoders]
    rows = []
    for u in us:
        q = prescription_at(lens, u)
        film = q.surfaces[-1].thickness
        z_film = q.vertex_z[-1] + film
        g = paraxial.gaussian(q, wavelength_nm=wavelength_nm, film_z=z_film)
        st = focusing.focus(q, math.inf, wavelength_nm=wavelength_nm)
        half = abs(paraxial.field_angle(st.prescription, w / 2.0, st.film_z, "x", wavelength_nm))
        k = z.encoder.index(u) if u in z.encoder else None
        rows.append(ZoomRow(
            encoder=u, tabulated=k is not None,
            stated_focal_length_mm=None if (k is None or z.stated_focal_length is None) else z.stated_focal_length[k],
            efl_mm=g.efl, f_number=g.f_number, stop_semi_diameter_mm=g.stop_semi_diameter,
            entrance_pupil_diameter_mm=g.entrance_pupil_diameter,
            entrance_pupil_from_front_vertex_mm=g.relative_to("entrance_pupil", "front_vertex"),
            entrance_pupil_from_film_mm=g.in_front_of("entrance_pupil", "film"),
            bfl_mm=g.bfl, film_distance_mm=film, image_shift_mm=g.bfl - film,
            front_vertex_to_film_mm=z_film, hfov_deg=math.degrees(2.0 * half)))
    for r in rows:
        if not all(math.isfinite(v) for v in (r.efl_mm, r.f_number, r.bfl_mm, r.entrance_pupil_from_film_mm)):
            raise OpticsError(f"lens {lens.name!r}: paraxial data at zoom {r.encoder:g} are not finite")
    return rows


@takes_prescription
def zoom_breathing(lens: Prescription, encoders=None, focus_marks_mm=None, *,
                   sensor_width_mm: float = DEFAULT_SENSOR_WIDTH_MM, wavelength_nm=None) -> list[tuple[float, list]]:
    """Breathing over zoom x focus: ``[(encoder, breathing rows)]``, the rows of
    :func:`physcam.optics.focusing.breathing_table` at each zoom position (default: the tabulated ones;
    focus marks default to that table's, down to each position's closest focus)."""
    us = list(tabulated_encoders(lens)) if encoders is None else [zoom_encoder(lens, u) for u in encoders]
    if not us:
        raise InputError("give at least one zoom position")
    out = []
    for u in us:
        q = prescription_at(lens, u)
        marks = _default_marks(q, wavelength_nm) if focus_marks_mm is None else focus_marks_mm
        out.append((u, focusing.breathing_table(q, marks, sensor_width_mm=sensor_width_mm, wavelength_nm=wavelength_nm)))
    return out


def _default_marks(q: Prescription, wavelength_nm) -> list[float]:
    """The breathing table's default marks down to the closest focus, leaving out marks whose subject would
    sit inside or at the lens (a long zoom's glass can be longer than a short lens's 1:1 distance)."""
    near = focusing.closest_focus(q, wavelength_nm=wavelength_nm)
    length = q.total_track + q.surfaces[-1].thickness
    marks = [m for m in focusing.DEFAULT_BREATHING_MARKS if m > near and m > 1.5 * length]
    return marks + ([near] if q.focus is not None and near > 1.5 * length else [])
