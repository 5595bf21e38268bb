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
import os
import pickle
import random
import tempfile
import time
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import live_usd  # noqa: E402  (the take's samples and frames: the same stream as the USD writer's benchmark)


def stream(n: int):
    """(datagrams, samples) of the test's stream (module notes), its timestamps from 0."""
    from physcam.live.protocol import ENCODING_CBOR, ENCODING_JSON, build_packet, packetize
    from physcam.live.sample import encode_sample

    samples = live_usd.samples(n)
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
    frames = live_usd.frames_of(got)
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
