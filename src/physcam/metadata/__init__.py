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
    from ._text import encoding_of

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
    try:
        if encoding_of(head) == "utf-16":  # a whole number of code units; a pair cut at 4 kB is dropped
            text = head[: len(head) // 2 * 2].decode("utf-16", errors="ignore")
        else:
            text = head.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        if exc.start < len(head) - 4:  # not a character cut at the 4 kB boundary: binary
            raise MetadataError("a binary file that is not a Mo-Sys F4 recording (no 0xF4 packet with a valid "
                                "checksum at its start)", p, offset=0) from None
        text = head[: exc.start].decode("utf-8-sig")
    if "\0" in text:
        raise MetadataError("a binary file that is not a Mo-Sys F4 recording (no 0xF4 packet with a valid "
                            "checksum at its start)", p, offset=0)
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
    return check_record(record)
