"""A recorded take's time samples written in one Sdf batch (round 13) give the file the per-sample
USD writer gave: the same bytes (.usdc and .usda), the same time samples read back by usd-core, and
a stage usd-core's validators pass.

The reference is the writer's own per-sample path (``batch=False``: ``Usd.Attribute.Set`` at each
frame, the code before round 13). Byte for byte against main's writer itself (git 3757dee4, 600
frames of benchmarks/live_usd.py's take, .usdc and .usda): identical, checked once by hand
(docs/performance.md, "round 13").
"""

from __future__ import annotations

import dataclasses

import pytest

from physcam.lens.library import load_lens
from physcam.live.camera import CameraMove, camera_frames, camera_samples, frames_to_samples
from physcam.live.frames import frame_from_sample
from physcam.live.record import _write_recording, solve_frames
from physcam.optics.sensors import find_sensor

pytest.importorskip("pxr")

SOURCE = "urn:uuid:00000000-0000-4000-8000-000000000013"


def _spherical_take():
    """48 frames at 24 fps of a moving camera, a focus pull and a lens shift; Brown-Conrady distortion
    from the 17th frame on (its attributes and Omniverse's distortion schema first appear mid-take),
    sequence numbers, timecode and the source in every sample."""
    frames = camera_frames(sensor=find_sensor("ALEXA 35"), frames=48, rate=24, focus_mm=1500.0, focus_to_mm=6000.0,
                           fstop=2.8, focal_length_mm=35.0, t0_ns=0, shift_mm=(0.4, -0.2), distortion=False,
                           move=CameraMove(velocity_m_s=(0.2, 0.5, 0.0), rate_deg_s=(15.0, -3.0, 1.0)))
    frames = [f if i < 16 else dataclasses.replace(f, distortion={"model": "Brown-Conrady U-D",
                                                                  "radial": [-2e-5 - 1e-7 * i, 0.0, 1e-8],
                                                                  "tangential": [1e-6, 0.0]})
              for i, f in enumerate(frames)]
    out, static = [], None
    for s in frames_to_samples(frames, static_every=24, source_id=SOURCE):
        static = s.get("static", static)
        out.append(frame_from_sample(s, static=static))
    return solve_frames(out)


def _anamorphic_take():
    """A front anamorphic's take (two entrance pupils), the third sample carrying its horizontal pupil over."""
    samples = camera_samples(sensor=find_sensor("ALEXA 35"), frames=6, rate=24, focus_mm=3000.0, focus_to_mm=1500.0,
                             lens=load_lens("neil_front_anamorphic_2x"), distortion=False, t0_ns=0)
    del samples[2]["custom"]
    return solve_frames([frame_from_sample(s) for s in samples])


def _samples_read_back(path) -> dict:
    """Every attribute of every prim, read by usd-core: (its time samples and their values, its default)."""
    from pxr import Usd

    stage = Usd.Stage.Open(str(path))
    out = {}
    for prim in stage.Traverse():
        for attr in prim.GetAttributes():
            times = attr.GetTimeSamples()
            out[str(attr.GetPath())] = ([(t, attr.Get(Usd.TimeCode(t))) for t in times], attr.Get())
    return out


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("take", [_spherical_take, _anamorphic_take], ids=["spherical", "anamorphic"])
def test_the_batched_writer_writes_what_the_per_sample_writer_wrote(tmp_path, take):
    from pxr import Usd

    from physcam.usd.validate import validation_errors

    solved = take()
    for ext in ("usdc", "usda"):
        new = _write_recording(tmp_path / f"new.{ext}", solved, rate=None, meters_per_unit=0.01,
                               path="/Cameras/Camera", resolution=(4096, None), force=False, batch=True)
        old = _write_recording(tmp_path / f"old.{ext}", solved, rate=None, meters_per_unit=0.01,
                               path="/Cameras/Camera", resolution=(4096, None), force=False, batch=False)
        assert new.read_bytes() == old.read_bytes(), ext
        back = _samples_read_back(new)
        assert back == _samples_read_back(old)
        assert validation_errors(Usd.Stage.Open(str(new))) == []
    # what the batch wrote is the take: one time sample per frame on the sampled attributes
    sampled = {k: v for k, v in back.items() if v[0]}
    assert len(back["/Cameras/Camera.physcam:live:sequenceNumber"][0]) == len(solved)
    assert len(back["/Cameras/Camera.xformOp:rotateZXY"][0]) == len(solved)
    assert all(len(v[0]) <= len(solved) for v in sampled.values())
    if take is _spherical_take:  # the distortion from the 17th frame on, in both forms
        assert len(back["/Cameras/Camera.physcam:live:distortionRadial"][0]) == len(solved) - 16
        assert len(back["/Cameras/Camera/Camera.omni:lensdistortion:opencvPinhole:k1"][0]) == len(solved) - 16
