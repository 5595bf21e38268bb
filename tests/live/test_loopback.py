"""10,000 samples over loopback UDP with bad packets mixed in (garbage, truncated, wrong checksum,
duplicated, out of order, oversized, schema-invalid): the recorded USD holds every good sample, in
order, with the values that were sent, and the receiver's memory stays bounded (measured)."""

from __future__ import annotations

import dataclasses
import os
import random
import time

import numpy as np
import pytest

from physcam.live.camera import CameraMove, camera_frames, frames_to_samples
from physcam.live.frames import frame_from_sample
from physcam.live.protocol import ENCODING_CBOR, ENCODING_JSON, build_packet, packetize
from physcam.live.receiver import Receiver
from physcam.live.record import solve_frames, write_lens_report, write_recording_usd
from physcam.live.sample import encode_sample
from physcam.live.sender import Sender
from physcam.optics.sensors import find_sensor

from _udp import PacedSender

pytestmark = pytest.mark.slow

#: The samples sent: 10,000, as issue 17 asks of this test ("streams 10,000 samples at full speed with
#: injected bad packets"). The memory bound is per sample kept (20 KiB each: 195 MiB for 10,000).
N = 10_000


def _rss_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def _good_samples():
    sensor = find_sensor("ALEXA 35")
    frames = camera_frames(sensor=sensor, frames=N, rate=240, focus_mm=1500.0, focus_to_mm=6000.0, fstop=2.8,
                           focal_length_mm=35.0, move=CameraMove(velocity_m_s=(0.2, 0.5, 0.0),
                                                                 rate_deg_s=(15.0, -3.0, 1.0)))
    # a distortion that changes every frame, in OpenTrackIO's millimetre form
    frames = [dataclasses.replace(f, distortion={"model": "Brown-Conrady U-D", "radial": [-2e-5 - 1e-9 * i, 1e-8, 0.0],
                                                 "tangential": [0.0, 0.0]}) for i, f in enumerate(frames)]
    return list(frames_to_samples(frames, static_every=240))


def _invalid_sample(good):
    bad = dict(good)
    bad["lens"] = dict(good["lens"], fStop=-1.0)
    return bad


def test_ten_thousand_samples_with_bad_packets(tmp_path):
    pxr = pytest.importorskip("pxr")
    from pxr import Usd, UsdGeom

    samples = _good_samples()
    rnd = random.Random(17)
    # the stream: (sequence, list of datagrams); sequence numbers wrap at 65536 from 65000
    seq = 65_000
    plan, expected = [], []
    injected = dict.fromkeys(("garbage", "truncated", "checksum", "duplicate", "out_of_order", "oversized",
                              "invalid"), 0)
    for i, s in enumerate(samples):
        enc = ENCODING_CBOR if i % 2 else ENCODING_JSON
        payload = encode_sample(s, "cbor" if enc == ENCODING_CBOR else "json")
        size = 400 if i % 10 == 0 else 1456  # every tenth sample in several segments
        packets = packetize(payload, encoding=enc, sequence=seq % 65536, segment_payload=size)
        if i % 10 == 0:
            packets.reverse()  # segments out of order
        extra = []
        if i % 97 == 3:  # a schema-invalid sample with its own sequence number: counted, not recorded
            seq += 1
            extra.append(packetize(encode_sample(_invalid_sample(s)), encoding=ENCODING_JSON, sequence=seq % 65536))
            injected["invalid"] += 1
        if i % 50 == 1:
            packets.insert(0, bytes(rnd.getrandbits(8) for _ in range(rnd.randint(1, 300))))
            injected["garbage"] += 1
        if i % 77 == 2:
            packets.insert(0, packets[-1][: len(packets[-1]) // 2])
            injected["truncated"] += 1
        if i % 91 == 4:
            bad = bytearray(packets[-1])
            bad[-1] ^= 0x55
            packets.insert(0, bytes(bad))
            injected["checksum"] += 1
        if i % 33 == 5:
            packets.append(packets[-1])
            injected["duplicate"] += 1
        if i % 200 == 6:
            packets.insert(0, build_packet(b"\0" * 32000, encoding=ENCODING_JSON, sequence=seq % 65536,
                                           offset=40000, last=True))  # beyond the 64 KiB sample limit
            packets.insert(0, b"OTrk" + b"\xff" * 60000)  # a 60 KB datagram whose header lies
            injected["oversized"] += 1
        plan.append(packets)
        for e in extra:
            plan.append(e)
        expected.append(s)
        seq += 1
    # out of order: swap some neighbouring samples' whole packet groups
    for j in range(20, len(plan) - 1, 41):
        plan[j], plan[j + 1] = plan[j + 1], plan[j]
        injected["out_of_order"] += 1

    received = []
    rss0 = _rss_bytes()
    rss_peak = rss0
    t0 = time.perf_counter()
    # the sender here shares a loaded 2-core machine with the receiver thread and other tests: a swapped
    # pair's second sample can be held up beyond the 50 ms window (counted late, and the take one short);
    # this test is about every counter and every value under bad packets, test_attacks.py about the window
    with Receiver(0, host="127.0.0.1", queue_size=1024, reorder_timeout_s=1.0) as rx, \
            Sender("127.0.0.1", rx.port) as tx:
        paced = PacedSender(tx, rx)
        for k, packets in enumerate(plan):
            for d in packets:
                paced.send(d)
            # full speed, limited only by the receiver: keep at most ~500 samples in flight
            while True:
                while (item := rx.get()) is not None:
                    received.append(item.sample)
                c = rx.counters()
                if k + 1 - (c["delivered"] + c["invalid"] + c["missing"]) < 500:
                    break
                time.sleep(0.001)
            if k % 250 == 0:
                rss_peak = max(rss_peak, _rss_bytes())
        deadline = time.monotonic() + 20
        while len(received) < N and time.monotonic() < deadline:
            item = rx.get(timeout=0.1)
            if item is not None:
                received.append(item.sample)
        counters = rx.counters()
        high = dict(rx.high_water)
    elapsed = time.perf_counter() - t0
    rss_peak = max(rss_peak, _rss_bytes())

    # every good sample, in order, nothing else
    assert [s["sampleId"] for s in received] == [s["sampleId"] for s in expected], counters
    assert counters["invalid"] == injected["invalid"]
    assert counters["wrong_checksum"] == injected["checksum"]
    assert counters["duplicate"] == injected["duplicate"]
    assert counters["malformed"] == injected["garbage"] + injected["truncated"] + 2 * injected["oversized"]
    assert counters["late"] == 0 and counters["missing"] == 0 and counters["dropped"] == 0
    # bounded memory: the buffers stayed within their limits, and the process grew by less than the
    # samples it kept (N decoded dicts, about 6 KiB each) plus a margin: 20 KiB a sample
    assert high["window"] <= 9 and high["queue"] <= 1024 and high["reassembly_bytes"] <= 16 * 65536
    assert rss_peak - rss0 < N * 20 * 1024, f"grew {(rss_peak - rss0) / 1024**2:.0f} MB"
    print(f"\n{N} samples in {elapsed:.1f} s ({N / elapsed:.0f}/s), counters {counters}, high water {high}, "
          f"RSS +{(rss_peak - rss0) / 1024**2:.1f} MB")

    # record them, then read the USD back
    frames, static = [], None
    for s in received:
        static = s.get("static", static)
        frames.append(frame_from_sample(s, static=static))
    solved = solve_frames(frames)
    out = write_recording_usd(tmp_path / "take.usdc", solved)
    write_lens_report(tmp_path / "take.csv", solved)
    stage = Usd.Stage.Open(str(out))
    assert stage.GetTimeCodesPerSecond() == 240.0 and UsdGeom.GetStageUpAxis(stage) == "Y"
    cam = stage.GetPrimAtPath("/Cameras/Camera")
    seq_attr = cam.GetAttribute("physcam:live:sequenceNumber")
    times = seq_attr.GetTimeSamples()
    assert times == [float(i) for i in range(N)]  # 240 fps timestamps -> one time code per frame
    assert [seq_attr.Get(t) for t in times] == [s["timing"]["sequenceNumber"] for s in expected]
    f32 = lambda v: float(np.float32(v))  # noqa: E731 - USD float attributes hold 32 bits
    lens = {n: cam.GetAttribute("lens:main:" + n) for n in ("pinholeFocalLength", "fStop", "entrancePupilDistance")}
    model = stage.GetPrimAtPath("/Cameras/Camera/Pinhole")
    rot = cam.GetAttribute("xformOp:rotateZXY")
    radial = cam.GetAttribute("physcam:live:distortionRadial")
    for i in range(0, N, 7):
        s, t = expected[i], float(i)
        L = s["lens"]
        assert lens["pinholeFocalLength"].Get(t) == f32(L["pinholeFocalLength"])
        assert lens["fStop"].Get(t) == f32(L["fStop"])
        assert lens["entrancePupilDistance"].Get(t) == f32(L["entrancePupilOffset"] * 1000.0)
        assert model.GetAttribute("focusDistance").Get(t) == f32(L["focusDistance"] * 1000.0)
        r = s["transforms"][0]["rotation"]
        assert tuple(rot.Get(t)) == (f32(r["tilt"]), f32(r["pan"]), f32(-r["roll"]))
        assert list(radial.Get(t)) == L["distortion"][0]["radial"]
        # the film plane lands where the tracker put the sensor: (x, y, z) Z-up metres -> (x, z, -y) cm
        m = np.array(UsdGeom.Xformable(cam).ComputeLocalToWorldTransform(Usd.TimeCode(t)))
        tr = s["transforms"][0]["translation"]
        assert np.allclose(m[3, :3], [tr["x"] * 100, tr["z"] * 100, -tr["y"] * 100], atol=1e-6)
    assert pxr is not None


BAD = 6_000  # datagrams, a third of each kind


def test_bad_input_alone_does_not_grow_the_receiver():
    """Only garbage, oversized datagrams and first segments of samples that never finish: the counters
    count them, the buffers stay at their caps, and memory does not grow with them.

    6,000 datagrams (20,000 until round 14): the 2,000 oversized ones alone are 100 MB, three times
    the growth allowed, and the 2,000 unfinished samples 125 times the 16 the reassembler keeps."""
    rnd = random.Random(5)
    with Receiver(0, host="127.0.0.1") as rx, Sender("127.0.0.1", rx.port) as tx:
        paced = PacedSender(tx, rx)
        rss0 = _rss_bytes()
        for k in range(BAD):
            kind = k % 3
            if kind == 0:
                paced.send(bytes(rnd.getrandbits(8) for _ in range(64)))
            elif kind == 1:
                paced.send(b"OTrk" + os.urandom(50_000))
            else:
                first = packetize(b"{" + b" " * 3000 + b"}", encoding=ENCODING_JSON, sequence=k % 65536,
                                  segment_payload=1000)[0]
                paced.send(first)
        deadline = time.monotonic() + 20
        while rx.counters()["received"] < BAD and time.monotonic() < deadline:
            time.sleep(0.05)
        c = rx.counters()
        growth = _rss_bytes() - rss0
    assert c["received"] == BAD and c["delivered"] == 0
    assert c["malformed"] == 2 * (BAD // 3) and c["dropped"] == BAD // 3 - 16
    assert rx.high_water["reassembly_bytes"] <= 16 * 1000
    assert growth < 32 * 1024 ** 2, f"grew {growth / 1024**2:.1f} MB"
