"""Benchmark: the sustained OpenTrackIO sample rate physcam's receiver records without a drop.

Goal (issue 17): at least 10 x a 240 fps stream (2,400 samples/s). A sender in another process
streams physcam's own per-frame samples (pinhole focal length, focus, f-stop, T-stop, pupil,
distortion, transform, timing; JSON, one packet each) over loopback UDP at a paced rate for a few
seconds; this process receives them (header, Fletcher-16, decode, schema validation, ordering) and
records each as a frame (:func:`physcam.live.frames.frame_from_sample`). The rate doubles, then is
bisected, to the highest one with no sample lost (received = sent, nothing missing or dropped).

``--journal``: record as ``physcam live record`` does: each sample is also appended to a take journal
(:mod:`physcam.live.journal`, synced every 0.5 s) and taken into a :class:`~physcam.live.take.Take`.
Before the trials the script prints the CPU time per sample of each step (decode and validate, the
frame, the journal line, the take), measured side by side on the same samples.

``--attack``: a second process attacks the receiver during every trial (issue 24): overlapping
32 KB segments of never-finished samples (``--attack-rate`` datagrams/s), and ten times a second a
packet with a valid checksum that is no sample and a valid sample of the stream's source far off its
sequence. The trial also reports the receiver's reassembly high water and the process's peak RSS
growth (``/proc/self/status`` VmHWM, reset before each trial). Plain script, prints figures:

    .venv/bin/python benchmarks/live.py [--seconds 3] [--cbor] [--journal] [--attack [--attack-rate 2000]]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

GOAL = 2400.0

SENDER = r"""
import json, sys, time
from physcam.live.sender import Sender
port, rate, seconds, enc, path = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), sys.argv[4], sys.argv[5]
samples = [json.loads(line) for line in open(path)]
n = int(rate * seconds)
with Sender("127.0.0.1", port, encoding=enc) as tx:
    t0 = time.monotonic()
    sent = tx.stream((samples[i % len(samples)] for i in range(n)), rate)
    print(sent, time.monotonic() - t0, flush=True)
"""

ATTACKER = r"""
import json, random, socket, sys, time
from physcam.live.protocol import ENCODING_JSON, build_packet, packetize
from physcam.live.sample import encode_sample
port, rate, seconds, path = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
sample = json.loads(open(path).readline())
rnd = random.Random(7)
body = b"\x7f" * 32000
sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4 * 1024 * 1024)
t0, n, k = time.monotonic(), 0, 0
while time.monotonic() - t0 < seconds:
    due = t0 + n / rate
    if due > time.monotonic():
        time.sleep(due - time.monotonic())
    sock.sendto(build_packet(body, encoding=ENCODING_JSON, sequence=40000 + n % 64, offset=k % 30000, last=False),
                ("127.0.0.1", port))
    n, k = n + 1, k + 1
    if n % max(1, int(rate / 10)) == 0:  # ten times a second: a lying packet and a stray sample
        far = rnd.randrange(65536)
        sock.sendto(build_packet(b"\xde\xad", encoding=ENCODING_JSON, sequence=far), ("127.0.0.1", port))
        for d in packetize(encode_sample(sample), encoding=ENCODING_JSON, sequence=(far + 7919) % 65536):
            sock.sendto(d, ("127.0.0.1", port))
print(n, flush=True)
"""


def _reset_peak_rss() -> int:
    """Reset the process's peak RSS (Linux: write 5 to clear_refs) and return the current RSS in bytes."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
    except OSError:
        pass
    return _status_kib("VmRSS") * 1024


def _status_kib(field: str) -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    return 0


def _samples(path: str, count: int = 2400) -> int:
    import dataclasses

    from physcam.live.camera import CameraMove, camera_frames, frames_to_samples
    from physcam.optics.sensors import find_sensor

    frames = camera_frames(sensor=find_sensor("ALEXA 35"), frames=count, rate=240, focus_mm=1500.0,
                           focus_to_mm=6000.0, fstop=2.8, tstop=3.0, focal_length_mm=35.0,
                           move=CameraMove(rate_deg_s=(20.0, 1.0, 0.0), velocity_m_s=(0.5, 0.2, 0.0)))
    frames = [dataclasses.replace(f, distortion={"model": "Brown-Conrady U-D", "radial": [-2e-5, 1e-8, 0.0],
                                                 "tangential": [0.0, 0.0]}) for f in frames]
    samples = list(frames_to_samples(frames, static_every=240))
    with open(path, "w") as fh:
        for s in samples:
            fh.write(json.dumps(s) + "\n")
    return len(json.dumps(samples[1]).encode())


def _recorder(journal: bool, folder: str):
    """What the benchmark does with each sample: a frame, or (``journal``) as live record: journal and take."""
    from physcam.live.frames import frame_from_sample

    if not journal:
        return (lambda item: frame_from_sample(item.sample)), (lambda: None)
    from physcam.live.journal import Journal
    from physcam.live.take import Take

    j = Journal.create(os.path.join(folder, "bench.usda"), {"output": "bench.usda", "report": None, "options": {}})
    take = Take()

    def record(item):
        j.add_sample(item.sample, item.sequence, item.encoding)
        j.sync()
        take.add(item.sample, item.sequence)
    return record, j.discard


def cpu_costs(path: str, n: int = 1000) -> dict:
    """CPU µs per sample of each step of recording, measured side by side (process_time)."""
    import tempfile

    from physcam.live.frames import frame_from_sample
    from physcam.live.journal import Journal
    from physcam.live.sample import decode_sample, encode_sample
    from physcam.live.take import Take

    samples = [json.loads(line) for line in open(path)][:n]
    payloads = [encode_sample(s) for s in samples]
    decode_sample(payloads[0])  # the validator is built once per process
    out, clock = {}, time.process_time
    t = clock()
    decoded = [decode_sample(p) for p in payloads]
    out["decode and validate"] = clock() - t
    t = clock()
    for s in decoded:
        frame_from_sample(s)
    out["frame"] = clock() - t
    with tempfile.TemporaryDirectory() as d:
        j = Journal.create(os.path.join(d, "c.usda"), {"output": "c.usda", "report": None, "options": {}})
        t = clock()
        for i, s in enumerate(decoded):
            j.add_sample(s, i, "json")
            j.sync()
        out["journal line"] = clock() - t
        j.discard()
    take = Take()
    t = clock()
    for i, s in enumerate(decoded):
        take.add(s, i)
    out["take (frame included)"] = clock() - t
    return {k: v / len(decoded) * 1e6 for k, v in out.items()}


def trial(rate: float, seconds: float, enc: str, path: str, attack_rate: float = 0.0, journal: bool = False) -> dict:
    import tempfile

    from physcam.live.receiver import Receiver

    folder = tempfile.mkdtemp()
    record, done = _recorder(journal, folder)
    recorded = 0
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    rss0 = _reset_peak_rss()
    with Receiver(0, host="127.0.0.1", queue_size=4096) as rx:
        attacker = None
        if attack_rate > 0:
            attacker = subprocess.Popen([sys.executable, "-c", ATTACKER, str(rx.port), str(attack_rate),
                                         str(seconds), path], stdout=subprocess.PIPE, text=True, env=env)
        proc = subprocess.Popen([sys.executable, "-c", SENDER, str(rx.port), str(rate), str(seconds), enc, path],
                                stdout=subprocess.PIPE, text=True, env=env)
        t0 = time.perf_counter()
        while proc.poll() is None or rx.counters()["received"] < int(rate * seconds):
            item = rx.get(timeout=0.05)
            if item is not None:
                record(item)
                recorded += 1
            elif proc.poll() is not None and time.perf_counter() - t0 > seconds + 2.0:
                break  # the sender has finished and nothing more arrives
        while (item := rx.get(timeout=0.2)) is not None:
            record(item)
            recorded += 1
        elapsed = time.perf_counter() - t0
        sent, send_s = proc.stdout.read().split()
        attacks = int(attacker.stdout.read().split()[0]) if attacker is not None else 0
        if attacker is not None:
            attacker.wait()
        c = rx.counters()
        high = dict(rx.high_water)
    done()
    os.rmdir(folder)
    peak = _status_kib("VmHWM") * 1024 - rss0
    return {"rate": rate, "sent": int(sent), "recorded": recorded, "send_s": float(send_s), "elapsed_s": elapsed,
            "lost": int(sent) - recorded, "counters": c, "attacks": attacks, "high_water": high,
            "peak_rss_growth": peak}


def _report(rate: float, r: dict) -> None:
    line = (f"  {rate:8.0f}/s: sent {r['sent']}, recorded {r['recorded']}, lost {r['lost']} "
            f"(send took {r['send_s']:.2f} s)")
    if r["attacks"]:
        c = r["counters"]
        line += (f"; {r['attacks']} attack segments, malformed {c['malformed']}, stray+late {c['stray'] + c['late']}, "
                 f"reassembly high water {r['high_water']['reassembly_bytes'] / 1024:.0f} KiB, "
                 f"peak RSS +{r['peak_rss_growth'] / 2**20:.1f} MiB")
    print(line)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=3.0, help="length of each trial")
    ap.add_argument("--cbor", action="store_true", help="CBOR payloads (default JSON)")
    ap.add_argument("--journal", action="store_true", help="journal and take each sample, as live record does")
    ap.add_argument("--attack", action="store_true", help="attack the receiver during every trial (module notes)")
    ap.add_argument("--attack-rate", type=float, default=2000.0, help="overlapping 32 KB segments per second")
    args = ap.parse_args()
    attack = args.attack_rate if args.attack else 0.0
    enc = "cbor" if args.cbor else "json"
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), ".live_samples.jsonl")
    size = _samples(path)
    print(f"sample: {size} bytes of JSON ({enc} on the wire), one packet each; {args.seconds:g} s per trial"
          + (f"; under attack, {attack:g} overlapping 32 KB segments/s" if attack else "")
          + ("; journal and take as live record" if args.journal else ""))
    costs = cpu_costs(path)
    print("CPU per sample: " + ", ".join(f"{k} {v:.0f} us" for k, v in costs.items())
          + f"; journal line / decode and validate = {costs['journal line'] / costs['decode and validate']:.2f}")
    good, bad = 0.0, None
    rate = GOAL / 2
    try:
        while bad is None and rate <= 64 * GOAL:  # double until a trial loses samples
            r = trial(rate, args.seconds, enc, path, attack, args.journal)
            _report(rate, r)
            if r["lost"] == 0 and r["send_s"] <= args.seconds * 1.05:
                good = rate
                rate *= 2
            else:
                bad = rate
        for _ in range(4 if bad else 0):  # bisect between the last good and the first bad rate
            mid = (good + bad) / 2
            r = trial(mid, args.seconds, enc, path, attack, args.journal)
            _report(mid, r)
            if r["lost"] == 0 and r["send_s"] <= args.seconds * 1.05:
                good = mid
            else:
                bad = mid
    finally:
        os.unlink(path)
    print(f"sustained without a drop: {good:.0f} samples/s = {good / 240:.1f} x a 240 fps stream "
          f"(goal {GOAL / 240:.0f} x: {'met' if good >= GOAL else 'NOT met'})")


if __name__ == "__main__":
    main()
