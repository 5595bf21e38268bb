"""What a clip records reaches OpenTrackIO and USD, or is refused in words (issue 40 item 7): a zoom's
focal length as each sample's pinhole, an anamorphic squeeze where physcam's own USD reader looks, a
RED clip's timecodes refused without a frame rate rather than dropped."""

from __future__ import annotations

import json
import math

import pytest

from physcam.cli import main
from physcam.metadata import load

from test_metadata_readers import BMD, RED, VENICE


def _zoom_clip(tmp_path):
    """The real VENICE clip (32 mm on every row) with its Focal Length (mm) column made a zoom from 24 mm
    to 70 mm, 2 mm a frame from row 1 (repeating): the focus and timecodes are the file's."""
    lines = VENICE[0].read_text(encoding="utf-8").splitlines()
    header = [h.strip('"') for h in lines[0].split(",")]
    i = header.index("Focal Length (mm)")
    out = [lines[0]]
    for k, line in enumerate(lines[1:]):
        cells = line.split(",")
        cells[i] = f'"{24 + 2 * (k % 24)}"' if cells[i].startswith('"') else str(24 + 2 * (k % 24))
        out.append(",".join(cells))
    p = tmp_path / "zoom.csv"
    p.write_text("\n".join(out) + "\n", encoding="utf-8")
    return p


def _thin_lens_pinhole(f, mark):
    """s' of a thin lens focused at ``mark`` from the film: s + s' = mark, 1/s + 1/s' = 1/f (by hand)."""
    return mark / 2 * (1 - math.sqrt(1 - 4 * f / mark))


def test_a_zoom_reaches_every_opentrackio_sample(tmp_path, capsys):
    pytest.importorskip("jsonschema")
    clip = _zoom_clip(tmp_path)
    rec = load(clip)
    assert len({f.focal_length_mm for f in rec.frames}) == 24
    assert main(["metadata", "opentrackio", str(clip), "--fps", "24"]) == 0
    samples = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert len(samples) == len(rec.frames)
    for s, f in zip(samples, rec.frames):
        assert s["lens"]["pinholeFocalLength"] == pytest.approx(_thin_lens_pinhole(f.focal_length_mm, f.focus_mm),
                                                                rel=1e-9)
    assert "nominalFocalLength" not in samples[0]["static"].get("lens", {})  # undefined for a zoom (schema)
    pins = [s["lens"]["pinholeFocalLength"] for s in samples[:24]]
    assert pins == sorted(pins) and pins[-1] > 70.0  # the zoom from 24 to 70 mm, each a little longer at focus


def test_live_send_clip_carries_the_zoom(tmp_path, capsys):
    pytest.importorskip("jsonschema")
    clip = _zoom_clip(tmp_path)
    rec = load(clip)
    assert main(["live", "send", "--clip", str(clip), "--sensor", "S35", "--fps", "24", "--frames", "30", "--print"]) == 0
    samples = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert len(samples) == 30
    for s, f in zip(samples, rec.frames):
        assert s["lens"]["pinholeFocalLength"] == pytest.approx(_thin_lens_pinhole(f.focal_length_mm, f.focus_mm),
                                                                rel=1e-9)


def test_a_prime_keeps_its_nominal_focal_length_and_the_same_pinhole_as_live_send(capsys):
    """RED's 40 mm prime: static nominalFocalLength 40; each sample's pinhole the thin lens's s' at the
    frame's focus (410 mm: 40 / 2 ... by hand), the value live send --clip computes through with_optics."""
    pytest.importorskip("jsonschema")
    assert main(["metadata", "opentrackio", *map(str, RED)]) == 0
    a = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert a[0]["static"]["lens"]["nominalFocalLength"] == 40.0
    assert a[0]["lens"]["pinholeFocalLength"] == pytest.approx(_thin_lens_pinhole(40.0, 410.0), rel=1e-9)
    assert main(["live", "send", "--clip", *map(str, RED), "--print"]) == 0
    b = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    for x, y in zip(a, b):
        assert y["lens"]["pinholeFocalLength"] == pytest.approx(x["lens"]["pinholeFocalLength"], rel=1e-6)


def test_an_anamorphic_clip_reads_back_with_its_squeeze(tmp_path):
    """The Blackmagic sample records anamorphic 2x (anamorphic_enable 1): physcam's own USD reader
    (physcam.live.usd_io.frames_from_usd, which reads physcam:live:anamorphicSqueeze) gives 2, as
    does the lens model's squeeze."""
    pytest.importorskip("pxr")
    from pxr import Usd

    from physcam.live.usd_io import frames_from_usd

    assert load(BMD).squeeze == 2.0
    out = tmp_path / "ana.usda"
    assert main(["metadata", "usd", str(BMD), "-o", str(out), "--sensor", "S35"]) == 0
    frames = frames_from_usd(out)
    assert frames and all(f.squeeze == 2.0 for f in frames)
    stage = Usd.Stage.Open(str(out))
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    assert cam.GetAttribute("physcam:live:anamorphicSqueeze").Get(0) == 2.0
    assert stage.GetPrimAtPath("/Cameras/Camera/Pinhole").GetAttribute("squeeze").Get(0) == 2.0


def test_red_timecodes_without_a_frame_rate_are_refused_not_dropped(capsys):
    """The RED frames CSV alone has timecodes (23:17:21:08 ...) but no FPS (the static CSV has it):
    refused in one sentence; with --fps 24 its timecodes are sent."""
    pytest.importorskip("jsonschema")
    assert main(["metadata", "opentrackio", str(RED[0])]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "records timecodes but no frame rate" in err and "--fps" in err
    assert main(["metadata", "opentrackio", str(RED[0]), "--fps", "24"]) == 0
    s = json.loads(capsys.readouterr().out.splitlines()[0])
    assert (s["timing"]["timecode"]["hours"], s["timing"]["timecode"]["frames"]) == (23, 8)
