"""Send OpenTrackIO samples over UDP, one sample per sequence number, segmented when large.

:class:`Sender` encodes a sample (JSON or CBOR), cuts it into packets
(:func:`physcam.live.protocol.packetize`) and sends them to a unicast address or a multicast
group (TTL 1, loopback on, so a receiver on the same machine hears it). :meth:`Sender.stream`
paces a sequence of samples at a frame rate against a monotonic clock (no drift: frame n leaves
at start + n / rate), for demos, tests and the benchmark.
"""

from __future__ import annotations

import socket
import time

from ..errors import InputError, PhysCamError, require_finite
from .protocol import DEFAULT_SEGMENT_PAYLOAD, ENCODING_CBOR, ENCODING_JSON, packetize
from .receiver import DEFAULT_PORT, check_address, check_port
from .sample import encode_sample, shown

__all__ = ["Sender", "MAX_STREAM_RATE"]

#: the fastest pacing :meth:`Sender.stream` accepts (samples per second); 0 sends as fast as possible
MAX_STREAM_RATE = 100_000.0


class Sender:
    """Send samples to ``host``:``port`` (module notes); ``encoding`` "json" or "cbor"."""

    def __init__(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT, *, encoding: str = "json",
                 segment_payload: int = DEFAULT_SEGMENT_PAYLOAD, interface: str = "127.0.0.1", modulus: int = 256):
        self.host = check_address("destination", host)
        self.port = check_port(port)
        if self.port == 0:
            raise InputError("the destination port must be 1..65535")
        if encoding not in ("json", "cbor"):
            raise InputError(f"encoding must be json or cbor, got {encoding!r}")
        if modulus not in (255, 256):
            raise InputError(f"the Fletcher-16 modulus is 256 or 255, got {shown(modulus)}")
        self.encoding = encoding
        self.segment_payload = segment_payload
        self.modulus = modulus
        self.sequence = 0
        self.sent_samples = 0
        self.sent_packets = 0
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        try:
            self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4 * 1024 * 1024)
            if 224 <= int(self.host.split(".")[0]) <= 239:
                self._sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 1)
                self._sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
                self._sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF,
                                      socket.inet_aton(check_address("interface", interface)))
        except OSError as exc:
            self._sock.close()
            raise PhysCamError(f"cannot set up sending to {self.host}: {exc.strerror or exc}") from None

    def packets(self, sample: dict) -> list[bytes]:
        """The datagrams of ``sample`` with the next sequence number (which this call uses up)."""
        payload = encode_sample(sample, self.encoding)
        enc = ENCODING_JSON if self.encoding == "json" else ENCODING_CBOR
        out = packetize(payload, encoding=enc, sequence=self.sequence, segment_payload=self.segment_payload,
                        modulus=self.modulus)
        self.sequence = (self.sequence + 1) & 0xFFFF
        return out

    def send_datagram(self, datagram: bytes) -> None:
        """Send raw bytes as one datagram (tests inject bad packets with it)."""
        try:
            self._sock.sendto(datagram, (self.host, self.port))
        except OSError as exc:
            raise PhysCamError(f"cannot send to {self.host}:{self.port}: {exc.strerror or exc}") from None
        self.sent_packets += 1

    def send(self, sample: dict) -> int:
        """Send one sample; returns the number of packets it took."""
        pk = self.packets(sample)
        for d in pk:
            self.send_datagram(d)
        self.sent_samples += 1
        return len(pk)

    def stream(self, samples, rate: float, *, duration_s: float | None = None, progress=None) -> int:
        """Send ``samples`` (an iterable of dicts) paced at ``rate`` per second (0: as fast as possible),
        stopping after ``duration_s`` seconds if given; returns how many were sent. ``progress(n)`` is
        called after each sample."""
        r = require_finite("rate", rate)
        if not 0.0 <= r <= MAX_STREAM_RATE:
            raise InputError(f"rate must lie between 0 and {MAX_STREAM_RATE:g} samples per second, got {r:g}")
        limit = None if duration_s is None else require_finite("duration", duration_s)
        if limit is not None and limit < 0:
            raise InputError(f"duration must be >= 0 s, got {limit:g}")
        t0 = time.monotonic()
        n = 0
        for sample in samples:
            now = time.monotonic()
            if limit is not None and now - t0 >= limit:
                break
            if r > 0:
                due = t0 + n / r
                if due > now:
                    time.sleep(due - now)
            self.send(sample)
            n += 1
            if progress is not None:
                progress(n)
        return n

    def close(self) -> None:
        self._sock.close()

    def __enter__(self) -> "Sender":
        return self

    def __exit__(self, *exc) -> bool:
        self.close()
        return False
