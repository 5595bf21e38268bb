"""A zoom lens through OpenTrackIO (issue 45 phase 2): a focus-and-zoom pull out through `physcam live
send` (and a zoom clip through `live send --clip` / `metadata opentrackio`), back through `live record`,
with the focal length per frame within 0.01 mm of physcam's paraxial prediction at that zoom and focus.

The prediction is computed here through the optics layer alone (`physcam.optics.zoom` for the zoom
position, `physcam.optics.focusing.technical_planes` for the best-match pinhole at the mark), not
through `physcam.live` or the on-set report; the samples are validated against the OpenTrackIO 1.0.1
schema with jsonschema directly (the published file, shipped as package data).
"""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from importlib import resources

import pytest

from physcam.cli import main
from physcam.lens.library import load_lens
from physcam.lens.zoom import prescription_at
from physcam.optics.focusing import technical_planes
from physcam.optics.zoom import efl_at, encoder_for_focal_length
from _udp import needs_proc_net_udp, recorder_port

CANON = "canon_ef_70_200mm_f2_8_zoom"


def _validator():
    jsonschema = pytest.importorskip("jsonschema")
    text = resources.files("physcam.data").joinpath("opentrackio-schema-1.0.1.json").read_text(encoding="utf-8")
    return jsonschema.Draft202012Validator(json.loads(text))


def _pinhole(lens, u, mark_mm):
    """physcam's paraxial best-match pinhole of the zoom lens at encoder u focused at the mark."""
    return technical_planes(prescription_at(lens, u), mark_mm).pinhole_focal_length_mm


def _send(capsys, *args):
    assert main(["live", "send", *args, "--print"]) == 0
    return [json.loads(line) for line in capsys.readouterr().out.splitlines()]


PULL = ["--lens", CANON, "--sensor", "Super 35", "--focus", "2m", "--focus-to", "5m", "--zoom", "80mm",
        "--zoom-to", "180mm", "--fstop", "4", "--frames", "4"]


def test_a_focus_and_zoom_pull_sends_each_frames_focal_length_and_zoom_encoder(capsys):
    lens = load_lens(CANON)
    v = _validator()
    samples = _send(capsys, *PULL)
    assert len(samples) == 4
    for s in samples:
        assert not list(v.iter_errors(s))
    u0, u1 = encoder_for_focal_length(lens, 80.0), encoder_for_focal_length(lens, 180.0)
    assert efl_at(lens, 0.0) < efl_at(lens, 1.0)  # the Canon's first position is its wide end: encoder = u
    for k, s in enumerate(samples):
        u, mark = u0 + (u1 - u0) * k / 3, 2000.0 + 1000.0 * k
        assert s["lens"]["encoders"]["zoom"] == pytest.approx(u, abs=1e-12)
        assert s["lens"]["focusDistance"] == pytest.approx(mark / 1000.0, rel=1e-12)
        assert s["lens"]["pinholeFocalLength"] == pytest.approx(_pinhole(lens, u, mark), abs=0.01)
    # focused closer than infinity, a unit-focused lens frames longer than its EFL at each end of the pull
    assert samples[0]["lens"]["pinholeFocalLength"] > 80.0 and samples[-1]["lens"]["pinholeFocalLength"] > 180.0
    static = samples[0]["static"]
    assert "nominalFocalLength" not in static.get("lens", {})  # schema 1.0.1: undefined for a zoom
    lo, hi = samples[0]["custom"]["physcam:focalLengthRange"]
    assert (lo, hi) == pytest.approx((72.118, 193.910), abs=5e-4)  # docs/zoom.md, measured against optiland


def test_the_opentrackio_zoom_encoder_runs_wide_to_tele(capsys):
    """OpenTrackIO's zoom encoder is 0 at the wide end (schema 1.0.1): the Canon's three positions joined
    tele first make a lens whose physcam encoder 0 is 194 mm; it sends 1 - u."""
    from physcam.lens.zoom import join_positions
    from physcam.live.camera import opentrackio_zoom, physcam_zoom

    lens = load_lens(CANON)
    flipped = join_positions([prescription_at(lens, u) for u in (1.0, 0.5, 0.0)])
    assert efl_at(flipped, 0.0) == pytest.approx(efl_at(lens, 1.0), rel=1e-12)
    assert opentrackio_zoom(flipped, 0.0) == 1.0 and opentrackio_zoom(lens, 0.0) == 0.0
    assert opentrackio_zoom(flipped, 0.25) == pytest.approx(0.75)
    assert physcam_zoom(flipped, opentrackio_zoom(flipped, 0.3)) == pytest.approx(0.3)


def test_a_zoom_position_on_a_prime_is_refused_in_one_line(capsys):
    assert main(["live", "send", "--lens", "dgauss_50mm", "--zoom", "50mm", "--frames", "1", "--print"]) == 2
    assert "has no zoom table" in capsys.readouterr().err


def test_the_recorder_solves_a_frame_that_sends_only_the_zoom_encoder(capsys):
    """Strip the pinhole from the sent samples: `live record --lens` solves each frame through the zoom
    lens at the sample's zoom encoder and focus, and gets the sender's pinhole back within 0.01 mm."""
    from physcam.live.frames import frame_from_sample
    from physcam.live.record import solve_frames

    lens = load_lens(CANON)
    samples = _send(capsys, *PULL)
    static, frames = None, []
    for s in samples:
        static = s.get("static") or static
        bare = dict(s, lens={k: v for k, v in s["lens"].items() if k not in ("pinholeFocalLength",)})
        frames.append(frame_from_sample(bare, static=static))
    assert frames[0].focal_range_mm == pytest.approx((72.118, 193.910), abs=5e-4)
    solved = solve_frames(frames, lens=lens)
    for s, sf in zip(samples, solved):
        assert sf.report.pinhole[0] == pytest.approx(s["lens"]["pinholeFocalLength"], abs=0.01)


@pytest.mark.slow
@needs_proc_net_udp
def test_a_focus_and_zoom_pull_comes_back_through_live_record(tmp_path):
    pytest.importorskip("pxr")
    lens = load_lens(CANON)
    out, rep = tmp_path / "take.usda", tmp_path / "take.csv"
    proc = subprocess.Popen([sys.executable, "-m", "physcam", "live", "record", str(out), "--port", "0",
                             "--host", "127.0.0.1", "--count", "4", "--duration", "60", "--report", str(rep),
                             "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    port, _ = recorder_port(proc)
    assert main(["live", "send", *PULL, "--port", str(port), "--cbor"]) == 0
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 0, stderr
    rows = list(csv.DictReader(rep.open()))
    assert len(rows) == 4
    u0, u1 = encoder_for_focal_length(lens, 80.0), encoder_for_focal_length(lens, 180.0)
    for k, r in enumerate(rows):
        u, mark = u0 + (u1 - u0) * k / 3, 2000.0 + 1000.0 * k
        assert float(r["focus_from_film_mm"]) == pytest.approx(mark, rel=1e-12)
        assert float(r["pinhole_focal_length_mm"]) == pytest.approx(_pinhole(lens, u, mark), abs=0.01)


def _zoom_clip(tmp_path):
    """The real VENICE clip (32 mm on every row) with its Focal Length (mm) column made a zoom from 80 mm
    to 180 mm in 10 steps, its first 12 rows: the focus and timecodes are the file's."""
    from test_metadata_readers import VENICE

    lines = VENICE[0].read_text(encoding="utf-8").splitlines()
    header = [h.strip('"') for h in lines[0].split(",")]
    i = header.index("Focal Length (mm)")
    out = [lines[0]]
    for k, line in enumerate(lines[1:13]):
        cells = line.split(",")
        f = 80 + 10 * (k % 11)
        cells[i] = f'"{f}"' if cells[i].startswith('"') else str(f)
        out.append(",".join(cells))
    p = tmp_path / "zoom.csv"
    p.write_text("\n".join(out) + "\n", encoding="utf-8")
    return p


@pytest.fixture
def metadata_tests_on_path():
    from pathlib import Path

    here = str(Path(__file__).resolve().parents[1] / "metadata")
    sys.path.insert(0, here)
    yield
    sys.path.remove(here)


@pytest.mark.slow
def test_a_zoom_clip_goes_out_at_each_frames_recorded_focal_length(tmp_path, capsys, metadata_tests_on_path):
    from physcam.metadata import load

    lens = load_lens(CANON)
    v = _validator()
    clip = _zoom_clip(tmp_path)
    rec = load(clip)
    assert main(["metadata", "opentrackio", str(clip), "--fps", "24", "--lens", CANON]) == 2
    assert "give the sensor" in capsys.readouterr().err
    assert main(["metadata", "opentrackio", str(clip), "--fps", "24", "--lens", CANON, "--sensor", "S35"]) == 0
    a = [json.loads(line) for line in capsys.readouterr().out.splitlines()][:12]
    b = _send(capsys, "--clip", str(clip), "--sensor", "S35", "--fps", "24", "--frames", "12", "--lens", CANON)
    assert len(a) == len(b) == 12
    for sa, sb, f in zip(a, b, rec.frames):
        assert not list(v.iter_errors(sa))
        assert not list(v.iter_errors(sb))
        u = encoder_for_focal_length(lens, f.focal_length_mm)
        want = _pinhole(lens, u, f.focus_mm)
        assert sa["lens"]["pinholeFocalLength"] == pytest.approx(want, abs=0.01)
        assert sb["lens"]["pinholeFocalLength"] == pytest.approx(want, abs=0.01)
        assert sa["lens"]["encoders"]["zoom"] == pytest.approx(u, abs=1e-9)
    assert "nominalFocalLength" not in a[0]["static"].get("lens", {})
    assert a[0]["custom"]["physcam:focalLengthRange"] == pytest.approx([72.118, 193.910], abs=5e-4)
