"""Cinema sensors and film gates, by name or alias.

The table ``physcam/data/sensors.csv`` holds active-area (or camera-aperture)
width and height in mm with their sources; the values were checked against the
shared reference table ``sensor_formats.csv`` (see tests/onset/test_sensors_pupil.py,
which also checks each diagonal). Digital sensors of one camera also carry the photosite
pitch (``pitch_um``, micrometres): the width over the photosites across it
(``photosites_across``), each count with its source (``pitch_source``; abbreviations in
``physcam/data/SENSORS.md``). Film gates and the generic full-frame format have none. Lookup ignores case, spaces and punctuation;
an unknown name raises :class:`~physcam.errors.SensorError` listing the closest names.

The camera table ``physcam/data/cameras.csv`` adds every recording format of current cine and hybrid
cameras (camera -> formats): each row a :class:`Sensor` named "maker camera format" (also found
without the maker: "FX6 FF 4K 17:9", or by another name of the camera, ``camera_aliases.csv``: "KOMODO 4K 17:9",
"BMPCC 6K 4K DCI"), with its source, the date it was read and how the size was had
(stated by the maker, or photosites x the maker's pitch), and whose figure it is (``maker_spec``). A camera's name alone ("FX6") is refused
with its formats listed: DOF and field of view depend on the crop. The few camera names the sensor table
has long given to a camera's full sensor ("ALEXA 35", "ALEXA Mini", "Mini LF", "VENICE 2", "V-RAPTOR")
keep that meaning, and :func:`camera_name_note` says which format that is and how to choose another.
"""

from __future__ import annotations

import csv
import math
import re
from functools import lru_cache
from pathlib import Path

from .._record import record
from ..errors import SensorError

__all__ = ["Sensor", "sensors", "cameras", "camera_formats", "find_sensor", "camera_name_note", "camera_aliases", "filter_sensors", "custom_sensor", "SENSOR_SIZE_RANGE_MM",
           "SENSOR_MAX_ASPECT", "PITCH_RANGE_UM", "MAKERS"]

#: Camera makers in the table (a digital sensor's name starts with its maker); film gates are "film".
MAKERS = ("ARRI", "RED", "Sony", "Canon", "Blackmagic", "Panasonic", "Fujifilm", "DJI")


@record(slots=True)
class Sensor:
    """A sensor or film gate: active area ``width_mm`` x ``height_mm``; ``pitch_um`` the photosite
    pitch (micrometres) where one camera's sensor is meant, else None."""

    key: str
    name: str
    width_mm: float
    height_mm: float
    aliases: tuple[str, ...] = ()
    kind: str = "digital"
    source: str = ""
    pitch_um: float | None = None
    pitch_source: str = ""
    camera: str = ""  # the camera table's rows: the camera and its recording format
    fmt: str = ""
    make: str = ""
    anamorphic: tuple[float, ...] = ()  # desqueeze factors the maker offers this format for
    read: str = ""  # the date the source was read
    method: str = ""  # how the size was had: "stated mm", "photosites x pitch", "derived: ..."
    maker_spec: str = ""  # whose figure the size is: the maker's (its page read, quoted, or its document via a transcription) or a third party's

    @property
    def diagonal_mm(self) -> float:
        return math.hypot(self.width_mm, self.height_mm)

    @property
    def aspect(self) -> float:
        return self.width_mm / self.height_mm

    @property
    def maker(self) -> str:
        """The camera maker (ARRI, RED, Sony), "film" for a film gate, "" when neither."""
        if self.kind == "film":
            return "film"
        if self.make:
            return self.make
        first = self.name.split()[0] if self.name else ""
        return first if first in MAKERS else ""

    def to_dict(self) -> dict:
        return {"key": self.key, "name": self.name, "maker": self.maker, "kind": self.kind,
                "width_mm": self.width_mm, "height_mm": self.height_mm, "diagonal_mm": self.diagonal_mm,
                "aspect": self.aspect, "photosite_pitch_um": self.pitch_um, "aliases": list(self.aliases),
                "source": self.source, "camera": self.camera or None, "format": self.fmt or None,
                "anamorphic": list(self.anamorphic), "read": self.read or None, "method": self.method or None,
                "maker_spec": self.maker_spec or None}


#: A custom sensor's width and height (mm): from a phone's sensor to beyond 15/70 IMAX film.
SENSOR_SIZE_RANGE_MM = (0.5, 1000.0)
#: The widest aspect ratio (either way) of a custom sensor: panoramic film is about 3:1, line
#: sensors aside; a 36 x 0.001 mm "sensor" is a typo that would size a 24 GB image (issue 8).
SENSOR_MAX_ASPECT = 20.0


#: Photosite pitches a custom sensor may have (micrometres): phone sensors to large-pixel cameras.
PITCH_RANGE_UM = (0.5, 50.0)


def custom_sensor(width_mm, height_mm, pitch_um=None) -> Sensor:
    """A sensor measured by hand, ``width_mm`` x ``height_mm`` (and optionally its photosite
    ``pitch_um``), checked against :data:`SENSOR_SIZE_RANGE_MM`, :data:`SENSOR_MAX_ASPECT` and
    :data:`PITCH_RANGE_UM` (else :class:`SensorError`)."""
    from ..errors import require_finite

    w = require_finite("sensor width", width_mm, error=SensorError)
    h = require_finite("sensor height", height_mm, error=SensorError)
    lo, hi = SENSOR_SIZE_RANGE_MM
    if not (lo <= w <= hi and lo <= h <= hi):
        raise SensorError(f"sensor width and height must lie between {lo:g} and {hi:g} mm, got {w:g} x {h:g} mm")
    if max(w / h, h / w) > SENSOR_MAX_ASPECT:
        raise SensorError(f"a {w:g} x {h:g} mm sensor is {max(w / h, h / w):.0f}:1; physcam accepts up to "
                          f"{SENSOR_MAX_ASPECT:g}:1 (check the units)")
    p = None
    if pitch_um is not None:
        p = require_finite("photosite pitch", pitch_um, error=SensorError)
        if not PITCH_RANGE_UM[0] <= p <= PITCH_RANGE_UM[1]:
            raise SensorError(f"photosite pitch must lie between {PITCH_RANGE_UM[0]:g} and {PITCH_RANGE_UM[1]:g} µm, "
                              f"got {p:g}")
    return Sensor("custom", f"custom {w:g} x {h:g} mm", w, h, pitch_um=p, pitch_source="given" if p else "")


def _norm(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "", text.lower())


def _data(name: str) -> str:
    return (Path(__file__).resolve().parent.parent / "data" / name).read_text(encoding="utf-8")


def _joined(camera: str, fmt: str) -> str:
    """"camera format", the format's first word dropped when the camera's name ends with it: the KOMODO 6K's
    "6K 17:9" is "KOMODO 6K 17:9", not "KOMODO 6K 6K 17:9"."""
    head, _, rest = fmt.partition(" ")
    return f"{camera} {rest}" if rest and camera.split()[-1].lower() == head.lower() else f"{camera} {fmt}"


@lru_cache(maxsize=1)
def camera_aliases() -> dict[str, tuple[str, ...]]:
    """Other names of a camera ("maker camera" -> its names: "KOMODO", "BMPCC 6K"), from camera_aliases.csv:
    names people use, not specifications, so they cite nothing."""
    return {f"{r['maker']} {r['camera']}": tuple(a.strip() for a in r["aliases"].split(";") if a.strip())
            for r in csv.DictReader(_data("camera_aliases.csv").splitlines())}


def _squeezes(text: str) -> tuple[float, ...]:
    """An ``anamorphic`` cell of sensors.csv or cameras.csv: the desqueezes offered, ";"-separated ("" none)."""
    return tuple(float(x) for x in text.split(";") if x.strip())


def _camera_formats() -> list[Sensor]:
    """The camera table's rows (cameras.csv) as sensors: "maker camera format", also "camera format" and
    "other-name format" (:func:`camera_aliases`), the doubled word of "KOMODO 6K 6K 17:9" once."""
    out = []
    for row in csv.DictReader(_data("cameras.csv").splitlines()):
        w, across = float(row["width_mm"]), row["photosites_across"]
        short, doubled = _joined(row["camera"], row["format"]), f"{row['camera']} {row['format']}"
        others = [_joined(a, row["format"]) for a in camera_aliases().get(f"{row['maker']} {row['camera']}", ())]
        names = dict.fromkeys((short, doubled, f"{row['maker']} {doubled}", *others,
                               *(a.strip() for a in row["aliases"].split(";") if a.strip())))
        out.append(Sensor(
            key=row["key"], name=f"{row['maker']} {short}", width_mm=w, height_mm=float(row["height_mm"]),
            aliases=tuple(n for n in names if n != f"{row['maker']} {short}"), kind="digital",
            source=row["source"], pitch_um=round(w * 1000.0 / int(across), 3) if across else None,
            pitch_source=f"width / photosites: {across} photosites across (the row's source)" if across else "",
            camera=row["camera"], fmt=row["format"],
            make=row["maker"], anamorphic=_squeezes(row["anamorphic"]),
            read=row["read"], method=row["method"], maker_spec=row["maker_spec"]))
    return out


@lru_cache(maxsize=1)
def _gates() -> tuple[Sensor, ...]:
    """The sensors and film gates of sensors.csv, in table order (the first rows of :func:`sensors`); a film
    gate made for anamorphic lenses gives their desqueeze (``anamorphic``, as the camera table's formats)."""
    out = []
    for row in csv.DictReader(_data("sensors.csv").splitlines()):
        out.append(
            Sensor(
                key=row["key"],
                name=row["name"],
                width_mm=float(row["width_mm"]),
                height_mm=float(row["height_mm"]),
                aliases=tuple(a.strip() for a in row["aliases"].split(";") if a.strip()),
                kind=row["kind"],
                source=row["source"],
                pitch_um=float(row["pitch_um"]) if row.get("pitch_um") else None,
                pitch_source=row.get("pitch_source", ""),
                anamorphic=_squeezes(row.get("anamorphic", "")),
            )
        )
    return tuple(out)


@lru_cache(maxsize=1)
def sensors() -> tuple[Sensor, ...]:
    """Every known sensor, in table order: the sensors and film gates, then the camera table's formats."""
    return _gates() + tuple(_camera_formats())


@lru_cache(maxsize=1)
def cameras() -> dict[str, tuple[Sensor, ...]]:
    """The camera table by camera ("Sony FX6" -> its formats, in table order)."""
    out: dict[str, list[Sensor]] = {}
    for s in sensors():
        if s.camera:
            out.setdefault(f"{s.make} {s.camera}", []).append(s)
    return {k: tuple(v) for k, v in out.items()}


def camera_formats(name: str) -> tuple[Sensor, ...]:
    """The formats of the camera called ``name`` ("Sony FX6", "FX6", "venice 2 8k"; case and punctuation
    ignored), or () when no camera has that name."""
    if not isinstance(name, str):
        raise SensorError(f"a camera name must be text, got {type(name).__name__}")
    key = _norm(name)
    for full, rows in cameras().items():
        if key and key in (_norm(full), _norm(rows[0].camera), *(_norm(a) for a in camera_aliases().get(full, ()))):
            return rows
    return ()


def _full_sensor_camera(name: str):
    """(camera, its format) when ``name`` is a bare camera name the sensor table gives the camera's full
    sensor ("ALEXA 35": the 4.6K 3:2 Open Gate), else None. The camera is the table's one whose name holds
    ``name`` and which records a format of the gate's size; the exact name, then the one the gate's name
    names ("VENICE 2": the 8K, not the 6K), then the shortest wins ("ALEXA Mini", not "ALEXA Mini LF")."""
    key = _norm(name)
    gate = _gate_index().get(key)
    if gate is None or name.strip() == gate.key:  # a key is a row's name, not a camera's
        return None
    found = []
    for full, rows in cameras().items():
        short = _norm(rows[0].camera)
        same = [r for r in rows if abs(r.width_mm - gate.width_mm) <= 0.011 and abs(r.height_mm - gate.height_mm) <= 0.011]
        if len(rows) > 1 and same and key in _norm(full):
            found.append(((key not in (short, _norm(full)), _norm(full) not in _norm(gate.name), len(full)), full, same[0]))
    return min(found)[1:] if found else None


def camera_name_note(name: str) -> str:
    """What a bare camera name given as a sensor ("ALEXA 35", "Mini LF") was taken as: the camera's full
    sensor, which format of the camera table that is and how to name another; "" for any other name."""
    hit = _full_sensor_camera(name) if isinstance(name, str) else None
    if hit is None:
        return ""
    full, fmt = hit
    n = len(cameras()[full])
    return (f"{name!r} is the {full}'s full sensor, its {fmt.fmt} ({fmt.width_mm:g} x {fmt.height_mm:g} mm); the "
            f"camera records in {n} formats and the crop sets the depth of field and the field of view: name "
            f"another as the sensor, e.g. {cameras()[full][1].aliases[0]!r} (`physcam sensors \"{full}\"` lists them)")


def _labelled(rows) -> dict[str, Sensor]:
    idx: dict[str, Sensor] = {}
    for s in rows:
        for label in (s.key, s.name, *s.aliases):
            idx.setdefault(_norm(label), s)
    return idx


@lru_cache(maxsize=1)
def _index() -> dict[str, Sensor]:
    """Every sensor by its key, name and aliases, normalised; the first row in table order wins."""
    return _labelled(sensors())


@lru_cache(maxsize=1)
def _gate_index() -> dict[str, Sensor]:
    """:func:`_index` of sensors.csv's rows alone: they come first in table order, so a name found here
    is the one :func:`_index` gives, without reading the camera table (issue 43: a report's start-up)."""
    return _labelled(_gates())


#: Names of camera families rather than of one sensor: refused with the family's members, so a
#: bare "ALEXA" never quietly becomes the 2010 camera's 16:9 gate (issue 8).
FAMILY_NAMES = {"alexa": "ALEXA", "arri": "ALEXA", "arriflex": "ALEXA"}


def filter_sensors(query: str = "", *, maker: str | None = None, fmt: str | None = None,
                   min_width_mm: float | None = None, max_width_mm: float | None = None) -> list[Sensor]:
    """Sensors matching every word of ``query`` (in the name, key, aliases or maker; case and
    punctuation ignored), the ``maker`` (ARRI, RED, Sony, Canon, Blackmagic, Panasonic or film), the
    ``fmt`` text in the name ("open gate", "16:9", "4-perf") and a width between ``min_width_mm`` and
    ``max_width_mm``.

    >>> [s.key for s in filter_sensors("FX6", fmt="17:9")]
    ['sony-fx6-ff-4k-17-9']
    """
    for name, v in (("query", query), ("maker", maker), ("format", fmt)):
        if v is not None and not isinstance(v, str):
            raise SensorError(f"a sensor {name} is text, got {type(v).__name__}")
    typed = [(w, _norm(w)) for w in (query or "").split()]
    words = [n for _, n in typed if n]
    if typed and (not words or any(not n and any(c.isalnum() for c in w) for w, n in typed)):
        return []  # only marks ("!!!"), or a word of letters no sensor is named in ("é"): nothing matches
    out = []
    for s in sensors():
        text = " ".join(_norm(t) for t in (s.key, s.name, s.maker, s.kind, *s.aliases))
        if not all(w in text for w in words):
            continue
        if maker is not None and _norm(maker) != _norm(s.maker):
            continue
        if fmt is not None and _norm(fmt) not in _norm(s.name) + " " + " ".join(_norm(a) for a in s.aliases):
            continue
        if min_width_mm is not None and s.width_mm < min_width_mm:
            continue
        if max_width_mm is not None and s.width_mm > max_width_mm:
            continue
        out.append(s)
    return out


def find_sensor(name: str) -> Sensor:
    """The sensor called ``name`` (key, full name or alias; case and punctuation ignored).

    A camera family name ("ALEXA") is refused with the sensors of that family.

    >>> find_sensor("alexa 35").width_mm
    27.99
    """
    if not isinstance(name, str):
        raise SensorError(f"a sensor name must be text, got {type(name).__name__}")
    key = _norm(name)
    if not key:
        if name.strip():  # "é", "!!!": letters and marks no sensor's name is told by (a-z, 0-9)
            raise SensorError(f"unknown sensor {name!r}: sensors are named in letters a-z and digits. "
                              "`physcam sensors` lists them all")
        raise SensorError("the sensor name is empty. `physcam sensors` lists them all")
    if key in FAMILY_NAMES:
        fam = _norm(FAMILY_NAMES[key])
        members = [s.name for s in sensors() if fam in _norm(s.name)]
        raise SensorError(f"{name!r} names a camera family, not one sensor: give one of "
                          + "; ".join(repr(m) for m in members))
    for index in (_gate_index, _index):  # the camera table is read only for a name not among the gates
        idx = index()
        if key in idx:
            return idx[key]
    formats = camera_formats(name)
    if formats:
        cam = f"{formats[0].make} {formats[0].camera}"
        other = [a for a in camera_aliases().get(cam, ()) if _norm(a) == key]  # as the user called it: "KOMODO 4K 17:9"
        shown = [_joined(other[0], s.fmt) if other else s.aliases[0] for s in formats]
        raise SensorError(f"{cam} records in {len(formats)} formats and the crop sets the depth of field and the "
                          f"field of view: which one? " + "; ".join(repr(n) for n in shown)
                          + f' (`physcam sensors "{formats[0].camera}"` lists them with their sizes)')
    labels = {}
    for s in sensors():
        for label in (s.name, *s.aliases):
            labels.setdefault(_norm(label), label)
    import difflib

    close = difflib.get_close_matches(key, list(labels), n=4, cutoff=0.4)
    hint = "; closest: " + ", ".join(repr(labels[c]) for c in close) if close else ""
    raise SensorError(f"unknown sensor {name!r}{hint}. `physcam sensors` lists them all")
