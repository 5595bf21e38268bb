"""A UDP receiver for OpenTrackIO: packets in, validated samples out, in order, with bounded memory.

A background thread reads datagrams (unicast, or a multicast group joined on one interface) and,
for each: checks the header and the Fletcher-16 checksum (:mod:`physcam.live.protocol`), puts
segmented samples back together, decodes JSON or CBOR and validates the sample against the
OpenTrackIO schema (:mod:`physcam.live.sample`), then hands samples on **in sequence order**
through a bounded queue.

Order: packet sequence numbers (16 bits, wrapping) are unwrapped into a running count. A sample
waits in a reorder window of ``reorder_window`` samples (and at most ``reorder_timeout_s``) for the
ones before it; a number the window has already passed is **late**, one already seen a
**duplicate**; both are dropped. Gaps the window gives up on are counted as **missing**.

Counters (:meth:`Receiver.counters`): ``received`` datagrams; ``malformed`` (not OpenTrackIO,
truncated, oversized, contradictory segments, undecodable payload); ``wrong_checksum``;
``duplicate``; ``late``; ``invalid`` (decoded but not a valid sample); ``dropped`` (unfinished
segmented samples pushed out, or samples the consumer did not take before the queue filled);
``missing`` (sequence numbers never seen); ``delivered`` samples.

Memory is bounded whatever arrives: one receive buffer, at most ``max_pending`` unfinished samples
of at most 64 KiB, ``reorder_window`` decoded samples and ``queue_size`` samples in the queue.
:meth:`Receiver.stop` (or leaving the ``with`` block) ends the thread and closes the socket.
"""

from __future__ import annotations

import queue
import socket
import struct
import threading
import time
from collections import deque
from dataclasses import dataclass

from ..errors import InputError, PhysCamError
from .protocol import ENCODINGS, PacketError, Reassembler, parse_packet
from .sample import SampleError, decode_sample

__all__ = ["Receiver", "ReceivedSample", "COUNTERS", "DEFAULT_PORT", "multicast_group"]

DEFAULT_PORT = 55555
COUNTERS = ("received", "malformed", "wrong_checksum", "duplicate", "late", "invalid", "dropped", "missing",
            "delivered")
_RECV_BUFFER = 65536  # the largest UDP datagram fits


def multicast_group(source_number: int = 1) -> str:
    """OpenTrackIO's multicast group for a source number: 239.135.1.N (current documentation)."""
    if isinstance(source_number, bool) or not isinstance(source_number, int) or not 1 <= source_number <= 200:
        raise InputError(f"source number must be 1..200, got {source_number!r}")
    return f"239.135.1.{source_number}"


def check_port(port) -> int:
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise InputError(f"port must be a whole number 0..65535, got {port!r}")
    return port


def check_address(name: str, text) -> str:
    if not isinstance(text, str):
        raise InputError(f"{name} must be an IPv4 address, got {text!r}")
    try:
        socket.inet_aton(text)
    except OSError:
        raise InputError(f"{name} must be an IPv4 address such as 127.0.0.1, got {text!r}") from None
    if text.count(".") != 3:
        raise InputError(f"{name} must be a dotted IPv4 address such as 127.0.0.1, got {text!r}")
    return text


@dataclass(frozen=True)
class ReceivedSample:
    """A validated sample, its packet sequence number (unwrapped), encoding and arrival time (monotonic s)."""

    sample: dict
    sequence: int
    encoding: str
    arrival_s: float


class Receiver:
    """Receive OpenTrackIO samples on ``port`` (module notes).

    ``host``: the unicast address to bind (default all interfaces); ``group``: a multicast group to
    join on ``interface`` (``127.0.0.1`` for loopback tests). ``modulus``: the Fletcher-16 modulus
    (256, 255 or "auto"). Use as a context manager, or call :meth:`start` and :meth:`stop`.
    """

    def __init__(self, port: int = DEFAULT_PORT, *, host: str = "0.0.0.0", group: str | None = None,
                 interface: str = "127.0.0.1", queue_size: int = 1024, reorder_window: int = 8,
                 reorder_timeout_s: float = 0.05, max_pending: int = 16, modulus: int | str = 256,
                 receive_buffer_bytes: int = 8 * 1024 * 1024):
        self.requested_port = check_port(port)
        self.host = check_address("host", host)
        self.group = None if group is None else check_address("multicast group", group)
        if self.group is not None and not 224 <= int(self.group.split(".")[0]) <= 239:
            raise InputError(f"{self.group} is not a multicast address (224.0.0.0 to 239.255.255.255)")
        self.interface = check_address("interface", interface)
        for name, v, lo, hi in (("queue size", queue_size, 1, 1 << 20), ("reorder window", reorder_window, 1, 4096),
                                ("receive buffer", receive_buffer_bytes, 65536, 1 << 30)):
            if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
                raise InputError(f"{name} must be a whole number {lo}..{hi}, got {v!r}")
        if modulus not in (255, 256, "auto"):
            raise InputError(f"the Fletcher-16 modulus is 256, 255 or 'auto', got {modulus!r}")
        if not isinstance(reorder_timeout_s, (int, float)) or not 0.0 < reorder_timeout_s <= 10.0:
            raise InputError(f"reorder timeout must lie in (0, 10] s, got {reorder_timeout_s!r}")
        self.modulus = modulus
        self.reorder_window = reorder_window
        self.reorder_timeout_s = float(reorder_timeout_s)
        self.receive_buffer_bytes = receive_buffer_bytes
        self._queue: queue.Queue = queue.Queue(maxsize=queue_size)
        self._reassembler = Reassembler(max_pending=max_pending)
        self._counts = dict.fromkeys(COUNTERS, 0)
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._sock: socket.socket | None = None
        self._error: BaseException | None = None
        # ordering state
        self._top: int | None = None  # highest unwrapped sequence seen
        self._next: int | None = None  # next sequence to hand on
        self._window: dict[int, ReceivedSample | None] = {}
        self._window_since = 0.0
        self._seen = deque(maxlen=4096)
        self._seen_set: set[int] = set()
        self.high_water = {"window": 0, "queue": 0, "reassembly_bytes": 0}
        self.port = None

    # --- life cycle ----------------------------------------------------------------
    def start(self) -> "Receiver":
        if self._thread is not None:
            raise PhysCamError("this receiver has already been started")
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, self.receive_buffer_bytes)
            except OSError:
                pass  # the kernel keeps its own limit
            if self.group is not None:
                sock.bind(("", self.requested_port))
                mreq = struct.pack("4s4s", socket.inet_aton(self.group), socket.inet_aton(self.interface))
                sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
            else:
                sock.bind((self.host, self.requested_port))
            sock.settimeout(0.02)
        except OSError as exc:
            sock.close()
            where = self.group or self.host
            raise PhysCamError(f"cannot listen on {where}:{self.requested_port}: {exc.strerror or exc}") from None
        self._sock = sock
        self.port = sock.getsockname()[1]
        self._thread = threading.Thread(target=self._run, name="physcam-opentrackio-receiver", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """End the receiving thread and close the socket; samples already in the queue stay readable."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        if self._sock is not None:
            self._sock.close()
            self._sock = None
        self._flush(skip_all=True)

    def __enter__(self) -> "Receiver":
        return self.start()

    def __exit__(self, *exc) -> bool:
        self.stop()
        return False

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    # --- output -----------------------------------------------------------------------
    def get(self, timeout: float | None = None) -> ReceivedSample | None:
        """The next sample in order, waiting up to ``timeout`` s (None: do not wait); None if there is none."""
        if self._error is not None:
            err, self._error = self._error, None
            raise err
        try:
            if timeout is None:
                return self._queue.get_nowait()
            return self._queue.get(timeout=timeout)
        except queue.Empty:
            return None

    def counters(self) -> dict:
        """A snapshot of the counters (module notes)."""
        with self._lock:
            out = dict(self._counts)
        out["dropped"] += self._reassembler.dropped
        return out

    # --- the thread --------------------------------------------------------------------
    def _count(self, name: str, n: int = 1) -> None:
        with self._lock:
            self._counts[name] += n

    def _run(self) -> None:
        buf = bytearray(_RECV_BUFFER)
        view = memoryview(buf)
        sock = self._sock
        try:
            while not self._stop.is_set():
                try:
                    n = sock.recv_into(buf)
                except socket.timeout:
                    self._flush(skip_all=True)
                    continue
                except OSError:
                    if self._stop.is_set():
                        break
                    raise
                self._count("received")
                self._handle(view[:n])
                if self._window and time.monotonic() - self._window_since > self.reorder_timeout_s:
                    self._flush(skip_all=True)
        except BaseException as exc:  # noqa: BLE001 - handed to the consumer, never lost in the thread
            self._error = exc

    def _unwrap(self, seq: int) -> int:
        if self._top is None:
            return seq
        delta = (seq - self._top + 32768) % 65536 - 32768
        return self._top + delta

    def _handle(self, datagram) -> None:
        try:
            header, piece = parse_packet(datagram, self.modulus)
        except PacketError as exc:
            self._count("wrong_checksum" if exc.kind == "checksum" else "malformed")
            return
        ext = self._unwrap(header.sequence)
        if ext in self._seen_set or ext in self._window:
            self._count("duplicate")
            return
        if self._next is not None and ext < self._next:
            self._count("late")
            return
        try:
            done = self._reassembler.add(header, piece)
        except PacketError as exc:
            self._count("duplicate" if exc.kind == "duplicate" else "malformed")
            return
        self.high_water["reassembly_bytes"] = max(self.high_water["reassembly_bytes"], self._reassembler.high_water_bytes)
        if done is None:
            return
        encoding, payload = done
        self._top = ext if self._top is None else max(self._top, ext)
        if self._next is None:
            self._next = ext
        try:
            sample = decode_sample(payload, ENCODINGS[encoding])
            item = ReceivedSample(sample, ext, ENCODINGS[encoding], time.monotonic())
        except SampleError as exc:
            self._count("malformed" if exc.problems[0].rule in ("json", "cbor") else "invalid")
            item = None  # the number is used up: the window moves past it
        if not self._window:
            self._window_since = time.monotonic()
        self._window[ext] = item
        self.high_water["window"] = max(self.high_water["window"], len(self._window))
        self._flush()

    def _remember(self, ext: int) -> None:
        if len(self._seen) == self._seen.maxlen:
            self._seen_set.discard(self._seen[0])
        self._seen.append(ext)
        self._seen_set.add(ext)

    def _deliver(self, ext: int) -> None:
        item = self._window.pop(ext)
        self._remember(ext)
        self._next = ext + 1
        if item is None:
            return
        try:
            self._queue.put_nowait(item)
        except queue.Full:
            self._count("dropped")
            return
        self._count("delivered")
        self.high_water["queue"] = max(self.high_water["queue"], self._queue.qsize())

    def _flush(self, skip_all: bool = False) -> None:
        """Hand on the window's samples that are next in order. Past a gap: wait while the window has
        room, else (or with ``skip_all``: timed out, stopping) give the gap up as missing."""
        while self._window:
            if self._next in self._window:
                self._deliver(self._next)
            elif skip_all or len(self._window) > self.reorder_window:
                ext = min(self._window)
                self._count("missing", ext - self._next)
                self._next = ext
                self._window_since = time.monotonic()
            else:
                break
