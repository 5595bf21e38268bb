"""A UDP receiver for OpenTrackIO: packets in, validated samples out, in order per source, with bounded memory.

A background thread reads datagrams (unicast, or a multicast group joined on one interface) and,
for each: checks the header and the Fletcher-16 checksum (:mod:`physcam.live.protocol`), puts
segmented samples back together (per sender address), decodes JSON or CBOR and validates the
sample against the OpenTrackIO schema (:mod:`physcam.live.sample`), then hands samples on **in
sequence order per source** through a bounded queue.

Sources: a stream is a sample's (``sourceId``, ``sourceNumber``); each has its own sequence numbers.
Source numbers outside 1..200 (OpenTrackIO's transport: multicast groups 239.135.1.1-200) are
discarded, as the transport asks of consumers, although the schema allows 0..2^32-1.

Order: a source's 16-bit packet sequence numbers are unwrapped into a running count. A sample waits
in a reorder window for the ones before it: a missing number is given up (counted **missing**)
once ``reorder_window`` (8) later samples wait, or the oldest of them has waited
``reorder_timeout_s`` (50 ms). An invalid sample of a known source holds its number the same way: a
valid sample with that number arriving meanwhile (the real one, after a forged or corrupted copy)
takes its place; else the number is passed over when the gap would be given up. A sample is on its stream when its number lies between the next one
due and ``reorder_window`` past the highest seen; anything else starts or extends an off-stream
**run**. A run **resynchronises** the source (the window is handed on, the run becomes the stream;
counted in ``resync``) when two samples in a row follow each other and are newer (by
``sampleTimestamp``, when both have one) than what was handed on, or when ``reorder_window`` samples
do: a restarted sender (numbers back to 0) or a jump is followed, and one packet far off the
sequence never moves it. A run that the stream's own samples interrupt is dropped: **late** if it
lay behind, **stray** if ahead.

Conflicts: UDP cannot be authenticated, so a different valid sample may claim a number its source has
used (a forged or replayed copy). A digest of each source's last ``HANDED_MEMORY`` (64) samples handed
on is kept (their content, whatever the encoding; made when a number is disputed, from the sample's
payload, kept till then when it is at most ``LAZY_DIGEST_BYTES``, 4 KiB: made for every sample, as
sorted JSON, it was a large part of receiving one); a different valid sample for one of those
numbers, or for one waiting in the window, is counted **conflict** (never late) and handed on flagged
(:attr:`ReceivedSample.conflict`) after the sample it disputes, for the take to judge
(:mod:`physcam.live.take`, "Conflicts").

Counters (:meth:`Receiver.counters`): ``received`` datagrams; ``malformed`` (not OpenTrackIO,
truncated, oversized, contradictory or overlapping segments, undecodable payload); ``wrong_checksum``;
``duplicate`` (a datagram received again, byte for byte; the same sample again in another encoding);
``late``; ``conflict``; ``stray``; ``invalid`` (decoded but not a valid sample, or a source number outside
1..200); ``dropped`` (unfinished segmented samples pushed out, or samples the consumer did not take
before the queue filled); ``missing`` (sequence numbers given up); ``resync``; ``delivered``. No
payload ends the receiving thread: one the checks themselves fail on is counted ``invalid``; the
reasons of the first ten refused payloads are kept, one bounded line each (:meth:`Receiver.refusals`).

Memory is bounded whatever arrives: one 64 KiB receive buffer; reassembly of at most
``max_pending`` (16) unfinished samples of 64 KiB each with an 8 KiB map (1.125 MiB,
:class:`~physcam.live.protocol.Reassembler`); the keys of the last 4,096 datagrams (duplicates);
at most 16 sources, each holding ``reorder_window`` samples in its window and as many in a run; and
``queue_size`` samples in the queue; for the digests, up to 64 payloads of at most 4 KiB per source
(4 MiB). :meth:`Receiver.stop` (or leaving the ``with`` block) ends the thread and closes the socket.
"""

from __future__ import annotations

import json
import queue
import socket
import struct
import threading
import time
from collections import deque
from dataclasses import dataclass

from ..errors import InputError, PhysCamError
from .protocol import ENCODINGS, PacketError, Reassembler, parse_packet
from .sample import SampleError, SampleProblem, decode_sample, sample_problems, shown

__all__ = ["Receiver", "ReceivedSample", "COUNTERS", "DEFAULT_PORT", "SOURCE_NUMBERS", "MAX_SOURCES", "multicast_group"]

DEFAULT_PORT = 55555
COUNTERS = ("received", "malformed", "wrong_checksum", "duplicate", "late", "conflict", "stray", "invalid",
            "dropped", "missing", "resync", "delivered")
#: OpenTrackIO's source numbers (the transport's multicast groups 239.135.1.1 to 239.135.1.200)
SOURCE_NUMBERS = (1, 200)
#: sources followed at once; a new one beyond this pushes out the one heard from longest ago
MAX_SOURCES = 16
_RECV_BUFFER = 65536  # the largest UDP datagram fits
_DUPLICATE_MEMORY = 4096  # keys of the last datagrams accepted, to know a repeated one
_EXPIRE_EVERY_S = 0.005
#: sequence numbers per source whose handed-on sample is remembered (a digest), to know a rival claimant
HANDED_MEMORY = 64
#: a handed-on sample's payload up to this size is kept for its digest, made only if its number is disputed
LAZY_DIGEST_BYTES = 4096
#: rival claimants held per number while it waits in the window (more are counted, not handed on)
MAX_RIVALS = 4
#: the reasons kept for refused payloads (:meth:`Receiver.refusals`); the counters count them all
MAX_REFUSALS_NOTED = 10


def multicast_group(source_number: int = 1) -> str:
    """OpenTrackIO's multicast group for a source number: 239.135.1.N (current documentation)."""
    lo, hi = SOURCE_NUMBERS
    if isinstance(source_number, bool) or not isinstance(source_number, int) or not lo <= source_number <= hi:
        raise InputError(f"source number must be {lo}..{hi}, got {shown(source_number)}")
    return f"239.135.1.{source_number}"


def check_port(port) -> int:
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise InputError(f"port must be a whole number 0..65535, got {shown(port)}")
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
    """A validated sample, its packet sequence number (unwrapped per source: it goes back when the
    source restarts), encoding and arrival time (monotonic s). ``conflict``: a second, different valid
    sample claiming a number that another sample of its source holds (module notes); handed on out of
    order, after that one, for the consumer to judge (:mod:`physcam.live.take`)."""

    sample: dict
    sequence: int
    encoding: str
    arrival_s: float
    conflict: bool = False


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
                raise InputError(f"{name} must be a whole number {lo}..{hi}, got {shown(v)}")
        if modulus not in (255, 256, "auto"):
            raise InputError(f"the Fletcher-16 modulus is 256, 255 or 'auto', got {shown(modulus)}")
        if not isinstance(reorder_timeout_s, (int, float)) or not 0.0 < reorder_timeout_s <= 10.0:
            raise InputError(f"reorder timeout must lie in (0, 10] s, got {shown(reorder_timeout_s)}")
        self.modulus = modulus
        self.reorder_window = reorder_window
        self.reorder_timeout_s = float(reorder_timeout_s)
        self.receive_buffer_bytes = receive_buffer_bytes
        self._queue: queue.Queue = queue.Queue(maxsize=queue_size)
        self._reassembler = Reassembler(max_pending=max_pending)
        self._counts = dict.fromkeys(COUNTERS, 0)
        self._refusals: list[str] = []
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._sock: socket.socket | None = None
        self._error: BaseException | None = None
        # ordering state: one _Stream per source, least recently heard first
        self._streams: dict[tuple, _Stream] = {}
        self._recent = deque(maxlen=_DUPLICATE_MEMORY)
        self._recent_set: set[int] = set()
        self._expired_at = 0.0
        self.high_water = {"window": 0, "queue": 0, "reassembly_bytes": 0, "sources": 0}
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
        """End the receiving thread and close the socket; the windows are handed on, and samples
        already in the queue stay readable."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        if self._sock is not None:
            self._sock.close()
            self._sock = None
        now = time.monotonic()
        for st in self._streams.values():
            self._flush(st, now, skip_all=True)
            self._drop_run(st)

    def __enter__(self) -> "Receiver":
        return self.start()

    def __exit__(self, *exc) -> bool:
        self.stop()
        return False

    @property
    def receive_buffer_granted_bytes(self) -> int | None:
        """The socket receive buffer the kernel gave (it caps ``receive_buffer_bytes`` at its own
        ``net.core.rmem_max``, and counts each datagram's overhead against it); None before start."""
        return None if self._sock is None else self._sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)

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
                    n, addr = sock.recvfrom_into(buf)
                except socket.timeout:
                    self._expire(time.monotonic())
                    continue
                except OSError:
                    if self._stop.is_set():
                        break
                    raise
                self._count("received")
                self._handle(view[:n], addr)
                now = time.monotonic()
                if now - self._expired_at > _EXPIRE_EVERY_S:
                    self._expire(now)
        except BaseException as exc:  # noqa: BLE001 - handed to the consumer, never lost in the thread
            self._error = exc

    # --- packets to samples --------------------------------------------------------------------
    def _repeated(self, key: int) -> bool:
        """True when a datagram with this key was accepted lately; else remember it."""
        if key in self._recent_set:
            return True
        if len(self._recent) == self._recent.maxlen:
            self._recent_set.discard(self._recent[0])
        self._recent.append(key)
        self._recent_set.add(key)
        return False

    def _handle(self, datagram, addr=None) -> None:
        try:
            header, piece = parse_packet(datagram, self.modulus)
        except PacketError as exc:
            self._count("wrong_checksum" if exc.kind == "checksum" else "malformed")
            return
        if self._repeated(hash((header.encoding, header.sequence, header.offset, header.last, piece))):
            self._count("duplicate")
            return
        try:
            done = self._reassembler.add(header, piece, source=addr)
        except PacketError as exc:
            self._count("duplicate" if exc.kind == "duplicate" else "malformed")
            return
        self.high_water["reassembly_bytes"] = max(self.high_water["reassembly_bytes"], self._reassembler.high_water_bytes)
        if done is None:
            return
        encoding, payload = done
        enc = ENCODINGS[encoding]
        try:
            obj = decode_sample(payload, enc, validate=False)
        except SampleError as exc:
            self._count("malformed")  # no sample, no source: the streams do not hear of it
            self._note(header.sequence, addr, exc.problems[0])
            return
        now = time.monotonic()
        key = _source_key(obj)
        lo, hi = SOURCE_NUMBERS
        try:
            problems = sample_problems(obj)
        except Exception as exc:  # noqa: BLE001 - no sample may end the take: a check that fails refuses it
            problems = [SampleProblem("$", "check", f"could not be checked ({type(exc).__name__})")]
        if not problems and key[1] is not None and not lo <= key[1] <= hi:
            problems = [SampleProblem("$.sourceNumber", "transport", f"source number {key[1]} is outside {lo}..{hi}")]
        if problems:
            self._count("invalid")
            self._note(header.sequence, addr, problems[0])
            if key in self._streams:  # its number is held as a gap a valid sample may still fill (a forged or
                self._place(key, header.sequence, None, now)  # corrupt copy must not cost the real frame)
            return
        self._place(key, header.sequence, _Arrived(obj, 0, enc, now, payload=payload), now)

    def _note(self, sequence: int, addr, problem) -> None:
        """Keep the reason a payload was refused, the first MAX_REFUSALS_NOTED of them (one line each)."""
        with self._lock:
            if len(self._refusals) < MAX_REFUSALS_NOTED:
                where = f" from {addr[0]}:{addr[1]}" if isinstance(addr, tuple) and len(addr) >= 2 else ""
                self._refusals.append(f"packet {sequence}{where}: {problem}")

    def refusals(self) -> list[str]:
        """Why the first payloads counted ``malformed`` (undecodable) or ``invalid`` were refused: at most
        MAX_REFUSALS_NOTED lines of at most about 300 characters (a received value is never shown whole)."""
        with self._lock:
            return list(self._refusals)

    # --- ordering, per source ----------------------------------------------------------------------
    def _place(self, key, seq: int, item, now: float) -> None:
        st = self._streams.pop(key, None)
        if st is None:
            if item is None:
                return
            if len(self._streams) >= MAX_SOURCES:  # the source heard from longest ago gives way
                old = self._streams.pop(next(iter(self._streams)))
                self._flush(old, now, skip_all=True)
                self._drop_run(old)
            st = _Stream(seq)
        self._streams[key] = st  # most recently heard last
        self.high_water["sources"] = max(self.high_water["sources"], len(self._streams))
        ext = st.next + (seq - st.next + 32768) % 65536 - 32768
        if st.next <= ext <= st.top + self.reorder_window:
            self._drop_run(st)  # the stream's own sample: an off-stream run was no restart
            if ext in st.window:
                held = st.window[ext]
                if held[1] is None and item is not None:  # a valid sample beats an invalid one's placeholder
                    st.window[ext] = (held[0], item)
                elif item is not None and _digest(item) not in map(_digest, (held[1], *st.rivals.get(ext, ()))):
                    self._count("conflict")  # two different valid samples, one number
                    rivals = st.rivals.setdefault(ext, [])
                    if len(rivals) < MAX_RIVALS:
                        rivals.append(item)  # handed on, flagged, right after the one held
                else:
                    self._count("duplicate")
            else:
                st.window[ext] = (now, item)
                st.top = max(st.top, ext)
                self.high_water["window"] = max(self.high_water["window"], len(st.window))
            self._flush(st, now)
        elif item is not None:  # an invalid sample off the stream is no evidence of anything
            self._off_stream(st, seq, ext, item, now)

    def _off_stream(self, st: "_Stream", seq: int, ext: int, item, now: float) -> None:
        """Start or extend the source's off-stream run; resynchronise when it shows a new stream.
        A straggler older than what was handed on is late at once (and taken back should its run
        resynchronise after all: a sender replaying old timestamps)."""
        stamp = _stamp(item)
        stale = ext < st.next and stamp is not None and st.stamp is not None and stamp <= st.stamp \
            and not self._rival(st, ext, item)  # a rival of a handed-on sample is counted when its run ends
        if stale:
            self._count("late")
        entry = (seq, ext, now, item, stale)
        if st.run and 1 <= (seq - st.run[-1][0]) % 65536 <= self.reorder_window:
            st.run.append(entry)
        else:
            self._drop_run(st)
            st.run = [entry]
        fresh = all(_stamp(r[3]) is None or st.stamp is None or _stamp(r[3]) > st.stamp for r in st.run)
        if (len(st.run) >= 2 and fresh) or len(st.run) >= max(2, self.reorder_window):
            self._resync(st, now)

    def _drop_run(self, st: "_Stream") -> None:
        """The run was no new stream: count its samples late or stray, except a different sample for a
        number already handed on, which is handed on flagged as a conflict (module notes)."""
        for _, ext, _, item, counted in st.run:
            if item is not None and not counted:
                if self._rival(st, ext, item):
                    self._count("conflict")
                    if len(st.handed[ext]) <= MAX_RIVALS:  # more are counted, not handed on (bounded)
                        st.handed[ext] = _handed(st, ext) + (_digest(item),)
                        self._hand_on(item, ext, conflict=True)
                elif ext < st.next and _digest(item) in _handed(st, ext):
                    self._count("duplicate")  # a sample handed on already, in another encoding
                else:
                    self._count("late" if ext < st.next else "stray")
        st.run = []

    @staticmethod
    def _rival(st: "_Stream", ext: int, item) -> bool:
        """Whether ``item`` is a different sample for the number ``ext`` that this source handed on lately."""
        return ext < st.next and ext in st.handed and _digest(item) not in _handed(st, ext)

    def _resync(self, st: "_Stream", now: float) -> None:
        """The run becomes the stream: hand on what the window holds, then number from the run's first."""
        self._flush(st, now, skip_all=True)
        run, st.run = st.run, []
        first = run[0][0]
        st.next = st.next + (first - st.next + 32768) % 65536 - 32768
        st.top = st.next - 1  # the old run's numbers are no longer the stream's
        for seq, _, arrived, item, counted in run:
            if counted:
                self._count("late", -1)
            ext = st.next + (seq - first) % 65536
            st.window[ext] = (arrived, item)
            st.top = max(st.top, ext)
        st.handed.clear()  # the numbers now name the new stream's samples
        self._count("resync")
        self._flush(st, now)

    def _deliver(self, st: "_Stream", ext: int) -> None:
        _, item = st.window.pop(ext)
        rivals = st.rivals.pop(ext, ())
        st.next = ext + 1
        if item is None:
            return
        stamp = _stamp(item)
        if stamp is not None:
            st.stamp = stamp if st.stamp is None else max(st.stamp, stamp)
        payload = getattr(item, "payload", None)  # its digest made when asked (_handed), the payload kept till then
        first = _Later(payload, item.encoding) if payload is not None and len(payload) <= LAZY_DIGEST_BYTES \
            else _digest(item)
        st.handed[ext] = (first, *map(_digest, rivals))
        if len(st.handed) > HANDED_MEMORY:
            del st.handed[next(iter(st.handed))]
        if self._hand_on(item, ext):
            self._count("delivered")
        for rival in rivals:
            self._hand_on(rival, ext, conflict=True)

    def _hand_on(self, item, ext: int, conflict: bool = False) -> bool:
        """Put one sample in the queue (numbered ``ext``); False (counted dropped) when the queue is full."""
        try:
            self._queue.put_nowait(ReceivedSample(item.sample, ext, item.encoding, item.arrival_s, conflict))
        except queue.Full:
            self._count("dropped")
            return False
        self.high_water["queue"] = max(self.high_water["queue"], self._queue.qsize())
        return True

    def _flush(self, st: "_Stream", now: float, skip_all: bool = False) -> None:
        """Hand on the window's samples that are next in order. Past a gap: wait while fewer than
        ``reorder_window`` samples wait and the oldest has waited less than the timeout, else (or with
        ``skip_all``: stopping, resynchronising) give the gap up as missing."""
        while st.window:
            held = st.window.get(st.next)
            if held is not None and held[1] is not None:
                self._deliver(st, st.next)
            elif skip_all or len(st.window) >= self.reorder_window \
                    or now - min(a for a, _ in st.window.values()) > self.reorder_timeout_s:
                if held is not None:  # an invalid sample's number, no valid one came for it: passed over
                    self._deliver(st, st.next)
                    continue
                ext = min(st.window)
                self._count("missing", ext - st.next)
                st.next = ext
            else:
                break  # a gap, or an invalid sample's number that its valid sample may still fill

    def _expire(self, now: float) -> None:
        """Windows whose oldest sample has waited the timeout give their gaps up."""
        self._expired_at = now
        for st in self._streams.values():
            if st.window:
                self._flush(st, now)


class _Stream:
    """One source's ordering state (module notes)."""

    __slots__ = ("next", "top", "window", "run", "stamp", "handed", "rivals")

    def __init__(self, first: int):
        self.next = first  # the next (unwrapped) sequence number to hand on
        self.top = first - 1  # the highest number seen on the stream
        self.window: dict[int, tuple] = {}  # number -> (arrival, ReceivedSample or None for an invalid one)
        self.run: list[tuple] = []  # off-stream samples that follow each other:
        # (seq, number, arrival, item, counted late already)
        self.stamp: int | None = None  # the newest sampleTimestamp handed on (ns)
        self.handed: dict[int, tuple] = {}  # number -> digests of the samples handed on, the last HANDED_MEMORY
        # (the first a _Later until it is asked for: _handed)
        self.rivals: dict[int, list] = {}  # number in the window -> other valid samples claiming it


def _source_key(obj) -> tuple:
    """(sourceId, sourceNumber) of a decoded sample; None for either one missing or of the wrong type."""
    if not isinstance(obj, dict):
        return (None, None)
    sid, num = obj.get("sourceId"), obj.get("sourceNumber")
    return (sid if isinstance(sid, str) else None,
            num if isinstance(num, int) and not isinstance(num, bool) else None)


def _digest(item) -> int:
    """A digest of a sample's content, whatever its encoding (JSON or CBOR of one sample digest alike)."""
    return _content_digest(item.sample)


def _content_digest(sample) -> int:
    return hash(json.dumps(sample, sort_keys=True, separators=(",", ":"), default=repr))


@dataclass(frozen=True)
class _Arrived(ReceivedSample):
    """A valid sample as the receiver holds it until it is handed on: with its payload (for :class:`_Later`)."""

    payload: bytes | None = None


class _Later:
    """The digest of a handed-on sample, made from its payload when first asked (:func:`_handed`)."""

    __slots__ = ("payload", "encoding")

    def __init__(self, payload: bytes, encoding: str):
        self.payload, self.encoding = payload, encoding

    def digest(self) -> int:
        """The sample's digest as :func:`_digest` made it when it was handed on: the payload decoded and
        checked again (a valid sample; the check turns CBOR's decimals and fractions into floats, in place,
        as it did then)."""
        sample = decode_sample(self.payload, self.encoding, validate=False)
        sample_problems(sample)
        return _content_digest(sample)


def _handed(st: "_Stream", ext: int) -> tuple:
    """The digests of the samples ``st`` handed on for number ``ext`` (empty if none), the first made now
    if it was left for later."""
    got = st.handed.get(ext, ())
    if got and isinstance(got[0], _Later):
        got = st.handed[ext] = (got[0].digest(), *got[1:])
    return got


def _stamp(item) -> int | None:
    """A handed-on sample's ``timing.sampleTimestamp`` in ns (validated), or None."""
    if item is None:
        return None
    ts = item.sample.get("timing", {}).get("sampleTimestamp")
    return None if ts is None else ts["seconds"] * 1_000_000_000 + ts["nanoseconds"]
