"""Benchmark: the CPU a received OpenTrackIO sample costs, from datagram to recorded take.

The stream is tests/live/test_loopback.py's: 240 fps frames of a moving ALEXA 35 with a focus pull
and a distortion that changes every frame, JSON and CBOR in turn, every tenth sample in 400-byte
segments sent last first, a static block once a second, with the same kinds of bad datagrams mixed
in (garbage, truncated, wrong checksum, duplicated, oversized, schema-invalid). The datagrams are
handed to a :class:`~physcam.live.receiver.Receiver`'s packet handler in this thread (no socket, no
scheduler: the receive path's own CPU), then the samples it delivers become frames
(:func:`~physcam.live.frames.frame_from_sample`), are solved (:func:`~physcam.live.record.solve_frames`)
and written (:func:`~physcam.live.record.write_recording_usd`, :func:`~physcam.live.record.write_lens_report`).
Prints CPU microseconds per sample of each step (the best of ``--repeat`` runs of the receive step);
``--out DIR`` keeps the take (take.usdc, take.csv) to compare two trees' bytes with ``cmp``.
``--receive-only`` stops after the receive step, and ``--repeat 0`` before it (after the warm-up): the
difference of two runs under ``valgrind --tool=callgrind`` (``PYTHONHASHSEED=0``) is the receive step's
instruction count, which the machine's load does not change; ``--stream FILE`` keeps the datagrams
(pickled; made when absent), so those runs do not build the stream under valgrind.

    PYTHONPATH=src .venv/bin/python benchmarks/live_receive.py [--samples 2000] [--repeat 3] [--out DIR]
        [--receive-only] [--stream FILE]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import pickle
import random
import tempfile
import time
from pathlib import Path


def stream(n: int):
    """(datagrams, samples) of the test's stream (module notes), its timestamps from 0."""
    from physcam.live.camera import CameraMove, camera_frames, frames_to_samples
    from physcam.live.protocol import ENCODING_CBOR, ENCODING_JSON, build_packet, packetize
    from physcam.live.sample import encode_sample
    from physcam.optics.sensors import find_sensor

    frames = camera_frames(sensor=find_sensor("ALEXA 35"), frames=n, rate=240, focus_mm=1500.0, focus_to_mm=6000.0,
                           fstop=2.8, focal_length_mm=35.0, t0_ns=0,
                           move=CameraMove(velocity_m_s=(0.2, 0.5, 0.0), rate_deg_s=(15.0, -3.0, 1.0)))
    frames = [dataclasses.replace(f, distortion={"model": "Brown-Conrady U-D", "radial": [-2e-5 - 1e-9 * i, 1e-8, 0.0],
                                                 "tangential": [0.0, 0.0]}) for i, f in enumerate(frames)]
    samples = list(frames_to_samples(frames, static_every=240,
                                     source_id="urn:uuid:00000000-0000-4000-8000-000000000017"))
    rnd, seq, out = random.Random(17), 65_000, []
    for i, s in enumerate(samples):
        enc = ENCODING_CBOR if i % 2 else ENCODING_JSON
        packets = packetize(encode_sample(s, "cbor" if i % 2 else "json"), encoding=enc, sequence=seq % 65536,
                            segment_payload=400 if i % 10 == 0 else 1456)
        if i % 10 == 0:
            packets.reverse()
        if i % 97 == 3:  # schema-invalid, its own number
            seq += 1
            bad = dict(s, lens=dict(s["lens"], fStop=-1.0))
            packets += packetize(encode_sample(bad), encoding=ENCODING_JSON, sequence=seq % 65536)
        if i % 50 == 1:
            packets.insert(0, bytes(rnd.getrandbits(8) for _ in range(rnd.randint(1, 300))))
        if i % 77 == 2:
            packets.insert(0, packets[-1][: len(packets[-1]) // 2])
        if i % 91 == 4:
            wrong = bytearray(packets[-1])
            wrong[-1] ^= 0x55
            packets.insert(0, bytes(wrong))
        if i % 33 == 5:
            packets.append(packets[-1])
        if i % 200 == 6:
            packets.insert(0, build_packet(b"\0" * 32000, encoding=ENCODING_JSON, sequence=seq % 65536,
                                           offset=40000, last=True))
            packets.insert(0, b"OTrk" + b"\xff" * 60000)
        out += packets
        seq += 1
    return out, samples


def receive(datagrams, n: int):
    """The samples a receiver delivers from ``datagrams``, and its counters (its handler, this thread)."""
    from physcam.live.receiver import Receiver

    rx = Receiver(0, host="127.0.0.1", queue_size=n + 16, reorder_timeout_s=10.0)
    addr = ("127.0.0.1", 50000)
    for d in datagrams:
        rx._handle(memoryview(d), addr)
    rx.stop()  # never started: hands on what its window holds
    got = []
    while (item := rx.get()) is not None:
        got.append(item.sample)
    return got, rx.counters()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", help="keep the take here (take.usdc, take.csv)")
    ap.add_argument("--receive-only", action="store_true", help="stop after the receive step")
    ap.add_argument("--stream", help="the datagrams and samples, pickled here (made when absent)")
    args = ap.parse_args()
    from physcam.live.frames import frame_from_sample
    from physcam.live.record import solve_frames, write_lens_report, write_recording_usd

    n = args.samples
    if args.stream and os.path.exists(args.stream):
        with open(args.stream, "rb") as f:
            datagrams, samples = pickle.load(f)
    else:
        datagrams, samples = stream(n)
        if args.stream:
            with open(args.stream, "wb") as f:
                pickle.dump((datagrams, samples), f)
    n = len(samples)
    receive(datagrams[:200], n)  # imports, the compiled schema and jsonschema's validator: once a process
    if args.repeat == 0:
        return
    clock, cpu = time.process_time, {}
    best = None
    for _ in range(args.repeat):
        t = clock()
        got, counters = receive(datagrams, n)
        best = min(best or 1e9, clock() - t)
    assert [s["sampleId"] for s in got] == [s["sampleId"] for s in samples], counters
    cpu["receive (parse, reassemble, decode, validate, order)"] = best
    if args.receive_only:
        print(f"{n} samples, {len(datagrams)} datagrams; receive {best / n * 1e6:.1f} us a sample")
        return
    t = clock()
    frames, static = [], None
    for s in got:
        static = s.get("static", static)
        frames.append(frame_from_sample(s, static=static))
    cpu["frame_from_sample"] = clock() - t
    t = clock()
    solved = solve_frames(frames)
    cpu["solve_frames"] = clock() - t
    folder = Path(args.out) if args.out else Path(tempfile.mkdtemp())
    folder.mkdir(parents=True, exist_ok=True)
    t = clock()
    write_recording_usd(folder / "take.usdc", solved, force=True)
    cpu["write_recording_usd"] = clock() - t
    t = clock()
    write_lens_report(folder / "take.csv", solved, force=True)
    cpu["write_lens_report"] = clock() - t
    if not args.out:
        for p in folder.iterdir():
            p.unlink()
        folder.rmdir()
    print(f"{n} samples, {len(datagrams)} datagrams; counters {counters}; load average {os.getloadavg()[0]:.2f}")
    for k, v in cpu.items():
        print(f"  {k:55s} {v / n * 1e6:7.1f} us a sample")
    print(f"  {'total':55s} {sum(cpu.values()) / n * 1e6:7.1f} us a sample")


if __name__ == "__main__":
    main()
