"""Benchmark: writing a recorded take to USD (:func:`physcam.live.record.write_recording_usd`).

The take is tests/live/test_loopback.py's: 10,000 frames at 240 fps of a moving ALEXA 35 with a
focus pull and a distortion that changes every frame, through OpenTrackIO samples and back
(sequence numbers, timecode, source), solved once (:func:`solve_frames`, timed apart). The writer
is then run ``--repeat`` times into a temporary folder; each run prints its wall and CPU seconds
(the stage is validated by usd-core's validators before it is written, as every physcam write).

    .venv/bin/python benchmarks/live_usd.py [--frames 10000] [--repeat 3] [--usda]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import tempfile
import time
from pathlib import Path


def samples(n: int) -> list:
    """The take's ``n`` OpenTrackIO samples (module notes), timestamps from 0: benchmarks/live_receive.py
    sends the same stream."""
    from physcam.live.camera import CameraMove, camera_frames, frames_to_samples
    from physcam.optics.sensors import find_sensor

    frames = camera_frames(sensor=find_sensor("ALEXA 35"), frames=n, rate=240, focus_mm=1500.0, focus_to_mm=6000.0,
                           fstop=2.8, focal_length_mm=35.0, t0_ns=0,
                           move=CameraMove(velocity_m_s=(0.2, 0.5, 0.0), rate_deg_s=(15.0, -3.0, 1.0)))
    frames = [dataclasses.replace(f, distortion={"model": "Brown-Conrady U-D", "radial": [-2e-5 - 1e-9 * i, 1e-8, 0.0],
                                                 "tangential": [0.0, 0.0]}) for i, f in enumerate(frames)]
    return list(frames_to_samples(frames, static_every=240, source_id="urn:uuid:00000000-0000-4000-8000-000000000017"))


def frames_of(received) -> list:
    """The frames of samples in order, each with the last static block seen (as a recorder reads them)."""
    from physcam.live.frames import frame_from_sample

    out, static = [], None
    for s in received:
        static = s.get("static", static)
        out.append(frame_from_sample(s, static=static))
    return out


def take(n: int):
    return frames_of(samples(n))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=10_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--usda", action="store_true", help="write text (.usda) instead of crate (.usdc)")
    args = ap.parse_args()
    from physcam.live.record import solve_frames, write_recording_usd

    frames = take(args.frames)
    t0, c0 = time.perf_counter(), time.process_time()
    solved = solve_frames(frames)
    print(f"solve_frames: {len(solved)} frames, {time.perf_counter() - t0:.2f} s wall, "
          f"{time.process_time() - c0:.2f} s CPU")
    print(f"load average {os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.repeat):
            path = Path(tmp) / f"take{k}.{'usda' if args.usda else 'usdc'}"
            t0, c0 = time.perf_counter(), time.process_time()
            write_recording_usd(path, solved)
            print(f"write_recording_usd run {k + 1}: {time.perf_counter() - t0:.2f} s wall, "
                  f"{time.process_time() - c0:.2f} s CPU, {path.stat().st_size:,} bytes")
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
