"""A recorded camera clip replayed as OpenTrackIO (issue 31 item 7): `physcam live send --clip` and
`physcam live play --clip` over loopback UDP into `physcam live record`.

The expected focus and iris are read here from the metadata files' own columns (ARRI Meta Extract:
``Lens Focus Distance`` in the ``Lens Distance Unit``, ``Lens Linear Iris`` in 1/1000 stop with
1000 = T1, so T = sqrt(2)^((n - 1000) / 1000); REDline: ``Focus Distance`` mm, ``Aperture``), not
from physcam's readers; the breathing pinhole of a named lens from `physcam lens breathing`.
"""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from physcam.cli import main
from physcam.live.sample import decode_sample
from _udp import needs_proc_net_udp, recorder_port

DATA = Path(__file__).resolve().parents[1] / "data" / "camera-metadata"
ARRI = DATA / "arri" / "B001C001_180327_R1ZA.mov.csv"
RED = [DATA / "red" / "A001_C066_0303LZ_001.frames.csv", DATA / "red" / "A001_C066_0303LZ_001.static.csv"]


def _arri_columns():
    rows = list(csv.DictReader(ARRI.open(encoding="utf-8"), delimiter="\t"))
    assert {r["Lens Distance Unit"] for r in rows} == {"Meter"}
    focus = [float(r["Lens Focus Distance"]) * 1000.0 for r in rows]
    tstop = [math.sqrt(2.0) ** ((float(r["Lens Linear Iris"]) - 1000.0) / 1000.0) for r in rows]
    return [r["Master TC"].strip() for r in rows], focus, tstop


def _red_columns():
    rows = list(csv.DictReader(RED[0].open(encoding="utf-8")))
    return [r["Timecode"] for r in rows], [float(r["Focus Distance"]) for r in rows], [float(r["Aperture"])
                                                                                      for r in rows]


def _record(tmp_path, count, send_args, *record_args):
    """Start `live record` for ``count`` samples, run ``send_args`` (a physcam command line, in this
    process) at its port, and return the lens report's rows."""
    out, rep = tmp_path / "take.usda", tmp_path / "take.csv"
    proc = subprocess.Popen([sys.executable, "-m", "physcam", "live", "record", str(out), "--port", "0",
                             "--host", "127.0.0.1", "--count", str(count), "--duration", "60", "--report", str(rep),
                             "--json", *record_args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    port, _ = recorder_port(proc)
    assert main([*send_args, "--port", str(port), "--cbor"]) == 0
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 0, stderr
    assert json.loads(stdout)["frames"] == count
    return list(csv.DictReader(rep.open()))


@pytest.mark.slow
@needs_proc_net_udp
def test_an_arri_clip_plays_into_the_recorder_frame_by_frame(tmp_path):
    pytest.importorskip("pxr")
    tcs, focus, tstop = _arri_columns()
    assert len(set(focus)) > 50  # the clip pulls focus
    # the file gives a T-stop only: the recorder is given an f-stop below it (a T-stop is never faster)
    rows = _record(tmp_path, len(focus), ["live", "play", "--clip", str(ARRI), "--rate", "1000"], "--fstop", "1.4")
    assert [r["timecode"] for r in rows] == tcs
    assert [float(r["focus_from_film_mm"]) for r in rows] == pytest.approx(focus, rel=1e-12)
    assert [float(r["tstop"]) for r in rows] == pytest.approx(tstop, rel=1e-3)


@pytest.mark.slow
@needs_proc_net_udp
def test_a_played_drop_frame_clip_records_without_missing_frames(tmp_path):
    """`live play --clip r2997df` into `live record`: 60 gapless rows through the minute at 29.97 drop-frame;
    the recorder counted 2 missing (00:00:59;29 -> 00:01:00;02 read as non-drop) before the flag was sent."""
    pytest.importorskip("pxr")
    clip = DATA / "arri-edited" / "r2997df.mov.csv"  # the reviewer's copy (its README.txt)
    proc = subprocess.Popen([sys.executable, "-m", "physcam", "live", "record", str(tmp_path / "take.usda"),
                             "--port", "0", "--host", "127.0.0.1", "--count", "60", "--duration", "60",
                             "--fstop", "1.4", "--report", str(tmp_path / "take.csv"), "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    port, _ = recorder_port(proc)
    assert main(["live", "play", "--clip", str(clip), "--rate", "1000", "--port", str(port), "--cbor"]) == 0
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 0, stderr
    out = json.loads(stdout)
    assert out["counters"]["missing"] == 0 and out["frames"] == 60
    rows = list(csv.DictReader((tmp_path / "take.csv").open()))
    tcs = [r["Master TC"].strip() for r in csv.DictReader(clip.open(encoding="utf-8"), delimiter="\t")]
    assert [r["timecode"] for r in rows] == tcs and tcs[9:12] == ["00:00:59;29", "00:01:00;02", "00:01:00;03"]


@pytest.mark.slow
@needs_proc_net_udp
def test_a_red_clip_sent_with_a_named_lens_records_its_focus_iris_and_breathing(tmp_path, capsys):
    pytest.importorskip("pxr")
    tcs, focus, stop = _red_columns()
    rows = _record(tmp_path, len(focus), ["live", "send", "--clip", *map(str, RED), "--lens", "dgauss_50mm"])
    assert [r["timecode"] for r in rows] == tcs
    assert [float(r["focus_from_film_mm"]) for r in rows] == pytest.approx(focus, rel=1e-12)
    assert [float(r["fstop"]) for r in rows] == pytest.approx(stop, rel=1e-12)
    capsys.readouterr()
    assert main(["lens", "breathing", "--lens", "dgauss_50mm", "--focus", f"{focus[0]:g}mm", "--json"]) == 0
    oracle = json.loads(capsys.readouterr().out)["rows"][0]
    assert float(rows[0]["pinhole_focal_length_mm"]) == pytest.approx(oracle["breathing_focal_length_mm"], rel=1e-6)


def test_send_clip_prints_the_clips_samples_at_its_rate(capsys):
    tcs, focus, tstop = _arri_columns()
    capsys.readouterr()
    assert main(["live", "send", "--clip", str(ARRI), "--frames", "3", "--print"]) == 0
    samples = [decode_sample(line.encode()) for line in capsys.readouterr().out.splitlines()]
    assert len(samples) == 3
    assert samples[0]["timing"]["sampleRate"] == {"num": 24, "denom": 1}
    tc = samples[0]["timing"]["timecode"]
    assert f"{tc['hours']:02d}:{tc['minutes']:02d}:{tc['seconds']:02d}:{tc['frames']:02d}" == tcs[0]
    assert [s["lens"]["focusDistance"] * 1000 for s in samples] == pytest.approx(focus[:3], rel=1e-12)
    assert [s["lens"]["tStop"] for s in samples] == pytest.approx(tstop[:3], rel=1e-3)
    assert "fStop" not in samples[0]["lens"]  # the file gives no f-stop: none is made up


def test_a_clip_refuses_the_generated_takes_options(capsys):
    assert main(["live", "send", "--clip", str(ARRI), "--focus-to", "2m", "--print"]) == 2
    assert "--clip" in capsys.readouterr().err
