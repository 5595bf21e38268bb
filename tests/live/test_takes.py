"""Live takes lost (issue 40, items 1-5): one time line per source, poison numbers refused in one line,
file options checked before the first packet, the journal that keeps a take through SIGKILL, a taken
name and a full disk, and every absent frame counted.

Every stream here is real UDP over loopback into a real receiver (a `physcam live record` process or
an in-process :class:`~physcam.live.receiver.Receiver`), with real CBOR (cbor2); waits are on events
(a port held, a socket read, journal lines written), never on fixed sleeps.
"""

from __future__ import annotations

import copy
import csv
import dataclasses
import functools
import json
import os
import signal
import socket
import subprocess
import sys
import time
from fractions import Fraction
from pathlib import Path

import cbor2
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.cli import main
from physcam.live.camera import camera_frames, frames_to_samples
from physcam.live.frames import TrackedFrame, frame_from_sample, timecode_fields
from physcam.live.protocol import ENCODING_CBOR, ENCODING_JSON, packetize
from physcam.live.receiver import Receiver
from physcam.live.record import solve_frames
from physcam.live.sample import SampleError, decode_sample
from physcam.live.sender import Sender
from physcam.optics.sensors import find_sensor
from _udp import needs_proc_net_udp, recorder_port, wait_until_read

SID_A = "urn:uuid:0a0a0a0a-0000-4000-8000-00000000000a"
SID_B = "urn:uuid:0b0b0b0b-0000-4000-8000-00000000000b"
DAY_NS = 86_400 * 10**9
T0_NS = 1_700_000_000 * 10**9
BIG = 10**5000  # 5001 digits: Python refuses str() of it (its limit is 4,300 digits)


def _samples(n, source_id=SID_A, t0_ns=T0_NS, rate=24):
    frames = camera_frames(sensor=find_sensor("ALEXA 35"), frames=n, rate=rate, focus_mm=1500.0, focus_to_mm=3000.0,
                           fstop=2.8, focal_length_mm=35.0, t0_ns=t0_ns)
    return list(frames_to_samples(frames, source_id=source_id))


def _with_fstop(sample, value):
    s = copy.deepcopy(sample)
    s["lens"]["fStop"] = value
    return s


def _big_json(sample) -> bytes:
    """``sample`` as JSON with a 5,000-digit integer literal as its f-stop (written as text: Python's
    json cannot print it)."""
    return json.dumps(_with_fstop(sample, "@BIG@")).replace('"@BIG@"', "1" + "0" * 5000).encode()


def _send_raw(sock, port, payload: bytes, seq: int, encoding: str) -> None:
    enc = ENCODING_CBOR if encoding == "cbor" else ENCODING_JSON
    for d in packetize(payload, encoding=enc, sequence=seq % 65536):
        sock.sendto(d, ("127.0.0.1", port))


class _Recorder:
    """A `physcam live record take.usda` process on the loopback port the system gives it (``--port 0``;
    :func:`_udp.recorder_port`), killed whatever fails. ``stderr`` is what it said besides its port."""

    def __init__(self, folder: Path, *args, argv_prefix=(), env=None, out=None):
        self.port, self.said = None, ""
        self.out = out or folder / "take.usda"
        self.proc = subprocess.Popen([*argv_prefix, sys.executable, "-m", "physcam", "live", "record", str(self.out),
                                      "--port", "0", "--host", "127.0.0.1", "--duration", "120", *args],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=folder, env=env)

    def __enter__(self):
        return self

    def wait_for_port(self):
        self.port, self.said = recorder_port(self.proc)
        return self

    def finish(self, sig=None):
        if sig is not None:
            wait_until_read(self.proc, self.port)
            self.proc.send_signal(sig)
        self.stdout, stderr = self.proc.communicate(timeout=120)
        self.stderr = self.said + stderr
        return self.proc.returncode

    def __exit__(self, *exc):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.communicate()
        return False


def _wait_for_samples(path: Path, n: int, proc, timeout: float = 60.0) -> None:
    """Until the journal ``path`` holds ``n`` whole sample lines (the recorder has journaled what was
    sent; its once-a-second counters lines are not counted)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:  # its one line says why (read here: the test's own error is raised first)
            err = proc.stderr.read() if proc.stderr is not None else ""
            raise RuntimeError(f"the recorder exited ({proc.returncode}) before journaling {n} samples: {err!r}")
        if path.exists() and sum(line.startswith(b'{"sequence":') and line.endswith(b"\n")
                                 for line in path.read_bytes().splitlines(keepends=True)) >= n:
            return
        time.sleep(0.05)
    raise TimeoutError(f"{path} holds fewer than {n} samples after {timeout} s")


def _sequence_numbers(usd_file) -> list[int]:
    from pxr import Usd

    stage = Usd.Stage.Open(str(usd_file))
    seq = stage.GetPrimAtPath("/Cameras/Camera").GetAttribute("physcam:live:sequenceNumber")
    return [seq.Get(t) for t in seq.GetTimeSamples()]


def _source_ids(usd_file) -> set[str]:
    from pxr import Usd

    stage = Usd.Stage.Open(str(usd_file))
    attr = stage.GetPrimAtPath("/Cameras/Camera").GetAttribute("physcam:live:sourceId")
    return {attr.Get(t) for t in attr.GetTimeSamples()}


# --- 1. one time line per source --------------------------------------------------------------------------
def test_a_stray_source_a_day_ahead_does_not_cut_the_time_line():
    """solve_frames: source B's one sample stamped a day ahead, between source A's frames, drops none of
    A's (before, the latest time code of any source was the bar: 19 of A's 40 frames were left out)."""
    a = _samples(40)
    stray = _samples(1, SID_B, t0_ns=T0_NS + DAY_NS)[0]
    order = a[:20] + [stray] + a[20:]
    statics: dict = {}
    frames = []
    for s in order:
        statics[s["sourceId"]] = s.get("static", statics.get(s["sourceId"]))
        frames.append(frame_from_sample(s, static=statics[s["sourceId"]]))
    solved = solve_frames(frames)
    assert [x.frame.sequence_number for x in solved if x.frame.source_id == SID_A] == list(range(40))


def test_one_sample_of_the_same_source_a_day_ahead_is_left_out_not_the_frames_after_it():
    """A tracker's clock glitches once: its frame 20 is stamped a day late. That one frame is left out
    of the time line (the longest run of increasing time codes), with a warning, and the 39 others are
    kept (before: every frame after it "did not advance in time", 19 of them)."""
    from physcam.errors import PhysCamWarning

    a = _samples(40)
    a[20]["timing"]["sampleTimestamp"]["seconds"] += 86_400
    frames = [frame_from_sample(s, static=a[0]["static"]) for s in a]
    with pytest.warns(PhysCamWarning, match="^1 samples lay off their source's time line"):
        solved = solve_frames(frames)
    assert [x.frame.sequence_number for x in solved] == [i for i in range(40) if i != 20]


@pytest.mark.parametrize("codes, kept", [
    ([0, 1, 2, 3], [0, 1, 2, 3]), ([0, 1, 86400, 2, 3], [0, 1, 3, 4]), ([0, 1, 1, 2], [0, 1, 3]),
    ([5, 6, 0, 1, 2, 3], [2, 3, 4, 5]), ([0, 2, 1, 3], [0, 2, 3]), ([], [])])
def test_the_time_line_is_the_longest_run_of_increasing_time_codes(codes, kept):
    """Worked by hand: a frame far ahead is dropped; of equal time codes the first stays; a clock that
    went back is followed when more frames follow it; of two frames swapped (2 before 1), the one
    ahead of its neighbours gives way (either run is as long; patience sorting keeps the lower)."""
    from physcam.live.record import time_line

    frames = [TrackedFrame(source_id=SID_A, source_number=1) for _ in codes]
    assert sorted(time_line(frames, codes)) == kept


@pytest.mark.slow
@needs_proc_net_udp
def test_a_stray_sample_and_a_poison_number_leave_the_take_whole(tmp_path):
    """A recorder (`--count 40`) hears source A's 40 samples at 240 fps; between them, from a second
    sender, one valid sample of source B stamped a day ahead, and from A's own sender one CBOR sample
    whose f-stop is a 5,000-digit integer. The take is A's 40 frames, numbered 0-39, none missing; B is
    named with its 1 sample; the poison sample is refused in one line that names its path (before: the
    stray cut the take to 21 frames, and the bignum killed the recorder with a traceback)."""
    pytest.importorskip("pxr")
    a = _samples(40)
    stray = _samples(1, SID_B, t0_ns=T0_NS + DAY_NS)[0]
    with _Recorder(tmp_path, "--count", "40") as rec:
        rec.wait_for_port()
        with Sender("127.0.0.1", rec.port, encoding="cbor") as tx_a, Sender("127.0.0.1", rec.port) as tx_b:
            tx_a.stream(a[:20], 240)
            tx_b.send(stray)
            tx_a.send(_with_fstop(a[20], BIG))  # an extra sample of A: its number is used up, nothing else
            tx_a.stream(a[20:], 240)
        assert rec.finish() == 0, rec.stderr
    assert f"recorded 40 frames of {SID_A} (source 1) to {tmp_path / 'take.usda'}" in rec.stdout
    assert f"also heard, not recorded: {SID_B} (source 1): 1 sample\n" in rec.stdout
    assert "missing 0," in rec.stdout
    poison = [line for line in rec.stderr.splitlines() if "$.lens.fStop" in line]
    assert len(poison) == 1 and "an integer of 5001 digits" in poison[0] and len(poison[0]) < 300, rec.stderr
    assert "Traceback" not in rec.stderr
    assert _sequence_numbers(tmp_path / "take.usda") == list(range(40))
    assert _source_ids(tmp_path / "take.usda") == {SID_A}


@pytest.mark.slow
@needs_proc_net_udp
@pytest.mark.parametrize("chosen", ["default", "--source"])
def test_two_senders_on_one_port_record_one_source_and_name_the_other(tmp_path, chosen):
    """Two real senders on one port: A sends 30 samples, B 12 (B's clock 3 s behind), interleaved. By
    default the take is the source with the most samples (A, all 30 of it); `--source B` records B's
    12. The summary names the other source with its sample count."""
    pytest.importorskip("pxr")
    from _documents import check_document

    a, b = _samples(30, SID_A), _samples(12, SID_B, t0_ns=T0_NS - 3 * 10**9)
    extra = ["--source", SID_B] if chosen == "--source" else []
    with _Recorder(tmp_path, "--json", *extra) as rec:
        rec.wait_for_port()
        with Sender("127.0.0.1", rec.port, encoding="cbor") as tx_a, Sender("127.0.0.1", rec.port) as tx_b:
            for i in range(30):
                tx_a.send(a[i])
                if i < 12:
                    tx_b.send(b[i])
                time.sleep(1 / 240)
        assert rec.finish(signal.SIGTERM) == 0, rec.stderr
    doc = json.loads(rec.stdout)
    check_document(doc)
    mine, other, n, n_other = (SID_A, SID_B, 30, 12) if chosen == "default" else (SID_B, SID_A, 12, 30)
    assert doc["frames"] == n and doc["counters"]["missing"] == 0
    assert doc["source"] == {"source_id": mine, "source_number": 1, "samples": n, "refused": 0, "recorded": True}
    assert doc["other_sources"] == [{"source_id": other, "source_number": 1, "samples": n_other, "refused": 0,
                                     "recorded": False}]
    assert _sequence_numbers(tmp_path / "take.usda") == list(range(n))
    assert _source_ids(tmp_path / "take.usda") == {mine}


# --- 2. a 5,000-digit integer is refused in one bounded line ---------------------------------------------------
@pytest.mark.parametrize("case", ["cbor value", "json value", "cbor list item", "cbor key", "cbor fraction",
                                  "cbor unknown tag"])
def test_a_5000_digit_integer_is_refused_in_one_bounded_line(case):
    from fractions import Fraction as F

    s = _samples(1)[0]
    path, payload, enc = "$.lens.fStop", None, "cbor"
    if case == "cbor value":
        s = _with_fstop(s, BIG)
    elif case == "json value":
        payload, enc = _big_json(s), "json"
    elif case == "cbor list item":
        s["transforms"][0]["translation"]["x"] = -BIG
        path = "$.transforms[0].translation.x"
    elif case == "cbor key":
        s["lens"][BIG] = 1.0
        path = "$.lens"
    elif case == "cbor fraction":
        s = _with_fstop(s, F(BIG, 3))
    else:
        s = _with_fstop(s, cbor2.CBORTag(4242, BIG))
    with pytest.raises(SampleError) as err:
        decode_sample(payload if payload is not None else cbor2.dumps(s), enc)
    text = str(err.value)
    assert err.value.problems[0].path == path, text
    assert len(text) < 300 and "\n" not in text
    if case != "cbor unknown tag":
        assert "an integer of 5001 digits" in text, text


def test_live_validate_refuses_a_bignum_cbor_file_in_one_line(tmp_path, capsys):
    f = tmp_path / "poison.cbor"
    f.write_bytes(cbor2.dumps(_with_fstop(_samples(1)[0], BIG)))
    assert main(["live", "validate", str(f)]) == 2
    out, err = capsys.readouterr()
    assert out.splitlines() == [f"{f}: INVALID", "  $.lens.fStop: an integer of 5001 digits is beyond what a 64-bit "
                                                 "float holds (rule: finite)"]
    assert err.strip() == "physcam: error: 1 of 1 samples are not valid OpenTrackIO 1.0.1"


def test_the_receiver_refuses_bignum_samples_and_keeps_the_stream():
    """Ten samples over UDP, numbered 0-9; 3 carries a 5,000-digit f-stop in CBOR, 6 in JSON: the other
    eight are handed on in order, the two counted invalid with one bounded reason each (before: the
    CBOR one ended the receiving thread, and `get` raised ValueError)."""
    good = _samples(10)
    got = []
    with Receiver(0, host="127.0.0.1") as rx, socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        for i, s in enumerate(good):
            if i == 3:
                _send_raw(sock, rx.port, cbor2.dumps(_with_fstop(s, BIG)), i, "cbor")
            elif i == 6:
                _send_raw(sock, rx.port, _big_json(s), i, "json")
            else:
                _send_raw(sock, rx.port, cbor2.dumps(s), i, "cbor")
        deadline = time.monotonic() + 30
        while len(got) < 8 and time.monotonic() < deadline:
            item = rx.get(timeout=0.05)
            if item is not None:
                got.append(item)
        counters, reasons = rx.counters(), rx.refusals()
    assert [g.sample["sampleId"] for g in got] == [s["sampleId"] for i, s in enumerate(good) if i not in (3, 6)]
    assert counters["invalid"] == 2 and counters["malformed"] == 0 and counters["missing"] == 0
    assert [r.split(":")[0] for r in reasons] == ["packet 3 from 127.0.0.1", "packet 6 from 127.0.0.1"]
    assert all("$.lens.fStop: an integer of 5001 digits" in r and len(r) < 300 for r in reasons), reasons


# --- 3. file options are checked before the first packet ---------------------------------------------------------
@pytest.mark.parametrize("option, value, says", [
    ("--lens", "no_such_lens_x", "no bundled lens called 'no_such_lens_x'"),
    ("--lens", "bad.toml", "bad.toml:1: not valid TOML"),
    ("--fiz", "missing.csv", "cannot read the FIZ table missing.csv"),
    ("--fiz", "fiz.csv", "fiz.csv:3: the encoder 'abc' is not a number"),
    ("--sensor", "NO SUCH SENSOR", "unknown sensor 'NO SUCH SENSOR'"),
])
def test_file_options_are_checked_before_the_port_is_opened(tmp_path, monkeypatch, capsys, option, value, says):
    """The recorder's port is held by another socket: a recorder that opened it before checking its
    options would fail there ("cannot listen"), or, before the fix, wait out its --duration and then
    throw the take away on the bad file. Now the bad option is the one line, exit 2, nothing left."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bad.toml").write_text('[lens\nname = "x"\n')
    (tmp_path / "fiz.csv").write_text("axis,encoder,value\nfocus,0,inf\nfocus,abc,1\n")
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as blocker:
        blocker.bind(("127.0.0.1", 0))  # no SO_REUSEADDR: the recorder cannot bind this port
        port = blocker.getsockname()[1]
        capsys.readouterr()
        rc = main(["live", "record", "take.usda", "--port", str(port), "--host", "127.0.0.1", "--duration", "30",
                   option, value])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and err.startswith(f"physcam: error: {says}"), err
    assert not list(tmp_path.glob("take.usda*"))


# --- 4. the journal ---------------------------------------------------------------------------------------------
@pytest.mark.slow
@needs_proc_net_udp
def test_a_killed_recorder_keeps_its_take_and_recover_writes_it(tmp_path, capsys, monkeypatch):
    """30 samples reach a recorder, which is then killed (SIGKILL: no handler runs, nothing is written
    at the end). Its journal holds all 30; a new recording of the same name points at it; `live
    recover` writes the USD file and the report the recording asked for, with all 30 frames, then
    removes the journal."""
    pytest.importorskip("pxr")
    samples = _samples(30)
    journal = tmp_path / "take.usda.journal"
    with _Recorder(tmp_path, "--report", "take.csv", "--json") as rec:
        rec.wait_for_port()
        with Sender("127.0.0.1", rec.port, encoding="cbor") as tx:
            tx.stream(samples, 240)
        _wait_for_samples(journal, 30, rec.proc)
        rec.proc.kill()
        rec.proc.communicate(timeout=60)
    assert rec.proc.returncode == -signal.SIGKILL
    assert not (tmp_path / "take.usda").exists() and not (tmp_path / "take.csv").exists()

    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    assert main(["live", "record", "take.usda", "--port", "0", "--host", "127.0.0.1",
                 "--duration", "0.2"]) == 2  # nothing arrives; it says where the unfinished take is
    err = capsys.readouterr().err
    assert f"an unfinished take is kept in {journal.name}: `physcam live recover {journal.name}`" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["take.usda.journal"]  # its own empty journal is gone

    assert main(["live", "recover", str(journal), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    from _documents import check_document

    check_document(doc)
    assert doc["frames"] == 30 and doc["recovered_from"] == str(journal) and doc["journal"] is None
    assert doc["file"] == str(tmp_path / "take.usda") and doc["report"] == str(tmp_path / "take.csv")
    assert not journal.exists()
    assert _sequence_numbers(tmp_path / "take.usda") == list(range(30))
    rows = list(csv.DictReader((tmp_path / "take.csv").open()))
    assert [float(r["focus_from_film_mm"]) for r in rows] == pytest.approx(
        [s["lens"]["focusDistance"] * 1000 for s in samples], rel=1e-12)


@pytest.mark.slow
@needs_proc_net_udp
def test_a_name_taken_while_recording_gets_a_free_name(tmp_path):
    """While the take records, someone writes take.usda and take.csv. The take (10 frames) is written
    to take-1.usda and take-1.csv, the command says so, their files stay as they were, and the journal
    goes (before: "already exists", exit 2, the take lost)."""
    pytest.importorskip("pxr")
    from _documents import check_document

    samples = _samples(10)
    with _Recorder(tmp_path, "--count", "10", "--report", str(tmp_path / "take.csv"), "--json") as rec:
        rec.wait_for_port()
        with Sender("127.0.0.1", rec.port, encoding="cbor") as tx:
            tx.stream(samples[:5], 240)
            _wait_for_samples(tmp_path / "take.usda.journal", 5, rec.proc)
            (tmp_path / "take.usda").write_text("someone else's camera\n")
            (tmp_path / "take.csv").write_text("someone else's report\n")
            tx.stream(samples[5:], 240)
        assert rec.finish() == 0, rec.stderr
    doc = json.loads(rec.stdout)
    check_document(doc)
    assert (doc["file"], doc["report"]) == (str(tmp_path / "take-1.usda"), str(tmp_path / "take-1.csv"))
    assert doc["asked_file"] == str(tmp_path / "take.usda") and doc["frames"] == 10
    assert f"{tmp_path / 'take.usda'} is taken: written to {tmp_path / 'take-1.usda'} instead" in rec.stderr
    assert (tmp_path / "take.usda").read_text() == "someone else's camera\n"
    assert (tmp_path / "take.csv").read_text() == "someone else's report\n"
    assert _sequence_numbers(tmp_path / "take-1.usda") == list(range(10))
    assert not (tmp_path / "take.usda.journal").exists()


def _can_mount_tmpfs() -> bool:
    try:
        return subprocess.run(["unshare", "-Urm", "sh", "-c", "mount -t tmpfs -o size=64k tmpfs /mnt"],
                              capture_output=True, timeout=30).returncode == 0
    except (OSError, subprocess.SubprocessError):
        return False


def _fill(folder: Path, leave: int) -> None:
    """Fill the file system of ``folder`` until ``leave`` bytes are free (0: until a write fails)."""
    free = os.statvfs(folder).f_bavail * os.statvfs(folder).f_frsize
    with open(folder / "filler", "wb", buffering=0) as f:
        try:
            f.write(b"\0" * max(0, free - leave))
            while leave == 0:
                f.write(b"\0" * 4096)
        except OSError:
            pass


@pytest.mark.slow
@needs_proc_net_udp
@pytest.mark.skipif(not _can_mount_tmpfs(), reason="needs a tmpfs mounted in a user namespace (unshare -Urm)")
@pytest.mark.parametrize("spare", ["writable", "none"])
def test_a_full_disk_at_the_end_loses_no_take(tmp_path, spare):
    """The recorder writes on a 1 MiB tmpfs (mounted in a user namespace), which fills up before the
    take ends: the USD write fails with ENOSPC. With a spare folder ($TMPDIR elsewhere) the take is
    written there, all 10 frames, and the command says where (the journal kept); without one (TMPDIR
    on the full disk), exit 2 in one line naming the journal, which holds all 10 samples and which
    `live recover` writes once it is copied to a disk with room."""
    pytest.importorskip("pxr")
    disk, outside, spare_dir = tmp_path / "disk", tmp_path / "outside", tmp_path / "spare"
    for d in (disk, outside, spare_dir):
        d.mkdir()
    script = (f'mount -t tmpfs -o size=1m tmpfs "{disk}" || exit 97; "$@"; rc=$?; '
              f'cp "{disk}/take.usda.journal" "{outside}/" 2>/dev/null; exit $rc')
    env = dict(os.environ, TMPDIR=str(spare_dir if spare == "writable" else disk))
    samples = _samples(10)
    with _Recorder(tmp_path, "--count", "10", "--json", argv_prefix=("unshare", "-Urm", "sh", "-c", script, "sh"),
                   env=env, out=disk / "take.usda") as rec:
        inside = Path(f"/proc/{rec.proc.pid}/root") / str(disk).lstrip("/")  # the tmpfs as the recorder sees it
        rec.wait_for_port()
        with Sender("127.0.0.1", rec.port, encoding="cbor") as tx:
            tx.stream(samples[:9], 240)
            _wait_for_samples(inside / "take.usda.journal", 9, rec.proc)
            _fill(inside, leave=0 if spare == "writable" else 8192)  # the USD needs 14 KB
            tx.send(samples[9])
        rc = rec.finish()
    assert "Traceback" not in rec.stderr
    if spare == "writable":
        assert rc == 0, rec.stderr
        doc = json.loads(rec.stdout)
        assert doc["file"] == str(spare_dir / "take.usda") and doc["frames"] == 10
        assert doc["journal"] == str(disk / "take.usda.journal")
        assert "No space left on device" in rec.stderr and f"written to {spare_dir / 'take.usda'}" in rec.stderr
        assert _sequence_numbers(spare_dir / "take.usda") == list(range(10))
        return
    assert rc == 2 and rec.stdout == ""
    assert rec.stderr.count("\n") == 1 and "No space left on device" in rec.stderr, rec.stderr
    assert f"the take is kept in {disk / 'take.usda.journal'}: `physcam live recover" in rec.stderr
    assert main(["live", "recover", str(outside / "take.usda.journal")]) == 0
    assert _sequence_numbers(outside / "take.usda") == list(range(10))


def test_a_journal_cut_short_by_a_power_cut_gives_back_every_whole_line(tmp_path):
    """A power cut can leave the last line half written, followed by the zeros a file system gives a
    block it had no time to fill: every whole line is read back, the cut one counted torn; a damaged
    line inside is skipped and counted."""
    from physcam.live.journal import Journal, JournalReader

    samples = _samples(5)
    j = Journal.create(tmp_path / "take.usda", {"output": "take.usda", "report": None, "options": {}})
    for i, s in enumerate(samples):
        j.add_sample(s, i, "cbor")
    j.close()
    data = j.path.read_bytes()
    lines = data.split(b"\n")
    for cut, tail, torn, skipped in ((len(data) - 40, b"", 1, 0), (len(data) - 40, b"\0" * 4096, 1, 0),
                                     (len(data), b"", 0, 0)):
        j.path.write_bytes(data[:cut] + tail)
        r = JournalReader(j.path)
        got = [rec[3]["sampleId"] for rec in r if rec[0] == "sample"]
        assert got == [s["sampleId"] for s in samples[:4 if torn else 5]] and (r.torn, r.skipped) == (torn, skipped)
    lines[2] = lines[2][:100]  # the second sample's line damaged, more after it
    j.path.write_bytes(b"\n".join(lines))
    r = JournalReader(j.path)
    assert [rec[1] for rec in r if rec[0] == "sample"] == [0, 2, 3, 4] and (r.torn, r.skipped) == (0, 1)


# --- 5. every absent frame is counted ---------------------------------------------------------------------------
ABSENT = {10, 20, 21, *range(30, 36), *range(45, 54)}  # gaps of 1, 2, 6 and 9 frames: 18 in a 60-frame line


@pytest.mark.slow
@needs_proc_net_udp
@pytest.mark.parametrize("numbering", ["consecutive packets", "packets numbered by frame"])
def test_every_absent_frame_is_counted(tmp_path, numbering):
    """A 24 fps line of 60 frames reaches the recorder without 18 of them, in gaps of 1, 2, 6 and 9
    frames; the packets are numbered one after the other (the frames never left the tracker) or by
    frame (they were lost on the way: the 9-frame gap is past the reorder window). Either way the
    summary counts 18 missing (before: 0, and 9)."""
    pytest.importorskip("pxr")
    samples = _samples(60)
    kept = [i for i in range(60) if i not in ABSENT]
    with _Recorder(tmp_path, "--count", str(len(kept)), "--json") as rec:
        rec.wait_for_port()
        if numbering == "consecutive packets":
            with Sender("127.0.0.1", rec.port, encoding="cbor") as tx:
                tx.stream([samples[i] for i in kept], 240)
        else:
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
                for i in kept:
                    _send_raw(sock, rec.port, cbor2.dumps(samples[i]), i, "cbor")
                    time.sleep(1 / 240)
        assert rec.finish() == 0, rec.stderr
    doc = json.loads(rec.stdout)
    assert doc["frames"] == 42 and doc["counters"]["missing"] == 18, doc["counters"]
    assert _sequence_numbers(tmp_path / "take.usda") == kept


def _line(n, rate, drop):
    """A hand-made time line of n frames at ``rate``: timestamps (ns, exact fractions of a second),
    timecode labels and sequence numbers."""
    fr = Fraction(rate)
    return [TrackedFrame(time_ns=T0_NS + round(Fraction(i * 10**9) / fr), rate=fr, sequence_number=1000 + i,
                         timecode=_label(timecode_fields(i + 3600 * 24, fr, drop_frame=drop)), drop_frame=drop)
            for i in range(n)]


def _label(tc):
    sep = ";" if tc.get("dropFrame") else ":"
    text = f"{tc['hours']:02d}:{tc['minutes']:02d}:{tc['seconds']:02d}{sep}{tc['frames']:02d}"
    return text + (f".{tc['subFrame']}" if "subFrame" in tc else "")


LINES = {(rate, drop): _line(2000, rate, drop) for rate, drop in
         ((24, False), (Fraction(30000, 1001), True), (120, False), (Fraction(24000, 1001), False))}


@settings(max_examples=40, deadline=None)
@given(st.sampled_from(sorted(LINES, key=str)), st.sets(st.integers(1, 1998), max_size=300),
       st.sampled_from(["timestamps", "timecodes", "sequence numbers"]))
def test_absent_frames_counts_what_a_line_lacks(line, dropped, by):
    """A time line's first and last frame kept and any others dropped: absent_frames counts exactly
    the dropped ones, from the timestamps, or the timecodes (drop-frame, and sub-frames at 120 fps),
    or the sequence numbers."""
    from physcam.live.record import absent_frames

    frames = [f for i, f in enumerate(_line_by(line, by)) if i not in dropped]
    assert absent_frames(frames) == len(dropped)


@functools.cache
def _line_by(line, by):
    """LINES[line] with only what places a frame ``by``: without timestamps, and without timecodes for
    sequence numbers (made once per line and clock: dataclasses.replace of 2,000 frames for each of the
    hypothesis examples was most of the test's time)."""
    frames = LINES[line]
    if by != "timestamps":
        frames = [dataclasses.replace(f, time_ns=None) for f in frames]
    if by == "sequence numbers":
        frames = [dataclasses.replace(f, timecode=None) for f in frames]
    return frames


RATES = [Fraction(24), Fraction(25), Fraction(24000, 1001), Fraction(30000, 1001), Fraction(120), Fraction(2),
         Fraction(60000, 1001)]


@settings(max_examples=50, deadline=None)
@given(st.sampled_from(RATES), st.lists(st.integers(0, 10**13), min_size=1, max_size=20),
       st.lists(st.sampled_from([0, 10**9 // 4, 10**9 // 2, 3 * 10**9 // 4]), min_size=1, max_size=20))
def test_timestamps_give_the_places_and_time_codes_of_exact_fractions(rate, offsets_ns, halves_ns):
    """A frame's place (absent_frames) and USD time code (time_codes) from its timestamp, in integers,
    are Python's Fraction arithmetic's: round(Fraction(dt, 1e9) * rate) (ties to even: quarter and half
    seconds at 2 fps land on .5 of a frame) and round(float(that product), 6)."""
    from physcam.live.record import _nearest, time_codes

    stamps = sorted(T0_NS + o for o in offsets_ns + halves_ns)
    for dt in (t - stamps[0] for t in stamps):
        assert _nearest(dt, rate.numerator, 10**9 * rate.denominator) == round(Fraction(dt, 10**9) * rate)
    frames = [TrackedFrame(time_ns=t, rate=rate) for t in stamps]
    codes, fr = time_codes(frames)
    assert fr == rate
    assert codes == [round(float(Fraction(t - stamps[0], 10**9) * rate), 6) for t in stamps]


@pytest.mark.parametrize("call", ["multicast_group", "build_packet", "Receiver", "timecode_fields", "Sender"])
def test_the_live_api_refuses_a_5000_digit_argument_in_one_line(call):
    """The API's own refusals show a 5,000-digit argument by its length (before: str() raised ValueError)."""
    from physcam.errors import InputError
    from physcam.live.protocol import build_packet
    from physcam.live.receiver import multicast_group

    calls = {"multicast_group": lambda: multicast_group(BIG),
             "build_packet": lambda: build_packet(b"{}", encoding=ENCODING_JSON, sequence=BIG),
             "Receiver": lambda: Receiver(0, queue_size=BIG),
             "timecode_fields": lambda: timecode_fields(-BIG, 24),
             "Sender": lambda: Sender("127.0.0.1", 5555, modulus=BIG)}
    with pytest.raises(InputError) as err:
        calls[call]()
    assert "an integer of 5001 digits" in str(err.value) and len(str(err.value)) < 200


# --- a valid forged copy of a sample (a user review, round 8) ------------------------------------------------
def _timecodes(usd_file) -> list[str]:
    from pxr import Usd

    stage = Usd.Stage.Open(str(usd_file))
    attr = stage.GetPrimAtPath("/Cameras/Camera").GetAttribute("physcam:live:timecode")
    return [attr.Get(t) for t in attr.GetTimeSamples()]


@pytest.mark.slow
@needs_proc_net_udp
@pytest.mark.parametrize("forgery", ["timecode 7 frames later", "same clocks, focus moved"])
def test_a_valid_forged_copy_never_silently_takes_the_real_frame(tmp_path, forgery):
    """The review's stream over UDP into `physcam live record`: samples 0 and 1, then a schema-valid deep
    copy of 2 (new sampleId, packet number 2), then the real 2, 3, 4. When the copy's timecode contradicts
    its neighbours (00:00:00:09 between :01 and :03) the take holds the real 2; when it carries the same
    clocks as the real one (only the focus differs) nothing tells them apart and the take holds neither
    (frame 2 missing). Either way the conflict is named on stderr and in the summary, and counted
    `conflict`, not `late` (before: the copy was recorded as frame 2 and the real 2 counted late)."""
    pytest.importorskip("pxr")
    from _documents import check_document

    good = _samples(5)
    forged = copy.deepcopy(good[2])
    forged["sampleId"] = "urn:uuid:f0f0f0f0-0000-4000-8000-0000000000f0"
    if forgery.startswith("timecode"):
        forged["timing"]["timecode"]["frames"] += 7
    else:
        forged["lens"]["focusDistance"] += 1.0
    decode_sample(json.dumps(forged).encode())  # valid against the schema
    with _Recorder(tmp_path, "--json") as rec:
        rec.wait_for_port()
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
            for seq, s in [(0, good[0]), (1, good[1]), (2, forged), (2, good[2]), (3, good[3]), (4, good[4])]:
                _send_raw(sock, rec.port, json.dumps(s).encode(), seq, "json")
        assert rec.finish(signal.SIGTERM) == 0, rec.stderr
    doc = json.loads(rec.stdout)
    check_document(doc)
    c = doc["counters"]
    if forgery.startswith("timecode"):  # (before: ..., "00:00:00:09", "00:00:00:03", ... and late 1)
        assert _timecodes(tmp_path / "take.usda") == [f"00:00:00:0{i}" for i in range(5)], c
    assert c["late"] == 0 and c["conflict"] == 1 and c["stray"] == 0, c
    real, fake = good[2]["sampleId"], forged["sampleId"]
    [conflict] = doc["conflicts"]
    assert conflict["sequence"] == 2 and [x["sample_id"] for x in conflict["claimants"]] == [fake, real]
    lines = [line for line in rec.stderr.splitlines() if line.startswith("physcam: conflict: packet 2 ")]
    assert len(lines) == 1 and fake in lines[0] and real in lines[0], rec.stderr
    if forgery.startswith("timecode"):
        assert conflict["kept"] == real and [x["timecode"] for x in conflict["claimants"]] == ["00:00:00:09",
                                                                                             "00:00:00:02"]
        assert doc["frames"] == 5 and c["missing"] == 0
        assert _timecodes(tmp_path / "take.usda") == [f"00:00:00:0{i}" for i in range(5)]
        assert f"kept {real}" in lines[0]
    else:
        assert conflict["kept"] is None and "more than one agrees" in conflict["reason"]
        assert doc["frames"] == 4 and c["missing"] == 1
        assert _timecodes(tmp_path / "take.usda") == ["00:00:00:00", "00:00:00:01", "00:00:00:03", "00:00:00:04"]
        assert "kept neither" in lines[0]


def test_live_recover_judges_a_journals_claimants_as_the_recorder_does(tmp_path, capsys):
    """The journal keeps both claimants of packet 2, the second marked `"conflict": true`; `live recover`
    reads the mark and keeps the real 2 (its timecode agrees with frames 1 and 3), naming the conflict."""
    pytest.importorskip("pxr")
    from physcam.live.journal import Journal

    good = _samples(5)
    forged = copy.deepcopy(good[2])
    forged["sampleId"] = "urn:uuid:f0f0f0f0-0000-4000-8000-0000000000f0"
    forged["timing"]["timecode"]["frames"] += 7
    j = Journal.create(tmp_path / "take.usda", {"output": "take.usda", "report": None, "options": {}})
    for seq, s, conflict in [(0, good[0], False), (1, good[1], False), (2, forged, False), (2, good[2], True),
                             (3, good[3], False), (4, good[4], False)]:
        j.add_sample(s, seq, "cbor", conflict)
    j.close()
    assert b'"conflict":true' in j.path.read_bytes()
    assert main(["live", "recover", str(j.path), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["frames"] == 5 and [c["kept"] for c in doc["conflicts"]] == [good[2]["sampleId"]]
    assert _timecodes(tmp_path / "take.usda") == [f"00:00:00:0{i}" for i in range(5)]


@pytest.mark.parametrize("rival_frame, rival_timecode, kept, why", [
    (11, "00:00:00:19", 0, "the only one"),  # the review's forgery: the timestamp copied, the timecode 8 ahead
    (12, "00:00:00:11", 0, "the only one"),  # a timestamp a frame late gives it away alone
    (11, "00:00:00:11", None, "more than one"),  # the same clocks (other lens values): no telling them apart
    (None, "00:00:00:11", None, "more than one"),  # no timestamp, the same timecode
    (10, "00:00:00:10", None, "none agrees"),  # and the "real" one stamped frame 9 (below): neither fits
])
def test_judge_claimants_keeps_the_one_its_neighbours_clocks_agree_with(rival_frame, rival_timecode, kept, why):
    """At 24 fps, packets 10 and 12 are frames 10 and 12 (00:00:00:10, :12) by both clocks; packet 11 is
    claimed by the real frame 11 and a rival. A clock counts where both frames carry it: frames apart must
    be packets apart. (Worked by hand.)"""
    from physcam.live.take import judge_claimants

    at = lambda frame, tc: TrackedFrame(time_ns=None if frame is None else T0_NS + frame * 10**9 // 24,  # noqa: E731
                                        timecode=tc, rate=Fraction(24))
    real, rival = at(11, "00:00:00:11"), at(rival_frame, rival_timecode)
    if kept is None and why == "none agrees":
        real = at(9, "00:00:00:09")  # a real frame that the neighbours do not vouch for either
    neighbours = [(at(10, "00:00:00:10"), 10), (at(12, "00:00:00:12"), 12)]
    assert judge_claimants([(real, 11), (rival, 11)], neighbours)[0] == kept
    assert why in judge_claimants([(real, 11), (rival, 11)], neighbours)[1]
    assert judge_claimants([(real, 11), (rival, 11)], []) == (None, "no undisputed neighbour to judge by")


@pytest.mark.slow
@needs_proc_net_udp
def test_a_take_named_in_upper_case_is_written(tmp_path):
    """USD tells a layer's format by its extension in any case (``TAKE.USDA`` is text). The recorder took the
    name at the start of a take, and its USD writer, which knew only lower-case names, refused it at the end
    (the take was left in its journal, which `live recover` could not write either). Now one rule says both
    (``physcam.usd_names``): 10 frames recorded to TAKE.USDA are written there, as text, all 10."""
    pytest.importorskip("pxr")
    samples = _samples(10)
    with _Recorder(tmp_path, "--count", "10", out=tmp_path / "TAKE.USDA") as rec:
        rec.wait_for_port()
        with Sender("127.0.0.1", rec.port, encoding="cbor") as tx:
            tx.stream(samples, 240)
        assert rec.finish() == 0, rec.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["TAKE.USDA"]
    assert (tmp_path / "TAKE.USDA").read_bytes().startswith(b"#usda 1.0")
    assert _sequence_numbers(tmp_path / "TAKE.USDA") == list(range(10))


def test_a_take_name_usd_cannot_write_is_refused_before_listening(tmp_path, capsys):
    assert main(["live", "record", str(tmp_path / "take.txt"), "--port", "0", "--duration", "0.1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "take.txt: a USD file's name ends in .usda, .usd or .usdc" in err, err
    assert list(tmp_path.iterdir()) == []
