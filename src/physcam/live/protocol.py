"""OpenTrackIO packets: the 16-byte header, the Fletcher-16 checksum, segmentation and reassembly.

A packet (one UDP datagram) is a big-endian header followed by a piece of the payload (one
JSON or CBOR sample)::

    offset size  field
    0      4     identifier "OTrk"
    4      1     reserved (0)
    5      1     encoding: 0x01 JSON, 0x02 CBOR
    6      2     sequence number (u16, one per sample, wraps)
    8      4     segment offset: where this piece starts in the whole payload (bytes)
    12     2     last-segment flag (top bit) and this piece's length (15 bits)
    14     2     Fletcher-16 checksum of bytes 0-13 and the piece

Source: the OpenTrackIO documentation's transport section, as summarised in
``shared/reference/opentrackio/README.md``. The checksum's modulus is 256 in the current reference
code and was 255 on the 1.0.0 page; :func:`fletcher16` takes either (``modulus``), 256 by default.

Reassembly keeps a bounded number of unfinished samples (:class:`Reassembler`), each in one buffer
of the largest sample (64 KiB) with a bit map of the bytes that have arrived: a piece overlapping
bytes already held is refused, a sample whose pieces never all arrive is dropped when newer ones
push it out, so memory never grows with bad input (16 x 72 KiB by default).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from itertools import accumulate

import numpy as np

from ..errors import InputError, PhysCamError, require_type
from .sample import shown

__all__ = [
    "HEADER_SIZE", "IDENTIFIER", "ENCODING_JSON", "ENCODING_CBOR", "MAX_SEGMENT_PAYLOAD", "DEFAULT_SEGMENT_PAYLOAD",
    "MAX_SAMPLE_BYTES", "PacketError", "PacketHeader", "fletcher16", "build_packet", "packetize", "parse_packet",
    "Reassembler",
]

HEADER_SIZE = 16
IDENTIFIER = b"OTrk"
ENCODING_JSON = 0x01
ENCODING_CBOR = 0x02
ENCODINGS = {ENCODING_JSON: "json", ENCODING_CBOR: "cbor"}
#: the 15-bit length field's largest piece
MAX_SEGMENT_PAYLOAD = 0x7FFF
#: pieces that fit a 1500-byte Ethernet frame with the IPv4 (20) and UDP (8) headers: 1500 - 28 - 16
DEFAULT_SEGMENT_PAYLOAD = 1456
#: the largest sample physcam reassembles (a complete static sample is ~5 KB; 64 KiB is generous)
MAX_SAMPLE_BYTES = 65536

_HEADER = struct.Struct("!4sBBHIH")  # the 14 bytes before the checksum
_CHECKSUM = struct.Struct("!H")


class PacketError(PhysCamError):
    """A datagram that is not a usable OpenTrackIO packet; ``kind`` is ``malformed`` (bad identifier,
    encoding, lengths, oversized) or ``checksum`` (the Fletcher-16 sum does not match)."""

    def __init__(self, message: str, kind: str = "malformed"):
        super().__init__(message)
        self.kind = kind


@dataclass(frozen=True)
class PacketHeader:
    """The header's fields (module notes)."""

    encoding: int
    sequence: int
    offset: int
    last: bool
    length: int
    checksum: int


def _modulus(modulus) -> int:
    if isinstance(modulus, bool) or modulus not in (255, 256):
        raise InputError(f"the Fletcher-16 modulus is 256 (current reference code) or 255 (1.0.0 page), got {shown(modulus)}")
    return int(modulus)


def fletcher16(data, modulus: int = 256) -> int:
    """Fletcher-16 of ``data`` (bytes-like): ``(sum2 << 8) | sum1`` with both running sums taken
    modulo ``modulus`` (Fletcher, "An Arithmetic Checksum for Serial Transmissions", IEEE Trans.
    Commun. 30(1), 1982).

    Computed in closed form: ``sum1 = sum(d_i)`` and ``sum2 = sum((n - i) d_i)`` reduced once at
    the end, equal to the byte-by-byte recurrence because reduction modulo m commutes with sums
    (summed 8 KiB at a time, :func:`_sums`).

    Wikipedia's test vectors ("Fletcher's checksum", modulus 255) and the same sums modulo 256:

    >>> hex(fletcher16(b"abcde", modulus=255)), hex(fletcher16(b"abcdef", modulus=255))
    ('0xc8f0', '0x2057')
    >>> hex(fletcher16(b"abcde"))  # sum1 = 495 = 239 (mod 256), sum2 = 1475 = 195 (mod 256)
    '0xc3ef'
    """
    if not isinstance(data, (bytes, bytearray, memoryview)):
        raise InputError(f"data must be bytes, got {type(data).__name__}")
    m = _modulus(modulus)
    s1, s2 = _sums((data,))
    return ((s2 % m) << 8) | (s1 % m)


_CHUNK = 8192  # bytes summed at a time: the working arrays stay at 128 KiB whatever the packet's size
# a chunk of n bytes weighs them n, n-1, ..., 1; summed in float64, exactly: every product and partial sum is
# an integer under 255 x 8192 x 8193 / 2 < 2^53, so any order of summation (BLAS, SIMD) gives the same sums
_WEIGHTS = np.arange(_CHUNK, 0, -1, dtype=np.float64)


def _sums(parts) -> tuple[int, int]:
    """Fletcher's running sums (unreduced) over the concatenation of ``parts``, without joining them:
    appending m bytes with sums (t1, t2) to a prefix with (s1, s2) gives (s1 + t1, s2 + m s1 + t2)."""
    s1 = s2 = 0
    for part in parts:
        if len(part) <= 64:  # a header: plain Python beats numpy's call overhead
            b = bytes(part)  # sum((n - i) d_i) is the sum of the n prefix sums d_0 + ... + d_k
            s1, s2 = s1 + sum(b), s2 + len(b) * s1 + sum(accumulate(b))
            continue
        d = np.frombuffer(part, dtype=np.uint8)
        for start in range(0, d.size, _CHUNK):
            c = d[start:start + _CHUNK].astype(np.float64)  # 0.6 x the time of int64's dot (no BLAS for ints)
            n = c.size
            t1 = int(c.sum())
            t2 = int(_WEIGHTS[_CHUNK - n:] @ c)
            s1, s2 = s1 + t1, s2 + n * s1 + t2
    return s1, s2


def build_packet(piece: bytes, *, encoding: int, sequence: int, offset: int = 0, last: bool = True,
                 modulus: int = 256) -> bytes:
    """One datagram: header (with its checksum) followed by ``piece``."""
    if not isinstance(piece, (bytes, bytearray, memoryview)):
        raise InputError(f"a packet's payload must be bytes, got {type(piece).__name__}")
    if encoding not in ENCODINGS:
        raise InputError(f"encoding must be 0x01 (JSON) or 0x02 (CBOR), got {shown(encoding)}")
    if isinstance(sequence, bool) or not isinstance(sequence, int) or not 0 <= sequence <= 0xFFFF:
        raise InputError(f"sequence number must be a whole number 0..65535, got {shown(sequence)}")
    if isinstance(offset, bool) or not isinstance(offset, int) or not 0 <= offset <= 0xFFFFFFFF:
        raise InputError(f"segment offset must be a whole number 0..2^32-1, got {shown(offset)}")
    if len(piece) > MAX_SEGMENT_PAYLOAD:
        raise InputError(f"a packet carries at most {MAX_SEGMENT_PAYLOAD} payload bytes, got {len(piece)}")
    head = _HEADER.pack(IDENTIFIER, 0, encoding, sequence, offset, (0x8000 if last else 0) | len(piece))
    return head + _CHECKSUM.pack(fletcher16(head + bytes(piece), modulus)) + bytes(piece)


def packetize(payload: bytes, *, encoding: int, sequence: int, segment_payload: int = DEFAULT_SEGMENT_PAYLOAD,
              modulus: int = 256) -> list[bytes]:
    """The datagrams of one sample: ``payload`` cut into pieces of at most ``segment_payload`` bytes,
    all with the same sequence number, offsets counting bytes, the last one flagged."""
    if not isinstance(payload, (bytes, bytearray, memoryview)):
        raise InputError(f"payload must be bytes, got {type(payload).__name__}")
    if isinstance(segment_payload, bool) or not isinstance(segment_payload, int) \
            or not 1 <= segment_payload <= MAX_SEGMENT_PAYLOAD:
        raise InputError(f"segment payload must be 1..{MAX_SEGMENT_PAYLOAD} bytes, got {shown(segment_payload)}")
    payload = bytes(payload)
    if not payload:
        raise InputError("an empty payload is not a sample")
    out = []
    for start in range(0, len(payload), segment_payload):
        piece = payload[start:start + segment_payload]
        out.append(build_packet(piece, encoding=encoding, sequence=sequence, offset=start,
                                last=start + len(piece) == len(payload), modulus=modulus))
    return out


def parse_packet(datagram, modulus: int | str = 256) -> tuple[PacketHeader, bytes]:
    """(header, piece) of one datagram, or :class:`PacketError` saying what is wrong.

    ``modulus``: 256, 255, or ``"auto"`` (either matches: senders following the 1.0.0 page).
    """
    if not isinstance(datagram, (bytes, bytearray, memoryview)):
        require_type("datagram", datagram, (bytes, bytearray, memoryview))
    data = memoryview(datagram)
    if len(data) < HEADER_SIZE:
        raise PacketError(f"{len(data)} bytes: shorter than the 16-byte header")
    ident, _reserved, encoding, seq, offset, lflag = _HEADER.unpack_from(data, 0)
    if ident != IDENTIFIER:
        raise PacketError("not an OpenTrackIO packet (identifier is not 'OTrk')")
    if encoding not in ENCODINGS:
        raise PacketError(f"unknown payload encoding 0x{encoding:02x} (0x01 JSON, 0x02 CBOR)")
    length = lflag & 0x7FFF
    if len(data) != HEADER_SIZE + length:
        raise PacketError(f"the header says {length} payload bytes, the datagram carries {len(data) - HEADER_SIZE}")
    if offset + length > MAX_SAMPLE_BYTES:
        raise PacketError(f"segment ends at byte {offset + length}: beyond the {MAX_SAMPLE_BYTES}-byte sample limit")
    (checksum,) = _CHECKSUM.unpack_from(data, 14)
    moduli = (255, 256) if modulus == "auto" else (_modulus(modulus),)
    s1, s2 = _sums((data[:14], data[HEADER_SIZE:]))
    if all(((s2 % m) << 8) | (s1 % m) != checksum for m in moduli):
        raise PacketError("Fletcher-16 checksum does not match", kind="checksum")
    header = PacketHeader(encoding, seq, offset, bool(lflag & 0x8000), length, checksum)
    return header, bytes(data[HEADER_SIZE:])


class _Unfinished:
    """One segmented sample being put together: a 64 KiB buffer and a bit map of the bytes it holds."""

    __slots__ = ("encoding", "buffer", "have", "bytes", "end", "top")

    def __init__(self, encoding: int, size: int):
        self.encoding = encoding
        self.buffer = bytearray(size)
        self.have = 0  # bit i set: byte i has arrived (a Python int of at most size bits)
        self.bytes = 0  # bytes held; the pieces never overlap, so the sample is whole when bytes == end
        self.end = None  # the sample's length, known from its last piece
        self.top = 0  # the furthest byte any piece reached


class Reassembler:
    """Collect the pieces of segmented samples, in bounded memory (module notes).

    :meth:`add` returns ``(encoding, payload)`` when a sample is complete, else None. It raises
    :class:`PacketError` for a piece it refuses: one that overlaps bytes already held (kind
    ``duplicate`` when it repeats them exactly, else ``malformed``; the sample keeps what it had), and
    for pieces that contradict the sample (two encodings, two different last pieces, a piece beyond
    the end; the sample is dropped).

    Bound: at most ``max_pending`` unfinished samples (a newer one pushes the oldest out, counted in
    :attr:`dropped`), each one buffer of ``max_sample_bytes`` and a bit map of as many bits, whatever
    arrives: 16 x (64 KiB + 8 KiB) = 1.125 MiB by default. Samples are keyed by the packet's sequence
    number and ``source`` (the sender's address), so two senders never mix their pieces.
    """

    def __init__(self, max_pending: int = 16, max_sample_bytes: int = MAX_SAMPLE_BYTES):
        if isinstance(max_pending, bool) or not isinstance(max_pending, int) or not 1 <= max_pending <= 4096:
            raise InputError(f"max_pending must be 1..4096, got {shown(max_pending)}")
        if isinstance(max_sample_bytes, bool) or not isinstance(max_sample_bytes, int) \
                or not 1 <= max_sample_bytes <= MAX_SAMPLE_BYTES:
            raise InputError(f"max_sample_bytes must be 1..{MAX_SAMPLE_BYTES}, got {shown(max_sample_bytes)}")
        self.max_pending = max_pending
        self.max_sample_bytes = max_sample_bytes
        self._pending: dict[tuple, _Unfinished] = {}
        self.dropped = 0
        self.high_water_bytes = 0

    @property
    def pending_bytes(self) -> int:
        """Payload bytes held in unfinished samples."""
        return sum(p.bytes for p in self._pending.values())

    @property
    def allocated_bytes(self) -> int:
        """Bytes of the unfinished samples' buffers (each ``max_sample_bytes``; the bit maps add 1/8)."""
        return len(self._pending) * self.max_sample_bytes

    def discard(self, sequence: int, source=None) -> None:
        self._pending.pop((source, sequence), None)

    def add(self, header: PacketHeader, piece: bytes, source=None):
        key = (source, header.sequence)
        if header.offset == 0 and header.last:  # the common case: one packet, one sample
            self._pending.pop(key, None)
            return header.encoding, piece
        end = header.offset + header.length
        if end > self.max_sample_bytes:
            raise PacketError(f"segment ends at byte {end}: beyond the {self.max_sample_bytes}-byte sample limit")
        entry = self._pending.get(key)
        if entry is None:
            if len(self._pending) >= self.max_pending:  # the oldest unfinished sample gives way
                del self._pending[next(iter(self._pending))]
                self.dropped += 1
            entry = self._pending[key] = _Unfinished(header.encoding, self.max_sample_bytes)
        if entry.encoding != header.encoding:
            del self._pending[key]
            raise PacketError("segments of one sample announce different encodings")
        if header.last:
            if entry.end is not None and entry.end != end:
                del self._pending[key]
                raise PacketError("two last segments of one sample")
            if entry.top > end:
                del self._pending[key]
                raise PacketError("a segment beyond the last one")
            entry.end = end
        elif entry.end is not None and end > entry.end:
            del self._pending[key]
            raise PacketError("a segment beyond the last one")
        mask = ((1 << header.length) - 1) << header.offset
        if entry.have & mask:
            if entry.have & mask == mask and entry.buffer[header.offset:end] == piece:
                raise PacketError("the same segment twice", kind="duplicate")
            raise PacketError("a segment overlaps bytes already received: refused")
        entry.buffer[header.offset:end] = piece
        entry.have |= mask
        entry.bytes += header.length
        entry.top = max(entry.top, end)
        self.high_water_bytes = max(self.high_water_bytes, self.pending_bytes)
        if entry.end is None or entry.bytes < entry.end:
            return None
        del self._pending[key]  # the pieces are disjoint and inside [0, end): all bytes are here
        return entry.encoding, bytes(entry.buffer[:entry.end])
