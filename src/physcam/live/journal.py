"""The journal of a take being recorded: each sample on disk as it arrives, for a take to survive a
killed recorder, a power cut or a final write that fails.

Format ``physcam-live-journal/1``: UTF-8 JSON Lines, append-only, beside the output (``take.usda``
-> ``take.usda.journal``; ``take.usda.2.journal``, ``.3.`` ... when that name is taken). The first
line is the header::

    {"format": "physcam-live-journal/1", "output": "take.usda", "report": "take.csv",
     "started": "2025-01-01T12:00:00Z", "options": {...}}

(``output`` and ``report`` by name when they lie beside the journal, else whole paths; ``options``
the recording's settings, which ``physcam live recover`` uses again). Then one line per sample the
recorder took, the decoded and validated sample as sent::

    {"sequence": 17, "encoding": "cbor", "sample": {...}}

(with ``"conflict": true`` when the sample claimed a number another sample of its source held:
:mod:`physcam.live.take`, "Conflicts") and, now and then, ``{"counters": {...}}``: the receiver's
counters at that moment.

Writing: each line goes to the file in one ``write`` call of the process (no buffer of its own), so
a recorder killed by SIGKILL loses nothing it took; the file is synced to the disk (``fsync``) at
least every :data:`SYNC_INTERVAL_S` (0.5 s), on a thread of its own (a slow disk never holds up the
recorder), and when the take ends, so a power cut loses at most the last half-second (and what a
slow disk has not yet synced). A write that fails (disk full) is taken back (the file is cut to its last whole
line) and the journal stops there with one warning; the take goes on in memory. While it records,
the recorder holds an exclusive lock (``flock``) on its journal: a journal nobody holds belongs to a
take that did not finish (:func:`unfinished_journals`).

Reading (:class:`JournalReader`): a last line cut short by a power cut (no newline, or the zeros a
file system leaves) is left out and counted ``torn``; a line inside that does not parse is skipped
and counted ``skipped``; no line is held longer than :data:`MAX_LINE_BYTES`.
"""

from __future__ import annotations

import json
import os
import re
import threading
import time
from pathlib import Path

from ..errors import InputError, PhysCamError

__all__ = ["JOURNAL_FORMAT", "SYNC_INTERVAL_S", "Journal", "JournalReader", "unfinished_journals",
           "output_of_journal", "discard_journal"]

JOURNAL_FORMAT = "physcam-live-journal/1"
#: the longest time between two syncs of the journal to the disk while a take records (s)
SYNC_INTERVAL_S = 0.5
#: a journal line longer than this is not read (a sample is at most 64 KiB of payload)
MAX_LINE_BYTES = 1 << 20
_MAX_NAMES = 1000


def _candidates(output: Path):
    yield output.with_name(output.name + ".journal")
    for n in range(2, _MAX_NAMES):
        yield output.with_name(f"{output.name}.{n}.journal")


def output_of_journal(path) -> Path:
    """The output a journal was written beside: ``take.usda.journal`` and ``take.usda.3.journal`` ->
    ``take.usda``, in the journal's own folder."""
    p = Path(path)
    m = re.fullmatch(r"(.+?)(\.\d+)?\.journal", p.name)
    if not m:
        raise InputError(f"{p}: a journal's name ends in .journal (take.usda.journal)")
    return p.with_name(m.group(1))


def _lock(fd: int, *, wait: bool) -> bool:
    """Take the exclusive lock on an open journal; False when another process holds it."""
    try:
        import fcntl
    except ImportError:  # no flock (Windows): every journal counts as unfinished
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
    except OSError:
        return False
    return True


def _sync_folder(folder: Path) -> None:
    """Make a name created or removed in ``folder`` last through a power cut (POSIX; a no-op elsewhere)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def unfinished_journals(output) -> list[Path]:
    """The journals of ``output`` that no running recorder holds: takes that did not finish."""
    output = Path(output)
    pattern = re.compile(re.escape(output.name) + r"(\.\d+)?\.journal")
    try:
        names = sorted(e.name for e in os.scandir(output.parent if str(output.parent) else ".")
                       if pattern.fullmatch(e.name))
    except OSError:
        return []
    out = []
    for name in names:
        p = output.with_name(name)
        try:
            fd = os.open(p, os.O_RDONLY)
        except OSError:
            continue
        try:
            if _lock(fd, wait=False):
                out.append(p)
        finally:
            os.close(fd)
    return out


def discard_journal(path) -> None:
    """Remove a journal (and make its removal last): only once its take is safely written elsewhere."""
    try:
        Path(path).unlink()
    except FileNotFoundError:
        return
    _sync_folder(Path(path).parent)


class Journal:
    """An open journal being written (module notes); :meth:`create` makes one beside an output."""

    def __init__(self, path: Path, fd: int):
        self.path = path
        self._fd = fd
        self._size = 0
        self._synced_at = time.monotonic()
        self._dirty = False
        self.samples = 0
        #: why the journal stopped (the first failed write), or None while it keeps everything
        self.error: str | None = None
        # the periodic fsync runs on a thread of its own: a slow disk never holds up the recorder
        self._due = threading.Event()
        self._closing = False
        self._syncer: threading.Thread | None = None

    @classmethod
    def create(cls, output, header: dict) -> "Journal":
        """Create the first free journal name beside ``output`` (exclusively), lock it, write the header."""
        output = Path(output)
        try:
            output.parent.mkdir(parents=True, exist_ok=True)  # as the output's own write would
        except OSError as exc:
            raise PhysCamError(f"cannot create the folder {output.parent} of the take: {exc.strerror or exc}") from None
        for p in _candidates(output):
            try:
                fd = os.open(p, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_APPEND, 0o644)
            except FileExistsError:
                continue
            except OSError as exc:
                raise PhysCamError(f"cannot create the take's journal {p}: {exc.strerror or exc}") from None
            _lock(fd, wait=True)
            journal = cls(p, fd)
            journal._append({"format": JOURNAL_FORMAT, **header})
            if journal.error is not None:
                journal.discard()
                raise PhysCamError(f"cannot write the take's journal {p}: {journal.error}")
            journal.sync(force=True)
            _sync_folder(p.parent)
            return journal
        raise PhysCamError(f"no free journal name beside {output} ({_MAX_NAMES} taken)")

    def _append(self, record: dict) -> bool:
        if self.error is not None or self._fd is None:
            return False
        try:
            data = (json.dumps(record, separators=(",", ":"), allow_nan=False) + "\n").encode("utf-8")
        except (TypeError, ValueError):  # not JSON (a validated sample always is): this record only is left out
            return False
        view, done = memoryview(data), 0
        try:
            while done < len(data):
                done += os.write(self._fd, view[done:])
        except OSError as exc:
            try:
                os.ftruncate(self._fd, self._size)  # no half line stays behind
            except OSError:
                pass
            self.error = exc.strerror or str(exc)
            return False
        self._size += len(data)
        self._dirty = True
        return True

    def add_sample(self, sample: dict, sequence: int, encoding: str, conflict: bool = False) -> bool:
        """Append one taken sample (``conflict``: a rival claimant of its number); False when the journal
        has stopped (:attr:`error`)."""
        line = {"sequence": sequence, "encoding": encoding, "sample": sample}
        if conflict:
            line["conflict"] = True
        ok = self._append(line)
        self.samples += ok
        return ok

    def add_counters(self, counters: dict) -> None:
        self._append({"counters": counters})

    def sync(self, *, force: bool = False) -> None:
        """Sync what was written to the disk once :data:`SYNC_INTERVAL_S` has passed since the last
        sync (on the journal's own thread), or now, in this thread, with ``force``."""
        now = time.monotonic()
        if self._fd is None or not self._dirty or (not force and now - self._synced_at < SYNC_INTERVAL_S):
            return
        self._synced_at, self._dirty = now, False
        if force:
            self._fsync()
            return
        if self._syncer is None:
            self._syncer = threading.Thread(target=self._sync_when_due, name="physcam-journal-sync", daemon=True)
            self._syncer.start()
        self._due.set()

    def _fsync(self) -> None:
        try:
            os.fsync(self._fd)
        except OSError as exc:
            self.error = self.error or (exc.strerror or str(exc))

    def _sync_when_due(self) -> None:
        while True:
            self._due.wait()
            self._due.clear()
            if self._closing:
                return
            self._fsync()

    def _stop_syncing(self) -> None:
        if self._syncer is not None:
            self._closing = True
            self._due.set()
            self._syncer.join()
            self._syncer = None

    def close(self) -> None:
        """Sync and close; the file stays (and its lock goes: it is unfinished until discarded)."""
        if self._fd is not None:
            self._stop_syncing()
            self._dirty = True
            self.sync(force=True)
            os.close(self._fd)
            self._fd = None

    def discard(self) -> None:
        """Close and remove the journal: only once the take is safely written elsewhere."""
        if self._fd is not None:
            self._stop_syncing()
            os.close(self._fd)
            self._fd = None
        discard_journal(self.path)


class JournalReader:
    """Read a journal (module notes): :attr:`header`, then iterate for ``("sample", sequence,
    encoding, sample, conflict)`` and ``("counters", counters)``; :attr:`torn` and :attr:`skipped` count the
    lines left out once iteration ends."""

    def __init__(self, path):
        self.path = Path(path)
        try:
            if not self.path.is_file():  # a FIFO or a device would hang or never end
                raise InputError(f"{self.path}: not a journal file (a take's journal is a regular file)")
            self._fh = open(self.path, "rb")
        except OSError as exc:
            raise InputError(f"cannot read the journal {self.path}: {exc.strerror or exc}") from None
        first = self._fh.readline(MAX_LINE_BYTES)
        try:
            header = json.loads(first)
        except ValueError:
            header = None
        if not isinstance(header, dict) or header.get("format") != JOURNAL_FORMAT:
            self._fh.close()
            raise InputError(f"{self.path}:1: not a physcam take journal ({JOURNAL_FORMAT})")
        self.header = header
        self.torn = self.skipped = 0

    def locked(self) -> bool:
        """Whether a running recorder holds this journal (it is still being written)."""
        return not _lock(self._fh.fileno(), wait=False)

    def __iter__(self):
        try:
            while True:
                line = self._fh.readline(MAX_LINE_BYTES + 1)
                if not line:
                    return
                record = _parse(line) if len(line) <= MAX_LINE_BYTES else None
                while not line.endswith(b"\n") and (more := self._fh.readline(MAX_LINE_BYTES)):
                    line = more  # the rest of an overlong line: skipped
                if record is not None:
                    yield record
                elif self._fh.peek(1):
                    self.skipped += 1  # a damaged line with more after it
                else:
                    self.torn += 1  # the end of the file: a write a power cut cut short
        finally:
            self._fh.close()


def _parse(line: bytes):
    try:
        obj = json.loads(line)
    except ValueError:
        return None
    if not isinstance(obj, dict):
        return None
    if isinstance(obj.get("sample"), dict) and isinstance(obj.get("sequence"), int) \
            and obj.get("encoding") in ("json", "cbor"):
        return ("sample", obj["sequence"], obj["encoding"], obj["sample"], obj.get("conflict") is True)
    if isinstance(obj.get("counters"), dict):
        return ("counters", obj["counters"])
    return None
