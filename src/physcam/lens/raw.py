"""A lens file as written: its prescription read without validation, with the file line of each
surface (what ``physcam lens check`` inspects and ``lens fix`` repairs, and what the library reads
before it validates)."""

from __future__ import annotations

from dataclasses import dataclass

from .prescription import Prescription, unvalidated

__all__ = ["RawLens", "read_raw"]


@dataclass(frozen=True)
class RawLens:
    """A lens file's rows as written (not validated), with the file line of each surface."""

    prescription: Prescription
    path: str | None
    lines: tuple[int | None, ...]
    format: str | None = None

    def line(self, i: int | None) -> int | None:
        return self.lines[i] if (i is not None and 0 <= i < len(self.lines)) else None


def read_raw(path, format: str | None = None) -> RawLens:
    """Read a lens file without validating the prescription (the reader's syntax checks still
    apply: a file that is not a lens raises :class:`LensFileError` with file and line)."""
    from .formats import detect_format, loads_lens
    from .formats._common import read_text

    text = read_text(path)
    fmt = format or detect_format(path, text)
    with unvalidated() as seen:
        p = loads_lens(text, fmt, str(path))
    lines = seen[-1][2] if seen and seen[-1][2] is not None else [None] * len(p.surfaces)
    return RawLens(p, str(path), tuple(lines), fmt)
