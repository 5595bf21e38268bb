"""Frame ranges of a farm job: ``FIRST-LAST`` as every farm manager writes it, and its chunks.

A range is inclusive at both ends (``1001-1004`` is four frames), as Deadline's, OpenCue's and Open
Job Description's frame lists are; a single frame is ``1001`` (OpenJD renders a one-frame chunk so).
A *chunk* is the run of consecutive frames one task does; :func:`chunks` cuts a range into chunks
of ``size`` frames, the last one shorter, covering every frame exactly once.
"""

from __future__ import annotations

import re

from ..errors import InputError

__all__ = ["MAX_FRAME", "parse_frames", "frames_text", "chunks"]

#: Largest frame number (farm managers store frames as 32-bit integers).
MAX_FRAME = 2**31 - 1

_RANGE = re.compile(r"^\s*(\d{1,10})\s*(?:-\s*(\d{1,10})\s*)?$")


def parse_frames(text) -> tuple[int, int]:
    """``"FIRST-LAST"`` or ``"FRAME"`` as (first, last), first <= last, both from 0 to :data:`MAX_FRAME`."""
    if not isinstance(text, str):
        raise InputError(f"a frame range is text such as 1001-1100, got {text!r}")
    m = _RANGE.match(text)
    if not m:
        raise InputError(f"a frame range is FIRST-LAST (e.g. 1001-1100) or one frame (1001), got {text!r}")
    first = int(m.group(1))
    last = int(m.group(2)) if m.group(2) is not None else first
    if last > MAX_FRAME:
        raise InputError(f"frame numbers go up to {MAX_FRAME}, got {text!r}")
    if last < first:
        raise InputError(f"a frame range runs from its first frame to its last, got {text!r}")
    return first, last


def frames_text(first: int, last: int) -> str:
    """(first, last) as ``FIRST-LAST``."""
    return f"{first}-{last}"


def chunks(first: int, last: int, size: int) -> list[tuple[int, int]]:
    """The range first..last (inclusive) cut into runs of ``size`` frames, in order; the last may be shorter."""
    if isinstance(size, bool) or not isinstance(size, int) or size < 1:
        raise InputError(f"a chunk is a whole number of frames >= 1, got {size!r}")
    if last < first:
        raise InputError(f"a frame range runs from its first frame to its last, got {first}-{last}")
    return [(a, min(a + size - 1, last)) for a in range(first, last + 1, size)]
