"""physcam.metadata: camera metadata recorded with real clips, read into one :class:`ClipRecord`.

One module per source (``arri``, ``arri_json``, ``red`` with ``cooke``, ``venice``, ``canon``, ``bmd``,
``mosys``);
:func:`detect` tells the format of each file from its content (never its name), :func:`load`
reads the files of one clip (RED's static and frames CSVs, VENICE's CSV and XML, Canon's two
CSVs) into a :class:`ClipRecord`, every value checked against what a camera can record
(:mod:`.limits`). ``convert`` turns a record into tracked frames, lens reports,
an animated USD camera (through ``physcam.live.record``) and OpenTrackIO samples.
Layer 8.5, beside ``live`` (docs/architecture.md); the readers need no optional extra.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import MetadataError
from .record import ClipRecord, CookeData, FrameSample, TrackerPose

__all__ = ["ClipRecord", "CookeData", "FrameSample", "TrackerPose", "detect", "detect_file", "load", "FORMATS"]

#: the sources physcam reads, and what each is
FORMATS = {"arri": "ARRI Meta Extract CSV (tab-separated, or a copy with commas or semicolons; one row per frame)",
           "arri-json": "ARRI Reference Tool JSON (metadata_output v2: clip and per-frame metadata sets)",
           "red": "REDline --printMeta 5 frames CSV (+ --printMeta 3 static CSV)",
           "venice": "Sony VENICE per-frame CSV (+ NonRealTimeMeta XML)",
           "canon": "Canon per-frame CSV (+ static CSV)",
           "bmd": "Blackmagic RAW SDK ExtractMetadata text",
           "mosys": "Mo-Sys StarTracker F4 recording (binary)"}


def detect_file(path) -> tuple[str, str]:
    """(format, role) of one file from its first bytes: role "frames" (the per-frame file),
    "static" (RED's or Canon's static CSV) or "xml" (VENICE's). Unknown content is a MetadataError."""
    from . import arri, arri_json, bmd, canon, mosys, red, venice

    p = Path(path)
    try:
        with open(p, "rb") as fh:
            head = fh.read(4096)
    except OSError as exc:
        raise MetadataError(f"cannot read it ({exc.strerror or exc})", p) from None
    if not head:
        raise MetadataError("the file is empty", p, 1)
    if mosys.sniff(head):
        return "mosys", "frames"
    text = _head_text(p, head)
    if arri_json.sniff(text):
        return "arri-json", "frames"
    first = text.splitlines()[0] if text.splitlines() else ""
    if arri.sniff(first):
        return "arri", "frames"
    for name, mod in (("red", red), ("canon", canon)):
        role = mod.sniff(first)
        if role:
            return name, role
    role = venice.sniff(text)
    if role:
        return "venice", "frames" if role == "csv" else "xml"
    if bmd.sniff(text):
        return "bmd", "frames"
    missing = _missing_columns(first)
    if missing:
        raise MetadataError(missing, p, 1)
    raise MetadataError("unknown column layout: not an ARRI Meta Extract or ARRI Reference Tool JSON, REDline, "
                        "VENICE, Canon, Blackmagic ExtractMetadata or Mo-Sys F4 file", p, 1)


_NOT_MOSYS = "a binary file that is not a Mo-Sys F4 recording (no 0xF4 packet with a valid checksum at its start)"


def _head_text(p: Path, head: bytes) -> str:
    """The first bytes of a text file as text (UTF-8, or UTF-16 after its byte-order mark), else a
    MetadataError at the first byte that is not: a NUL byte (binary, or UTF-16 saved without its
    byte-order mark: ASCII text with every other byte 0) or a byte UTF-8 does not allow (a Latin-1 or
    Windows-1252 export: "é" is the one byte 0xE9), named by its offset and line."""
    from ._text import encoding_of, not_utf8

    if encoding_of(head) == "utf-16":  # a whole number of code units; a pair cut at 4 kB is dropped
        return head[: len(head) // 2 * 2].decode("utf-16", errors="ignore")
    nul = head.find(b"\0")
    if nul >= 0:
        for order, text, zeros in (("little", head[0:64:2], head[1:64:2]), ("big", head[1:64:2], head[0:64:2])):
            if len(head) >= 8 and not zeros.strip(b"\0") and all(9 <= b < 127 for b in text):
                raise MetadataError(f"UTF-16 ({order}-endian) text without a byte-order mark, not UTF-8 text: "
                                    "save it as UTF-8 (or UTF-16 with its byte-order mark)", p, offset=nul)
        raise MetadataError(_NOT_MOSYS, p, offset=nul)
    bom = 3 if head.startswith(b"\xef\xbb\xbf") else 0
    try:
        return head[bom:].decode("utf-8")
    except UnicodeDecodeError as exc:
        at = bom + exc.start
        if len(head) == 4096 and at >= len(head) - 3 and exc.reason == "unexpected end of data":
            return head[bom:at].decode("utf-8")  # a character cut at the 4 kB boundary
        raise not_utf8(p, head[at], at, head[:at].count(b"\n") + 1) from None


def _missing_columns(first_line: str) -> str | None:
    """What a header that has a per-frame CSV layout's own columns (its reader's ``LAYOUT_MARKERS``) but not
    all it needs (``LAYOUT_GROUPS``, one of each group) lacks, in words; else None."""
    from . import arri, canon, red, venice
    from ._text import header_columns, lacking_columns

    layouts = (("an ARRI Meta Extract CSV", arri), ("a REDline frames CSV", red), ("a Canon per-frame CSV", canon),
               ("a Sony VENICE per-frame CSV", venice))
    for delimiter in arri.DELIMITERS:
        cols = set(header_columns(first_line, delimiter))
        for what, reader in layouts:
            if any(m in cols for m in reader.LAYOUT_MARKERS):
                lacking = [" or ".join(repr(n + ("...)" if n.endswith("(") else "")) for n in g)
                           for g in lacking_columns(cols, reader.LAYOUT_GROUPS)]
                if not lacking:  # every column of this layout: not another layout's file missing columns
                    break
                return f"the header looks like {what} but has no {', no '.join(lacking)} column"
    return None


def detect(paths) -> str:
    """The one format of the files of a clip (each detected from its content)."""
    found = {detect_file(p)[0] for p in _paths(paths)}
    if len(found) > 1:
        raise MetadataError(f"the files are of different formats ({', '.join(sorted(found))}); give one clip's files")
    return found.pop()


def _paths(paths) -> list[Path]:
    if isinstance(paths, (str, Path)):
        paths = [paths]
    out = [Path(p) for p in paths]
    if not out:
        raise MetadataError("no metadata file given")
    return out


def load(paths) -> ClipRecord:
    """Read one clip's metadata files (one path or several) into a :class:`ClipRecord`."""
    from . import arri, arri_json, bmd, canon, mosys, red, venice
    from .limits import check_record

    files = _paths(paths)
    roles: dict = {}
    fmt = None
    for p in files:
        f, role = detect_file(p)
        if fmt is not None and f != fmt:
            raise MetadataError(f"{p} is a {f} file, the others {fmt}; give one clip's files")
        fmt = f
        if role in roles:
            raise MetadataError(f"two {f} {role} files ({roles[role]} and {p}); give one clip's files")
        roles[role] = p
    if "frames" not in roles:
        raise MetadataError(f"only the {fmt} {', '.join(roles)} file: give the per-frame file too", files[0])
    single = {"arri": arri.read, "arri-json": arri_json.read, "bmd": bmd.read, "mosys": mosys.read}
    if fmt in single:
        record = single[fmt](roles["frames"])
    elif fmt == "venice":
        record = venice.read(roles["frames"], roles.get("xml"))
    else:
        record = {"red": red.read, "canon": canon.read}[fmt](roles["frames"], roles.get("static"))
    if not record.drop_frame and any(f.timecode is not None and ";" in f.timecode for f in record.frames):
        from dataclasses import replace

        record = replace(record, drop_frame=True)  # a ";" timecode is drop-frame, whatever the format
    return check_record(record)
