"""Mo-Sys StarTracker: a recording of F4 protocol packets (binary), one packet per frame.

A packet: ``0xF4``, camera id, axis count n, status (low 4 bits a frame counter), n axis blocks of
5 bytes (axis id, then 4 bytes), and a checksum byte = (0x40 - the sum of the other bytes) mod 256.
Axis blocks read (Mo-Sys F4 notes as implemented by camdkit, ``camdkit/mosys/f4.py``):

* 0x01 pan, 0x02 tilt, 0x13 roll: signed 24-bit, 1/1000 degree;
* 0x05 X, 0x06 Y, 0x07 height: signed 24-bit / 1000, in the tracker's linear unit (camdkit and
  its OpenTrackIO examples read metres; the public notes do not fix it, so ``TrackerPose`` keeps
  the value as sent and the USD and OpenTrackIO writers use camdkit's metres, docs/camera-metadata.md);
* 0x03 focus, 0x04 zoom, 0x0D iris: lens encoders, 16 bits / 65536 (0..1);
* 0x57: 1 / focus distance (a 32-bit float, 1/m): ``focus_mm`` = 1000 / value;
* 0x60: the f-number (32-bit float), when sent;
* 0x50 entrance pupil, 0x51 k1, 0x52 k2, 0x53 fx, 0x54 cx, 0x55 cy, 0x58 fy: 32-bit floats kept
  as sent in ``TrackerPose.lens_fields`` (their units follow the tracker's lens file);
* 0xF8 timecode: frame rate in bits 5-6 of the status byte (24, 25, 30), then H, M, S, F packed;
* 0xF9 tracking status (high nibble of the third byte).

No focal length, T-stop or sensor is sent: those fields are None.
"""

from __future__ import annotations

import struct
from fractions import Fraction
from pathlib import Path

from ..errors import MetadataError, require_type
from .record import ClipRecord, FrameSample, TrackerPose

__all__ = ["sniff", "read"]

STATUS = ("Undefined", "Tracking", "Optical Good", "Optical Acceptable", "Optical Unreliable", "Optical Unstable",
          "Optical Lost", "Lost Too Few Stars", "Location Searching", "Busy or Waiting", "Busy Loading Map",
          "No Map Loaded", "Test Signal", "Mechanical Encoders Only", "I/O Error", "Internal Error")
FLOATS = {0x50: "entrance_pupil", 0x51: "k1", 0x52: "k2", 0x53: "fx", 0x54: "cx", 0x55: "cy", 0x58: "fy"}
MAX_PACKETS = 1_000_000


def sniff(head: bytes) -> bool:
    """True when ``head`` starts with one well-formed F4 packet."""
    require_type("head", head, bytes, "the first bytes of a metadata file")
    return _packet_size(head, 0) is not None


def _packet_size(data: bytes, off: int) -> int | None:
    if len(data) < off + 5 or data[off] != 0xF4 or data[off + 2] == 0:
        return None
    size = data[off + 2] * 5 + 5
    if len(data) < off + size or (0x40 - sum(data[off:off + size - 1])) % 256 != data[off + size - 1]:
        return None
    return size


def _s24(b: bytes) -> int:
    v = (b[0] << 16) | (b[1] << 8) | b[2]
    return v - (1 << 24) if v & 0x800000 else v


def _timecode(status: int, b: bytes) -> tuple[str, int]:
    rate = {0: 24, 1: 25, 2: 30}.get((status >> 5) & 3)
    h = (b[0] >> 2) % 24
    m = ((b[0] << 4) % 64) + ((b[1] >> 4) % 16)
    s = ((b[1] << 2) % 64) + ((b[2] >> 6) % 4)
    return f"{h:02d}:{m:02d}:{s:02d}:{b[2] % 64:02d}", rate


def _frame(index: int, packet: bytes):
    pose = {0x01: 0.0, 0x02: 0.0, 0x13: 0.0, 0x05: 0.0, 0x06: 0.0, 0x07: 0.0}
    enc, lens, tc, rate, status, focus, fstop = {}, {}, None, None, None, None, None
    for i in range(packet[2]):
        axis, st, b = packet[4 + 5 * i], packet[5 + 5 * i], packet[6 + 5 * i: 9 + 5 * i]
        f32 = struct.unpack(">f", bytes([st]) + b)[0]
        if axis in pose:
            pose[axis] = _s24(b) / 1000.0
        elif axis in (0x03, 0x04, 0x0D):
            enc[{0x03: "focus", 0x04: "zoom", 0x0D: "iris"}[axis]] = ((b[1] << 8) | b[2]) / 65536.0
        elif axis == 0x57:
            focus = 1000.0 / f32 if f32 > 0 else None
        elif axis == 0x60:
            fstop = f32
        elif axis in FLOATS:
            lens[FLOATS[axis]] = f32
        elif axis == 0xF8:
            tc, rate = _timecode(st, b)
        elif axis == 0xF9:
            status = STATUS[(b[1] >> 4) & 0xF]
    tracker = TrackerPose(translation=(pose[0x05], pose[0x06], pose[0x07]),
                          rotation_deg=(pose[0x01], pose[0x02], pose[0x13]), status=status, encoders=enc,
                          lens_fields=lens)
    return FrameSample(line=index, timecode=tc, focus_mm=focus, fstop=fstop, tracker=tracker), rate


def read(path) -> ClipRecord:
    """The clip of one F4 recording (module notes); ``FrameSample.line`` is the packet's index."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise MetadataError(f"cannot read it ({exc.strerror or exc})", p) from None
    frames, rates, off = [], set(), 0
    while off < len(data):
        size = _packet_size(data, off)
        if size is None:
            what = "the file is truncated" if data[off:off + 1] == b"\xf4" else "not a Mo-Sys F4 packet"
            raise MetadataError(f"{what} (packet {len(frames)}: no 0xF4 start, short, or a wrong checksum)",
                                p, offset=off)
        if len(frames) >= MAX_PACKETS:
            raise MetadataError(f"more than {MAX_PACKETS} packets", p, offset=off)
        sample, rate = _frame(len(frames), data[off:off + size])
        frames.append(sample)
        rates.add(rate)
        off += size
    if not frames:
        raise MetadataError("the file is empty", p, offset=0)
    rate = rates.pop() if len(rates) == 1 else None
    return ClipRecord(source="mosys", files=(str(p),), frames=tuple(frames), camera_make=None,
                      frame_rate=None if rate is None else Fraction(rate),
                      notes=("tracker translation kept in the F4 unit / 1000 (camdkit reads metres)",
                             "focus distance from the F4 inverse-focus field (1/m)"))
