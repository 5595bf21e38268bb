"""``physcam live record`` and ``physcam live recover``: a take received, kept in a journal while it
records, and written as a USD camera and a lens report (docs/live.md, "Recording a take").

Before the first packet is read every option is checked and every file it names is opened (the
sensor, ``--lens``, ``--fiz``, the output names): a bad one exits 2 at once. The take records one
source (:mod:`physcam.live.take`), each sample goes to the journal as it arrives
(:mod:`physcam.live.journal`), and at the end the files are written: under the asked names, or, when
one was taken meanwhile, under the first free name beside it (``take-1.usda``), said on stderr and
in the summary. When a write fails (a full disk), the journal stays and the error says how to
recover the take from it; the journal is removed only once every file is written.
"""

from __future__ import annotations

import argparse
import sys
import time
from shlex import quote
from dataclasses import dataclass
from pathlib import Path

from ._output import document, emit_json

#: the receiver's counters are written to the journal this often (s)
_COUNTERS_EVERY_S = 1.0


def source_id(text):
    """An argparse type: a sourceId, ``urn:uuid:`` and a UUID (the prefix may be left out)."""
    import re

    t = str(text).strip().lower()
    hexes = r"[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}"
    if not re.fullmatch(rf"(urn:uuid:)?{hexes}", t):
        raise argparse.ArgumentTypeError(f"a source is a sourceId such as urn:uuid:{'0' * 8}-0000-4000-8000-"
                                         f"{'0' * 12}, got {text[:60]!r}")
    return t if t.startswith("urn:uuid:") else "urn:uuid:" + t


def resolve_sensor_opt(args):
    """The sensor the options name (--sensor, or --sensor-width and --sensor-height), or None."""
    if args.sensor is None and args.sensor_width is None and args.sensor_height is None:
        return None
    from .report import resolve_sensor

    return resolve_sensor(args)


@dataclass
class Settings:
    """What a take is written with, checked and loaded before anything is received."""

    file: str
    report: str | None
    force: bool
    options: dict  # as the journal keeps them (names and numbers, not objects)
    sensor: object = None
    lens: object = None
    fiz: object = None


#: the options a journal keeps and ``live recover`` uses again (argparse dest names)
KEPT_OPTIONS = ("sensor", "sensor_width", "sensor_height", "focal", "fstop", "focus", "fps", "lens", "fiz",
                "meters_per_unit", "path", "source")


def settings(args, kept: dict | None = None, *, check_outputs: bool = True) -> Settings:
    """Check every option and load every file it names (``kept``: a journal's options, which the
    arguments given override; ``check_outputs``: refuse output names that exist, without --force).
    Raises a PhysCamError in one line before anything is received."""
    from ..errors import InputError
    from ..io import check_writable
    from ..usd_names import usd_layer_format

    opts = dict(kept or {})
    for name in KEPT_OPTIONS:
        if getattr(args, name, None) is not None:
            opts[name] = getattr(args, name)
    ns = argparse.Namespace(**{k: opts.get(k) for k in KEPT_OPTIONS})
    sensor = resolve_sensor_opt(ns)
    if opts.get("focus") is not None and not isinstance(opts["focus"], (int, float)):
        from ._common import resolve_focus
        from .report import resolve_sensor

        opts["focus"] = resolve_focus(opts["focus"], focal_length_mm=opts.get("focal"), fstop=opts.get("fstop"),
                                      sensor=sensor or resolve_sensor(ns), args=ns)
    lens = fiz = None
    if opts.get("lens"):
        from ..lens.library import load_lens

        lens = load_lens(opts["lens"])
        if Path(opts["lens"]).is_file():  # a file is named by its whole path: recover may run elsewhere
            opts["lens"] = str(Path(opts["lens"]).resolve())
    if opts.get("fiz"):
        from ..live.fiz import read_fiz_table

        fiz = read_fiz_table(opts["fiz"])
        opts["fiz"] = str(Path(opts["fiz"]).resolve())
    file, report = args.file, args.report
    usd_layer_format(file)
    if report is not None and not str(report).lower().endswith((".csv", ".json")):
        raise InputError("--report is written as .csv or .json")
    if check_outputs:  # a recording starts only when its names are free (or --force); recover takes free names
        check_writable(file, force=args.force)
        if report is not None:
            check_writable(report, force=args.force)
    return Settings(str(file), None if report is None else str(report), bool(args.force), opts, sensor, lens, fiz)


class _Status:
    """Rate, counters and last timecode on stderr, redrawn a few times a second at a terminal."""

    def __init__(self, enabled: bool):
        self.enabled = enabled and sys.stderr.isatty()
        self._live = None

    def __enter__(self):
        if self.enabled:
            from rich.live import Live

            from ._common import console

            self._live = Live(console=console(stderr=True), refresh_per_second=4, transient=True)
            self._live.__enter__()
        return self

    def update(self, frames: int, rate: float, counters: dict, timecode, elapsed: float) -> None:
        if self._live is None:
            return
        from rich.table import Table

        t = Table(title="physcam live record", show_header=False, box=None)
        t.add_row("elapsed", f"{elapsed:.1f} s")
        t.add_row("recorded", f"{frames} samples ({rate:.1f}/s)")
        t.add_row("last timecode", str(timecode or "-"))
        for k, v in counters.items():
            t.add_row(k.replace("_", " "), str(v))
        self._live.update(t)

    def __exit__(self, *exc):
        if self._live is not None:
            self._live.__exit__(*exc)
        return False


class StopSignals:
    """While recording, SIGINT (Ctrl-C), SIGTERM (a process manager) and SIGHUP (the terminal closed)
    end the recording, which is then written; :meth:`restore` and leaving give the old handlers back."""

    NAMES = ("SIGINT", "SIGTERM", "SIGHUP")

    def __init__(self):
        self.received = None
        self._old: dict = {}

    def _handle(self, signum, frame) -> None:
        self.received = signum

    def __enter__(self):
        import signal
        import threading

        if threading.current_thread() is threading.main_thread():  # only the main thread may set handlers
            for name in self.NAMES:
                sig = getattr(signal, name, None)  # Windows has no SIGHUP
                if sig is not None:
                    self._old[sig] = signal.signal(sig, self._handle)
        return self

    def restore(self, name: str) -> None:
        import signal

        sig = getattr(signal, name, None)
        if sig in self._old:
            signal.signal(sig, self._old.pop(sig))

    def __exit__(self, *exc) -> bool:
        for name in self.NAMES:
            self.restore(name)
        return False


def _journal_header(s: Settings) -> dict:
    """The journal's header: the outputs by name when beside the journal, the options."""
    from datetime import datetime, timezone

    out = Path(s.file)
    report = s.report
    if report is not None and Path(report).resolve().parent == out.resolve().parent:
        report = Path(report).name
    elif report is not None:
        report = str(Path(report).resolve())
    return {"output": out.name, "report": report,
            "started": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"), "options": s.options}


class _Recording:
    """The take, its journal and the receiver's counters while a recording runs."""

    def __init__(self, take, journal):
        self.take, self.journal = take, journal
        self.counters_at = 0.0
        self.warned = False

    def add(self, item) -> None:
        if self.journal is not None and not self.journal.add_sample(item.sample, item.sequence, item.encoding,
                                                                    item.conflict) \
                and self.journal.error is not None and not self.warned:
            self.warned = True
            print(f"physcam: warning: the journal {self.journal.path} stopped ({self.journal.error}); the take "
                  f"goes on in memory from sample {self.journal.samples + 1}", file=sys.stderr)
        self.take.add(item.sample, item.sequence, item.conflict)

    def keep(self, receiver, now: float) -> None:
        if self.journal is None:
            return
        if now - self.counters_at >= _COUNTERS_EVERY_S:
            self.journal.add_counters(receiver.counters())
            self.counters_at = now
        self.journal.sync()


def _receive(args, receiver, rec: _Recording, stop: StopSignals) -> bool:
    """Hand the receiver's samples to the take until the recording ends; True when a signal or
    Ctrl-C ended it."""
    from ..live.frames import _timecode_text

    t0 = time.monotonic()
    last_tc, next_draw = None, 0.0
    take = rec.take
    with _Status(not args.json) as status:
        try:
            while stop.received is None and not take.full:
                now = time.monotonic()
                if args.duration is not None and now - t0 >= args.duration:
                    break
                if args.count is not None and take.count() >= args.count:
                    break
                item = receiver.get(timeout=0.05)
                if item is not None:
                    rec.add(item)
                    tc = item.sample.get("timing", {}).get("timecode")
                    last_tc = _timecode_text(tc) if tc else last_tc
                rec.keep(receiver, now)
                if now >= next_draw:
                    el = now - t0
                    status.update(take.count(), take.count() / el if el > 0 else 0.0, receiver.counters(), last_tc, el)
                    next_draw = now + 0.25
        except KeyboardInterrupt:
            return True  # Ctrl-C where no handler could be set: write what was received
    return False


def run_record(args) -> int:
    from ..errors import PhysCamError
    from ..live.journal import Journal, unfinished_journals
    from ..live.receiver import Receiver, multicast_group
    from ..live.take import Take

    s = settings(args)  # every option and file checked before a packet is read
    for old in unfinished_journals(s.file):
        print(f"physcam: note: an unfinished take is kept in {old}: `physcam live recover {quote(str(old))}` writes it",
              file=sys.stderr)
    group = multicast_group(args.multicast) if args.multicast is not None else None
    receiver = Receiver(args.port, host=args.host, group=group, interface=args.interface,
                        modulus=args.modulus if args.modulus == "auto" else int(args.modulus))
    journal = Journal.create(s.file, _journal_header(s))
    rec = _Recording(Take(s.options.get("source")), journal)
    t0 = time.monotonic()
    try:
        with StopSignals() as stop:
            with receiver:
                if args.port == 0:  # the system chose the port: say which, for the senders (and scripts)
                    print(f"physcam: listening on UDP {group or args.host}:{receiver.port}", file=sys.stderr,
                          flush=True)
                interrupted = _receive(args, receiver, rec, stop)
            stop.restore("SIGINT")  # a second Ctrl-C while writing aborts; SIGTERM and SIGHUP wait for the file
            while (item := receiver.get()) is not None and not rec.take.full:  # samples still queued
                if args.count is not None and rec.take.count() >= args.count:
                    break
                rec.add(item)
            counters = receiver.counters()
            journal.add_counters(counters)
            journal.sync(force=True)
            interrupted = interrupted or stop.received is not None
            return write_take(s, rec.take, counters, journal.path, time.monotonic() - t0, interrupted, args.json,
                              receiver=receiver, discard=journal.discard)
    except PhysCamError:
        if rec.take.sources():
            journal.close()  # the journal holds the take: kept
        else:
            journal.discard()  # nothing arrived (or the port could not be had): nothing to keep
        raise


def _nothing_written(s, take, counters, journal_path, receiver) -> str:
    """Why a take wrote nothing, and where its samples are."""
    heard = take.sources()
    if take.source is not None and heard:
        names = ", ".join(f"{h['source_id']} ({h['samples']} samples)" for h in heard[:4])
        return (f"no sample of source {take.source} arrived (heard: {names}); the samples are kept in "
                f"{journal_path}: `physcam live recover {quote(str(journal_path))} --source ID` writes another source's")
    why = f" ({take.refusals[0]})" if take.refusals else ""
    if receiver is None:
        return f"the journal {journal_path} holds no sample physcam can record{why}; nothing written"
    if receiver.refusals() and not why:
        why = f" (refused {receiver.refusals()[0]})"
    return (f"no valid samples arrived on port {receiver.port} (received {counters.get('received', 0)} packets){why}; "
            "nothing written")


def write_take(s: Settings, take, counters: dict, journal_path, elapsed: float, interrupted: bool,
               as_json: bool, *, discard, receiver=None, recovered_from=None) -> int:
    """Solve the take's frames and write its files (module notes); ``discard()`` removes the journal,
    called only after every file is written. A frame that cannot be solved is refused, the take kept."""
    from ..errors import InputError
    from ..live.record import absent_frames, solve_frames

    frames = take.frames()
    if not frames:
        raise InputError(_nothing_written(s, take, counters, journal_path, receiver))
    refused: list = []
    o = s.options
    solved = solve_frames(frames, sensor=s.sensor, rate=o.get("fps"), focal_length_mm=o.get("focal"),
                          fstop=o.get("fstop"), focus_mm=o.get("focus"), refused=refused, lens=s.lens, fiz=s.fiz)
    refusals = take.refusals + [reason for _, reason in refused]
    if receiver is not None:
        refusals = receiver.refusals() + refusals
    if not solved:
        raise InputError(f"no frame of the take could be recorded: {refusals[0]}; the samples are kept in "
                         f"{journal_path}")
    counters = dict(counters)
    counters["missing_packets"] = counters.pop("missing", 0)
    counters["missing"] = absent_frames([x.frame for x in solved], o.get("fps"))
    counters["refused"] = take.refused + len(refused)
    for reason in refusals[:10]:
        print(f"physcam: refused {reason}", file=sys.stderr)
    conflicts = take.conflicts()
    for c in conflicts[:10]:
        print(f"physcam: {conflict_line(c)}", file=sys.stderr)
    if len(conflicts) > 10:
        print(f"physcam: {len(conflicts) - 10} more packet numbers claimed by different samples", file=sys.stderr)
    if len(refusals) > 10:
        print(f"physcam: refused {len(refusals) - 10} more samples", file=sys.stderr)
    out, rep, moved = _write_files(s, solved, journal_path)
    if not moved:  # every file where it was asked (or beside it): the journal has done its work
        discard()
    _summary(s, take, solved, counters, out, rep, elapsed, interrupted, as_json, recovered_from,
             journal_path if moved else None, conflicts)
    return 0  # a signal is how a recording is ended: the file is written and that is success


def _spare_folder() -> Path:
    """Where a take goes when its own folder cannot take it: $TMPDIR, else the system's temporary folder."""
    import os
    import tempfile

    env = os.environ.get("TMPDIR")
    return Path(env) if env and Path(env).is_dir() else Path(tempfile.gettempdir())


def _write_one(write, asked: str, force: bool, journal_path) -> tuple[Path, bool]:
    """(where ``write`` wrote, whether it had to leave the asked folder): the asked name, the first
    free name beside it when that is taken, else, when the folder cannot be written (a full disk), the
    first free name in :func:`_spare_folder`. Both failing raises the first error with where the take is."""
    from ..errors import ExportError
    from ..live.take import write_under_free_name

    try:
        written = write_under_free_name(write, asked, force=force)
    except ExportError as exc:
        first = exc
    else:
        if Path(written) != Path(asked):
            print(f"physcam: {asked} is taken: written to {written} instead", file=sys.stderr)
        return written, False
    spare = _spare_folder()
    try:
        if spare.resolve() == Path(asked).resolve().parent:
            raise first
        written = write_under_free_name(write, spare / Path(asked).name)
    except ExportError:
        raise ExportError(f"{first}; the take is kept in {journal_path}: `physcam live recover "
                          f"{quote(str(journal_path))}` writes it once that is mended") from None
    print(f"physcam: warning: {first}; written to {written} instead (the journal {journal_path} is kept)",
          file=sys.stderr)
    return written, True


def _write_files(s: Settings, solved, journal_path) -> tuple[Path, Path | None, bool]:
    """Write the USD file and the report (:func:`_write_one`); (USD, report, whether one left its folder)."""
    from ..errors import ExportError
    from ..live.record import write_lens_report, write_recording_usd

    o = s.options
    out, moved = _write_one(lambda p, force: write_recording_usd(
        p, solved, rate=o.get("fps"), meters_per_unit=o.get("meters_per_unit", 0.01),
        path=o.get("path", "/Cameras/Camera"), force=force), s.file, s.force, journal_path)
    rep = None
    if s.report:
        try:
            rep, moved_rep = _write_one(lambda p, force: write_lens_report(p, solved, force=force), s.report,
                                        s.force, journal_path)
        except ExportError as exc:
            raise ExportError(f"{out} is written, the report is not: {exc}") from None
        moved = moved or moved_rep
    return out, rep, moved


def conflict_line(c: dict) -> str:
    """One line naming a packet number that different samples claimed, and what the take kept."""
    who = ", ".join(f"{x['sample_id']} (timecode {x['timecode'] or '-'})" for x in c["claimants"])
    kept = f"kept {c['kept']}" if c["kept"] is not None else "kept neither (the frame is missing)"
    return f"conflict: packet {c['sequence']} was claimed by {len(c['claimants'])} different samples: {who}; " \
           f"{kept}: {c['reason']}"


def _summary(s, take, solved, counters, out, rep, elapsed, interrupted, as_json, recovered_from, journal,
             conflicts) -> None:
    heard = take.sources()
    chosen = next(h for h in heard if h["recorded"])
    others = [h for h in heard if not h["recorded"]]
    summary = {"file": str(out), "report": None if rep is None else str(rep), "frames": len(solved),
               "seconds": round(elapsed, 3), "interrupted": interrupted, "counters": counters,
               "first_timecode": solved[0].frame.timecode, "last_timecode": solved[-1].frame.timecode,
               "source": chosen, "other_sources": others, "unlisted_source_samples": take.unlisted_samples,
               "asked_file": s.file, "asked_report": s.report, "recovered_from": recovered_from,
               "journal": None if journal is None else str(journal), "conflicts": conflicts[:100]}
    if as_json:
        emit_json(document("live_record", summary, version=2, units={"time": "s"}))
        return
    name = f"{chosen['source_id'] or 'a source without sourceId'}" + (
        f" (source {chosen['source_number']})" if chosen["source_number"] is not None else "")
    print(f"recorded {len(solved)} frames of {name} to {out}" + (f" and {rep}" if rep else "")
          + f" ({summary['first_timecode'] or '-'} to {summary['last_timecode'] or '-'})")
    print("  " + ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in counters.items()))
    for h in others:
        print(f"  also heard, not recorded: {h['source_id']}" + (
            f" (source {h['source_number']})" if h["source_number"] is not None else "") + f": {h['samples']} sample{'s' * (h['samples'] != 1)}")
    if take.unlisted_samples:
        print(f"  and {take.unlisted_samples} samples of further sources")
    for c in conflicts[:10]:
        print(f"  {conflict_line(c)}")


def run_recover(args) -> int:
    """Write the take an unfinished journal holds (a recorder killed, a disk full), as ``live record``
    would have written it."""
    from ..errors import InputError
    from ..live.journal import JournalReader, discard_journal, output_of_journal
    from ..live.take import Take

    t0 = time.monotonic()
    reader = JournalReader(args.journal)
    if reader.locked():
        raise InputError(f"{args.journal}: a recorder is still writing this journal (it holds its lock)")
    h = reader.header
    folder = Path(args.journal).parent
    if args.file is None:
        named = h.get("output")  # by name only: a journal never sends its take out of its own folder
        args.file = str(folder / Path(named).name) if isinstance(named, str) and Path(named).name \
            else str(output_of_journal(args.journal))
    if args.report is None and isinstance(h.get("report"), str):
        args.report = str(folder / h["report"])  # a whole path stays whole
    s = settings(args, h.get("options") if isinstance(h.get("options"), dict) else {}, check_outputs=False)
    take, counters = Take(s.options.get("source")), {}
    for record in reader:
        if record[0] == "counters":
            counters = {k: v for k, v in record[1].items() if isinstance(k, str) and isinstance(v, int)}
        elif not take.full:
            take.add(record[3], record[1], record[4])
    for what, n in (("torn at its end (a write cut short)", reader.torn), ("damaged, skipped", reader.skipped)):
        if n:
            print(f"physcam: note: {args.journal}: {n} line{'s' * (n > 1)} {what}", file=sys.stderr)
    return write_take(s, take, counters, args.journal, time.monotonic() - t0, False, args.json,
                      discard=lambda: discard_journal(args.journal), recovered_from=str(args.journal))
