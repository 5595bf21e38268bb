"""Cooke /i lens data: the packed binary ``Kd`` response, decoded from its bytes.

Layout (Cooke /i Technology, User's Guide & Technical Manual v3.0, "Command Kd"): one tag byte
``d``, then fields packed 6 bits to a byte (bit 6 set, bit 7 clear), most significant first:

====  =====  ===============================================================
byte  field  meaning
====  =====  ===============================================================
1-4   ssss   focus distance, 24 bits: 1 mm (or 0.1 inch in imperial display units); all ones = infinity
5-6   TT     aperture: T-number x 100
7-8   tt     aperture ring (status bits; not decoded)
9-10  zz     zoom: effective focal length in mm, 0 for a prime
11-14 hhhh   hyperfocal distance, as ssss
15-18 nnnn   near focus distance, as ssss
19-22 ffff   far focus distance, as ssss
23-24 vv     horizontal field of view (raw; its scale depends on the lens's film-format setting)
25-26 ee     entrance pupil position: bit 5 of byte 25 the sign, then 10 bits, mm (camdkit's reading)
27-28 ZZ     normalised zoom
29-   S...   'S' and the lens serial number in ASCII, then LF CR
====  =====  ===============================================================

The distances are returned as millimetres assuming the lens reports metric units; the RED sample
agrees (its focus 424 mm beside REDline's own 410 mm column, its near and far 414 and 435 mm).
"""

from __future__ import annotations

from ..errors import MetadataError, require_type
from .record import CookeData

__all__ = ["decode", "parse_hex"]

_INFINITY = (1 << 24) - 1


def _field(b: bytes, start: int, count: int) -> int:
    v = 0
    for x in b[start:start + count]:
        v = (v << 6) | (x & 0x3F)
    return v


def _distance(b: bytes, start: int) -> float | None:
    v = _field(b, start, 4)
    return float("inf") if v == _INFINITY else float(v)


def parse_hex(path, line, text: str) -> bytes:
    """REDline's "64/40/40/..." as bytes."""
    require_type("text", text, str, 'slash-separated hex bytes, "64/40/..."')
    try:
        return bytes(int(x, 16) for x in text.strip().split("/"))
    except ValueError:
        raise MetadataError(f"Cooke /i data {text[:24]!r}... is not slash-separated hex bytes", path, line) from None


def decode(data: bytes, path=None, line=None) -> CookeData:
    """The :class:`CookeData` of one ``Kd`` response (module notes)."""
    require_type("data", data, (bytes, bytearray), "the bytes of a Cooke /i Kd response")
    if len(data) < 29 or data[0] != ord("d"):
        raise MetadataError(f"Cooke /i data of {len(data)} bytes is not a 'd' lens-data response", path, line)
    sign = -1 if data[25] & 0b0010_0000 else 1
    pupil = sign * (((data[25] & 0x0F) << 6) | (data[26] & 0x3F))
    serial = None
    if data[29:30] == b"S":
        serial = data[30:].split(b"\n")[0].split(b"\r")[0].decode("ascii", "replace").strip() or None
    zoom = _field(data, 9, 2)
    return CookeData(focus_distance_mm=_distance(data, 1), t_stop=_field(data, 5, 2) / 100.0,
                     zoom_mm=float(zoom) if zoom else None, hyperfocal_mm=_distance(data, 11),
                     near_mm=_distance(data, 15), far_mm=_distance(data, 19),
                     horizontal_fov_raw=_field(data, 23, 2), entrance_pupil_mm=float(pupil),
                     normalized_zoom_raw=_field(data, 27, 2), serial=serial)
