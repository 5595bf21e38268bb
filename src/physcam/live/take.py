"""A take: the frames a recording keeps, one time line per source, and the one source it records.

Every sample the receiver hands on is taken as a :class:`~physcam.live.frames.TrackedFrame` of its
source, the stream's (``sourceId``, ``sourceNumber``), with the last ``static`` block **of that
source**. A take records one source, chosen by this rule:

* ``source`` given (``physcam live record --source ID``): the source whose ``sourceId`` is ID (the
  first heard, should ID come with several source numbers); other sources' samples are counted,
  not kept;
* else the source with the most frames, the first heard of those tied. A stray sample from
  another source (another camera on the port, a sender replaying old data, a clock a day ahead)
  never becomes the take, and never touches its time line.

The other sources are named with their sample counts (:meth:`Take.sources`), so a recording says
when two cameras were on one port.

**Conflicts.** UDP cannot be authenticated: a second, different valid sample may claim a packet number
its source has already used (a forged or replayed copy, a second sender with the same sourceId). The
receiver hands it on flagged (:attr:`~physcam.live.receiver.ReceivedSample.conflict`); the take holds
every claimant of the number and keeps the one its neighbours vouch for (:func:`judge_claimants`): the
nearest frames before and after it, on each clock both carry (``sampleTimestamp`` at the sample rate,
the timecode), lie exactly as many frames away as their packet numbers say. A claimant that any clock
contradicts is left out; when not exactly one claimant agrees (both do: a copy with the same clocks;
none does; no neighbour or clock to judge by), the take keeps **neither** and the frame is absent
(counted in ``missing``). Each conflict is named (:meth:`Take.conflicts`), never counted as late.

A sample physcam cannot read as a frame (a transform chain with no orientation, a distance beyond
millimetres) is refused with its reason and counted; the first :data:`MAX_REFUSALS_KEPT` reasons
are kept. Bounded: at most ``max_frames`` frames in all (and :data:`MAX_CLAIMANTS` rivals of each),
and :data:`MAX_SOURCES_NAMED` sources by name (the samples of further ones are counted together).
"""

from __future__ import annotations

import os
from fractions import Fraction
from pathlib import Path

from ..errors import ExportError, InputError, PhysCamError, require_type
from .record import MAX_RECORDED_FRAMES

__all__ = ["Take", "MAX_SOURCES_NAMED", "MAX_REFUSALS_KEPT", "same_source_id", "free_names", "write_under_free_name",
           "judge_claimants"]

#: sources a take names one by one; the samples of any further source are counted together
MAX_SOURCES_NAMED = 64
#: reasons kept for refused samples (all are counted)
MAX_REFUSALS_KEPT = 100
#: claimants a take holds for one packet number besides the first (the receiver hands on at most 4)
MAX_CLAIMANTS = 8


def same_source_id(given: str, source_id) -> bool:
    """Whether ``source_id`` (a sample's) is the ``given`` one: ``urn:uuid:`` optional, case ignored."""
    require_type("given", given, str)
    if not isinstance(source_id, str):
        return False
    strip = lambda t: t.strip().lower().removeprefix("urn:uuid:")  # noqa: E731
    return strip(given) == strip(source_id)


class _Source:
    __slots__ = ("key", "order", "frames", "samples", "refused", "static", "numbers", "ids", "at", "rivals")

    def __init__(self, key: tuple, order: int):
        self.key, self.order = key, order
        self.frames: list = []
        self.numbers: list = []  # each frame's packet number (the receiver's, unwrapped)
        self.ids: list = []  # each frame's sampleId
        self.at: dict = {}  # packet number -> index of the latest frame with it
        self.rivals: dict = {}  # frame index -> [(frame, sampleId)] other claimants of its number
        self.samples = self.refused = 0
        self.static = None


def _places(frame):
    """(clock name, place in frames) of each clock a frame carries: its sampleTimestamp at the sample
    rate, its timecode (drop-frame counted); packet numbers count one a frame."""
    from .frames import timecode_index

    out = []
    if frame.rate is not None and frame.time_ns is not None:
        out.append(("sampleTimestamp", Fraction(frame.time_ns, 1_000_000_000) * frame.rate))
    if frame.rate is not None and frame.timecode is not None:
        try:
            out.append(("timecode", timecode_index(frame.timecode, frame.rate, frame.drop_frame)))
        except PhysCamError:
            pass
    return out


def judge_claimants(claimants, neighbours):
    """Which of several frames claiming one packet number to keep: ``claimants`` and ``neighbours``
    are (frame, packet number) pairs, the neighbours the nearest undisputed frames before and after.
    A claimant agrees with a neighbour on a clock both carry when their places differ by exactly the
    packet numbers' difference (:func:`_places`; a timestamp to the nearest frame). Returns (index of
    the one claimant no clock contradicts and at least one confirms, or None; a reason in words)."""
    verdicts = []
    for frame, number in claimants:
        agree = disagree = 0
        mine = dict(_places(frame))
        for other, n in neighbours:
            for clock, place in _places(other):
                if clock in mine:
                    if round(mine[clock] - place) == number - n:
                        agree += 1
                    else:
                        disagree += 1
        verdicts.append((agree, disagree))
    good = [i for i, (a, d) in enumerate(verdicts) if a and not d]
    if len(good) == 1:
        return good[0], "the only one whose clocks agree with its neighbours'"
    if not neighbours:
        return None, "no undisputed neighbour to judge by"
    if good:
        return None, "more than one agrees with its neighbours' clocks"
    return None, "none agrees with its neighbours' clocks"


class Take:
    """The frames of a recording, per source (module notes)."""

    def __init__(self, source: str | None = None, *, max_frames: int = MAX_RECORDED_FRAMES):
        if source is not None and (not isinstance(source, str) or not source.strip()):
            raise InputError(f"a source is a sourceId (urn:uuid:...), got {source!r:.60}")
        if isinstance(max_frames, bool) or not isinstance(max_frames, int) or not 1 <= max_frames <= MAX_RECORDED_FRAMES:
            raise InputError(f"max_frames must be 1..{MAX_RECORDED_FRAMES}")
        self.source = source
        self.max_frames = max_frames
        self._sources: dict[tuple, _Source] = {}
        self.unlisted_samples = 0  # samples of sources beyond MAX_SOURCES_NAMED
        self.held = 0
        self.refused = 0
        self.refusals: list[str] = []

    @property
    def full(self) -> bool:
        """Whether the take holds ``max_frames`` frames (the recording ends there)."""
        return self.held >= self.max_frames

    def add(self, sample: dict, sequence: int | None = None, conflict: bool = False):
        """Take one validated sample; return its frame, or None (refused, another source's, or full).
        ``conflict``: it claims ``sequence``, a number another sample of its source holds (module notes)."""
        from .frames import frame_from_sample

        key = (sample.get("sourceId"), sample.get("sourceNumber"))
        src = self._sources.get(key)
        if src is None:
            if len(self._sources) >= MAX_SOURCES_NAMED:
                self.unlisted_samples += 1
                return None
            src = self._sources[key] = _Source(key, len(self._sources))
        src.samples += 1
        held_at = src.at.get(sequence) if conflict else None
        if "static" in sample and held_at is None:  # a rival claimant's static block changes nothing
            src.static = sample["static"]
        if self.full or (self.source is not None and src is not self._named()):
            return None
        try:
            frame = frame_from_sample(sample, static=src.static)
        except PhysCamError as exc:
            src.refused += 1
            self.refused += 1
            if len(self.refusals) < MAX_REFUSALS_KEPT:
                number = sample.get("timing", {}).get("sequenceNumber", sequence)
                self.refusals.append(f"sample {number}: {exc}")
            return None
        if held_at is not None:  # a rival claimant: judged against its neighbours when the take is read
            rivals = src.rivals.setdefault(held_at, [])
            if len(rivals) < MAX_CLAIMANTS:
                rivals.append((frame, sample.get("sampleId")))
            return frame
        src.at[sequence] = len(src.frames)
        src.frames.append(frame)
        src.numbers.append(sequence)
        src.ids.append(sample.get("sampleId"))
        self.held += 1
        return frame

    def _named(self):
        """The first source heard whose sourceId is :attr:`source`, or None."""
        return next((s for s in self._sources.values() if same_source_id(self.source, s.key[0])), None)

    def chosen(self):
        """The key (sourceId, sourceNumber) of the source the take records (module notes), or None."""
        if self.source is not None:
            named = self._named()
            return None if named is None else named.key
        best = max(self._sources.values(), key=lambda s: (len(s.frames), -s.order), default=None)
        return None if best is None or not best.frames else best.key

    def count(self) -> int:
        """Frames of the source the take records, so far."""
        key = self.chosen()
        return 0 if key is None else len(self._sources[key].frames)

    def frames(self) -> list:
        """The frames of the source the take records, in the order they arrived; of claimants of one
        packet number, the one :func:`judge_claimants` keeps, or none."""
        key = self.chosen()
        if key is None:
            return []
        src = self._sources[key]
        kept = {i: c["kept_index"] for i, c in self._judged(src)}  # None: neither claimant
        out = []
        for i, f in enumerate(src.frames):
            k = kept.get(i, 0)
            if k is not None:
                out.append(f if k == 0 else src.rivals[i][k - 1][0])
        return out

    def conflicts(self) -> list[dict]:
        """The packet numbers of the recorded source that several different samples claimed: ``sequence``,
        ``claimants`` (sampleId and timecode of each, first arrived first), ``kept`` (a sampleId or None)
        and ``reason`` (module notes)."""
        key = self.chosen()
        if key is None:
            return []
        return [{k: v for k, v in c.items() if k != "kept_index"} for _, c in self._judged(self._sources[key])]

    @staticmethod
    def _judged(src) -> list[tuple[int, dict]]:
        out = []
        disputed = set(src.rivals)
        for i in sorted(src.rivals):
            claimants = [(src.frames[i], src.ids[i])] + src.rivals[i]
            before = next((j for j in range(i - 1, -1, -1) if j not in disputed), None)
            after = next((j for j in range(i + 1, len(src.frames)) if j not in disputed), None)
            neighbours = [(src.frames[j], src.numbers[j]) for j in (before, after) if j is not None]
            k, reason = judge_claimants([(f, src.numbers[i]) for f, _ in claimants], neighbours)
            out.append((i, {"sequence": src.numbers[i], "source_id": src.key[0],
                            "claimants": [{"sample_id": sid, "timecode": f.timecode} for f, sid in claimants],
                            "kept": None if k is None else claimants[k][1], "kept_index": k, "reason": reason}))
        return out

    def sources(self) -> list[dict]:
        """Every source heard, first heard first: ``source_id``, ``source_number``, ``samples``
        received, ``refused`` of them, and ``recorded`` (the one the take records)."""
        chosen = self.chosen()
        return [{"source_id": s.key[0], "source_number": s.key[1], "samples": s.samples, "refused": s.refused,
                 "recorded": s.key == chosen} for s in sorted(self._sources.values(), key=lambda s: s.order)]


def free_names(path, limit: int = 1000):
    """``path``, then ``take-1.usda``, ``take-2.usda`` ... beside it (``limit`` names in all)."""
    p = Path(path)
    yield p
    for n in range(1, limit):
        yield p.with_name(f"{p.stem}-{n}{p.suffix}")


def write_under_free_name(write, path, *, force: bool = False) -> Path:
    """``write(name, force)`` under ``path``, or, when that name is taken (before the call or while it
    writes: another process won it), under the first free name of :func:`free_names`; return the
    Path written. ``force`` overwrites ``path`` itself (never another name); a write that fails for
    another reason (a full disk) raises its ExportError."""
    asked = Path(path)
    for p in free_names(asked):
        mine = force and p == asked
        if os.path.lexists(p) and not mine:
            continue
        try:
            return Path(write(p, mine))
        except ExportError:
            if mine or not os.path.lexists(p):
                raise
    raise ExportError(f"{asked} and the next 999 names beside it are taken")
