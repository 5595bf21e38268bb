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
when two cameras were on one port. A sample physcam cannot read as a frame (a transform chain with
no orientation, a distance beyond millimetres) is refused with its reason and counted; the first
:data:`MAX_REFUSALS_KEPT` reasons are kept. Bounded: at most ``max_frames`` frames in all, and
:data:`MAX_SOURCES_NAMED` sources by name (the samples of further ones are counted together).
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import ExportError, InputError, PhysCamError, require_type
from .record import MAX_RECORDED_FRAMES

__all__ = ["Take", "MAX_SOURCES_NAMED", "MAX_REFUSALS_KEPT", "same_source_id", "free_names", "write_under_free_name"]

#: sources a take names one by one; the samples of any further source are counted together
MAX_SOURCES_NAMED = 64
#: reasons kept for refused samples (all are counted)
MAX_REFUSALS_KEPT = 100


def same_source_id(given: str, source_id) -> bool:
    """Whether ``source_id`` (a sample's) is the ``given`` one: ``urn:uuid:`` optional, case ignored."""
    require_type("given", given, str)
    if not isinstance(source_id, str):
        return False
    strip = lambda t: t.strip().lower().removeprefix("urn:uuid:")  # noqa: E731
    return strip(given) == strip(source_id)


class _Source:
    __slots__ = ("key", "order", "frames", "samples", "refused", "static")

    def __init__(self, key: tuple, order: int):
        self.key, self.order = key, order
        self.frames: list = []
        self.samples = self.refused = 0
        self.static = None


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

    def add(self, sample: dict, sequence: int | None = None):
        """Take one validated sample; return its frame, or None (refused, another source's, or full)."""
        from .frames import frame_from_sample

        key = (sample.get("sourceId"), sample.get("sourceNumber"))
        src = self._sources.get(key)
        if src is None:
            if len(self._sources) >= MAX_SOURCES_NAMED:
                self.unlisted_samples += 1
                return None
            src = self._sources[key] = _Source(key, len(self._sources))
        src.samples += 1
        if "static" in sample:
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
        src.frames.append(frame)
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
        """The frames of the source the take records, in the order they arrived."""
        key = self.chosen()
        return [] if key is None else list(self._sources[key].frames)

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
