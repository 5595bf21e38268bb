"""`physcam live` from the command line: validate, and a record run fed by the sender."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

from physcam.cli import main
from physcam.live.camera import camera_frames, frames_to_samples
from physcam.live.sender import Sender
from physcam.optics.sensors import find_sensor
from _udp import needs_proc_net_udp, recorder_port, socket_inodes, udp_socket_inodes, wait_until_read

DATA = Path(__file__).parent / "data"


def test_validate_examples_and_a_broken_sample(tmp_path, capsys):
    assert main(["live", "validate", *map(str, sorted(DATA.glob("*.json")))]) == 0
    broken = json.loads((DATA / "recommended_dynamic_example.json").read_text())
    broken["lens"]["fStop"] = 0
    (tmp_path / "b.json").write_text(json.dumps(broken))
    capsys.readouterr()
    assert main(["live", "validate", str(tmp_path / "b.json"), "--json"]) == 2
    out = json.loads(capsys.readouterr().out)
    assert out["samples"][0]["problems"][0] == {"path": "$.lens.fStop", "rule": "exclusiveMinimum",
                                                "message": "0 is less than or equal to the minimum of 0.0"}


@pytest.mark.slow
def test_record_a_sent_take(tmp_path):
    pytest.importorskip("pxr")
    from pxr import Usd

    out, rep = tmp_path / "take.usda", tmp_path / "take.csv"
    proc = subprocess.Popen([sys.executable, "-m", "physcam", "live", "record", str(out), "--port", "0",
                             "--host", "127.0.0.1", "--count", "30", "--duration", "60", "--report", str(rep),
                             "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    frames = camera_frames(sensor=find_sensor("ALEXA 35"), frames=30, rate=24, focus_mm=2000.0, focus_to_mm=3000.0,
                           fstop=4.0, focal_length_mm=32.0)
    samples = list(frames_to_samples(frames))
    port, said = recorder_port(proc)  # --port 0: the system's free port, which the recorder says it holds
    assert said == "" and port != 0
    if Path("/proc/net/udp").exists():  # and it is the recorder's own socket, no other process's
        assert udp_socket_inodes(port) and udp_socket_inodes(port) <= socket_inodes(proc.pid)
    with Sender("127.0.0.1", port, encoding="cbor") as tx:
        tx.stream(samples, 240)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 0, stderr
    summary = json.loads(stdout)
    from _documents import check_document

    assert check_document(summary) == "physcam.live_record"
    assert summary["frames"] == 30 and summary["counters"]["delivered"] >= 30
    stage = Usd.Stage.Open(str(out))
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    assert cam.GetAttribute("physcam:live:sequenceNumber").GetTimeSamples() == [float(i) for i in range(30)]
    rows = list(csv.DictReader(rep.open()))
    assert [float(r["focus_from_film_mm"]) for r in rows] == pytest.approx(
        [s["lens"]["focusDistance"] * 1000 for s in samples], rel=1e-12)


def test_port_0_is_a_port_no_other_socket_holds_and_the_recorder_says_it(tmp_path, monkeypatch, capsys):
    """Round 18's flake: a test picked a free port, closed it and started a recorder on it; another
    test's socket took it first, and the recorder exited 2 before journaling. Here a socket holds port
    P (no SO_REUSEADDR): a recorder told P says so in one line, exit 2, no journal left; told 0, it takes
    another port, says it ("listening on"), and its empty take names that same port."""
    import re
    import socket

    pytest.importorskip("pxr")
    monkeypatch.chdir(tmp_path)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as blocker:
        blocker.bind(("127.0.0.1", 0))
        held = blocker.getsockname()[1]
        capsys.readouterr()
        assert main(["live", "record", "take.usda", "--port", str(held), "--host", "127.0.0.1",
                     "--duration", "0.1"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith(f"physcam: error: cannot listen on 127.0.0.1:{held}: "), err
        assert not list(tmp_path.glob("take.usda*"))
        assert main(["live", "record", "take.usda", "--port", "0", "--host", "127.0.0.1", "--duration", "0.1"]) == 2
    lines = capsys.readouterr().err.splitlines()
    said = re.fullmatch(r"physcam: listening on UDP 127\.0\.0\.1:(\d+)", lines[0])
    assert said and int(said[1]) not in (0, held), lines
    assert lines[1:] == [f"physcam: error: no valid samples arrived on port {said[1]} (received 0 packets); "
                         "nothing written"]


def test_a_json_lens_report_plays_back_as_valid_samples(tmp_path):
    from physcam.cli.live import _frames_from_report
    from physcam.live.record import solve_frames, write_lens_report
    from physcam.live.sample import validate_sample

    frames = camera_frames(sensor=find_sensor("ALEXA 35"), frames=5, rate=23.976, focus_mm=2000.0, fstop=2.0,
                           focal_length_mm=50.0)
    rep = write_lens_report(tmp_path / "r.json", solve_frames(frames))
    back = _frames_from_report(rep)
    samples = list(frames_to_samples(back))
    for s in samples:
        validate_sample(s)
    assert samples[0]["timing"]["sampleRate"] == {"num": 24000, "denom": 1001}
    assert samples[0]["static"]["camera"]["activeSensorPhysicalDimensions"] == {"width": 27.99, "height": 19.22}
    assert [s["lens"]["focusDistance"] for s in samples] == [2.0] * 5


@pytest.mark.slow
def test_multicast_on_loopback():
    from physcam.live.receiver import Receiver, multicast_group

    frames = camera_frames(sensor=find_sensor("ALEXA 35"), frames=50, rate=48, focus_mm=2000.0, fstop=2.0,
                           focal_length_mm=50.0)
    samples = list(frames_to_samples(frames))
    group = multicast_group(1)
    with Receiver(0, group=group, interface="127.0.0.1") as rx, Sender(group, rx.port, encoding="cbor") as tx:
        tx.stream(samples, 1000)
        got, deadline = [], time.monotonic() + 10
        while len(got) < 50 and time.monotonic() < deadline:
            item = rx.get(timeout=0.1)
            if item is not None:
                got.append(item)
    assert [g.sample["sampleId"] for g in got] == [s["sampleId"] for s in samples]
    assert {g.encoding for g in got} == {"cbor"}


def test_a_multicast_sender_says_the_groups_source_number(capsys):
    """OpenTrackIO ties the multicast group 239.135.1.N to source number N: `live send --multicast 3` sent to
    239.135.1.3 samples that said source 1 (a review found it). Every sample now says 3, as the group does."""
    from physcam.cli import main
    from physcam.live.sample import validate_sample

    assert main(["live", "send", "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--sensor", "S35",
                 "--frames", "4", "--multicast", "3", "--print"]) == 0
    samples = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert len(samples) == 4 and {s["sourceNumber"] for s in samples} == {3}
    for s in samples:
        validate_sample(s)
    assert main(["live", "send", "--focal", "35", "--fstop", "2.8", "--focus", "3m", "--sensor", "S35",
                 "--frames", "2", "--print"]) == 0
    assert {json.loads(x)["sourceNumber"] for x in capsys.readouterr().out.splitlines()} == {1}


@pytest.mark.slow
@needs_proc_net_udp
@pytest.mark.parametrize("sig", ["SIGTERM", "SIGHUP", "SIGINT"])
def test_a_signal_ends_the_recording_and_the_take_is_written(tmp_path, sig):
    """`physcam live record` stopped by SIGTERM (a process manager), SIGHUP (the terminal closed) or
    SIGINT (Ctrl-C) writes what it received. Two of the 20 samples sent are out of range (fStop 1e308,
    and 1e5000 as a CBOR decimal fraction): they are refused, the other 18 recorded."""
    import signal
    from decimal import Decimal

    pytest.importorskip("pxr")
    from pxr import Usd

    out = tmp_path / "take.usda"
    proc = subprocess.Popen([sys.executable, "-m", "physcam", "live", "record", str(out), "--port", "0",
                             "--host", "127.0.0.1", "--duration", "120", "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    frames = camera_frames(sensor=find_sensor("ALEXA 35"), frames=20, rate=24, focus_mm=2000.0, fstop=4.0,
                           focal_length_mm=32.0)
    samples = list(frames_to_samples(frames))
    samples[5]["lens"]["fStop"] = 1e308
    samples[9]["lens"]["fStop"] = Decimal("1e5000")
    try:
        port, _ = recorder_port(proc)
        with Sender("127.0.0.1", port, encoding="cbor") as tx:
            tx.stream(samples, 240)
        # the recorder has read all 20 (the first pays for the schema validator): its receiver's stop()
        # waits for the one being handled and hands on what it holds
        wait_until_read(proc, port)
        proc.send_signal(getattr(signal, sig))
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:  # a failed wait: the recorder would run out its 120 s
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, stderr
    summary = json.loads(stdout)
    assert summary["interrupted"] is True and summary["frames"] == 18
    assert summary["counters"]["invalid"] == 1 and summary["counters"]["refused"] == 1
    stage = Usd.Stage.Open(str(out))
    seq = stage.GetPrimAtPath("/Cameras/Camera").GetAttribute("physcam:live:sequenceNumber")
    assert [seq.Get(t) for t in seq.GetTimeSamples()] == [i for i in range(20) if i not in (5, 9)]
