"""OpenTrackIO samples and packets: the official examples validate, broken samples are rejected at the
right JSON path with the right rule, Fletcher-16 against published vectors and its recurrence, packets
round-trip through segmentation in any order, and the distortion conversion against OpenCV itself."""

from __future__ import annotations

import copy
import json
import math
from fractions import Fraction
from pathlib import Path

import cbor2
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from physcam.errors import InputError
from physcam.live.frames import (
    TrackedFrame, frame_from_sample, pan_tilt_roll, rotation_matrix, sample_from_frame, timecode_fields,
)
from physcam.live.lens_data import opencv_to_opentrackio, opentrackio_to_opencv
from physcam.live.protocol import (
    ENCODING_CBOR, ENCODING_JSON, PacketError, Reassembler, build_packet, fletcher16, packetize, parse_packet,
)
from physcam.live.sample import SampleError, decode_sample, encode_sample, sample_problems, validate_sample

DATA = Path(__file__).parent / "data"
EXAMPLES = sorted(DATA.glob("*_example.json"))


def test_the_four_official_examples_are_here():
    assert [p.name for p in EXAMPLES] == ["complete_dynamic_example.json", "complete_static_example.json",
                                         "recommended_dynamic_example.json", "recommended_static_example.json"]


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_every_example_validates_as_json_and_as_cbor(path):
    sample = json.loads(path.read_text())
    assert sample_problems(sample) == []
    assert decode_sample(path.read_bytes(), "json") == sample
    assert decode_sample(cbor2.dumps(sample), "cbor") == sample
    assert decode_sample(encode_sample(sample, "cbor"), "cbor") == sample


def _base():
    return json.loads((DATA / "complete_dynamic_example.json").read_text())


def _set(sample, path, value):
    obj = sample
    for k in path[:-1]:
        obj = obj[k]
    if value is _DELETE:
        del obj[path[-1]]
    else:
        obj[path[-1]] = value
    return sample


_DELETE = object()

#: (what is broken, where, new value, the JSON path and rule the validator must name)
BROKEN = [
    ("f-stop zero", ("lens", "fStop"), 0, "$.lens.fStop", "exclusiveMinimum"),
    ("negative focus", ("lens", "focusDistance"), -1.0, "$.lens.focusDistance", "exclusiveMinimum"),
    ("focal length as text", ("lens", "pinholeFocalLength"), "50mm", "$.lens.pinholeFocalLength", "type"),
    ("encoder above 1", ("lens", "encoders", "focus"), 1.5, "$.lens.encoders.focus", "maximum"),
    ("empty encoders", ("lens", "encoders"), {}, "$.lens.encoders", "anyOf"),
    ("radial list empty", ("lens", "distortion", 0, "radial"), [], "$.lens.distortion[0].radial", "minItems"),
    ("overscan below 1", ("lens", "distortion", 1, "overscan"), 0.5, "$.lens.distortion[1].overscan", "minimum"),
    ("unknown lens key", ("lens", "zoomRatio"), 2.0, "$.lens", "additionalProperties"),
    ("timecode frame 120", ("timing", "timecode", "frames"), 120, "$.timing.timecode.frames", "maximum"),
    ("timecode without rate", ("timing", "timecode", "frameRate"), _DELETE, "$.timing.timecode", "required"),
    ("bad timing mode", ("timing", "mode"), "realtime", "$.timing.mode", "enum"),
    ("nanoseconds negative", ("timing", "sampleTimestamp", "nanoseconds"), -1,
     "$.timing.sampleTimestamp.nanoseconds", "minimum"),
    ("sample id not a URN", ("sampleId",), "12345", "$.sampleId", "pattern"),
    ("protocol version of 2", ("protocol", "version"), [1, 0], "$.protocol.version", "minItems"),
    ("transform without rotation", ("transforms", 2, "rotation"), _DELETE, "$.transforms[2]", "required"),
    ("pan as text", ("transforms", 0, "rotation", "pan"), "left", "$.transforms[0].rotation.pan", "type"),
    ("no transforms", ("transforms",), [], "$.transforms", "minItems"),
    ("PTP domain 200", ("timing", "synchronization", "ptp", "domain"), 200,
     "$.timing.synchronization.ptp.domain", "maximum"),
    ("sensor width negative", ("static",), {"camera": {"activeSensorPhysicalDimensions": {"width": -1, "height": 24}}},
     "$.static.camera.activeSensorPhysicalDimensions.width", "minimum"),
    ("NaN translation", ("transforms", 0, "translation", "x"), float("nan"), "$.transforms[0].translation.x",
     "finite"),
]


@pytest.mark.parametrize("what, where, value, path, rule", BROKEN, ids=[b[0] for b in BROKEN])
def test_a_broken_sample_is_rejected_at_its_json_path(what, where, value, path, rule):
    sample = _set(_base(), where, value if value is _DELETE else copy.deepcopy(value))
    with pytest.raises(SampleError) as err:
        validate_sample(sample)
    first = err.value.problems[0]
    assert (first.path, first.rule) == (path, rule), str(err.value)
    assert path in str(err.value) and rule in str(err.value)
    # and the same through CBOR, which can carry the NaN JSON cannot
    with pytest.raises(SampleError) as err2:
        decode_sample(cbor2.dumps(sample), "cbor")
    assert (err2.value.problems[0].path, err2.value.problems[0].rule) == (path, rule)


@pytest.mark.parametrize("payload, encoding", [(b"{not json", "json"), (b'{"a": NaN}', "json"),
                                               (b"\xff\xfe", "json"), (b"\xff\x00", "cbor"), (b"", "cbor")])
def test_undecodable_payloads_are_named_at_the_root(payload, encoding):
    with pytest.raises(SampleError) as err:
        decode_sample(payload, encoding)
    assert (err.value.problems[0].path, err.value.problems[0].rule) == ("$", encoding)


def test_a_sample_that_is_not_an_object_is_rejected():
    assert sample_problems([1, 2])[0].rule == "type"


# --- Fletcher-16 --------------------------------------------------------------------------------
def test_fletcher16_published_vectors():
    # Wikipedia, "Fletcher's checksum": modulus 255
    assert fletcher16(b"abcde", 255) == 0xC8F0
    assert fletcher16(b"abcdef", 255) == 0x2057
    assert fletcher16(b"abcdefgh", 255) == 0x0627


def _recurrence(data, m):
    s1 = s2 = 0
    for b in data:
        s1 = (s1 + b) % m
        s2 = (s2 + s1) % m
    return (s2 << 8) | s1


@given(st.binary(max_size=3000), st.sampled_from([255, 256]))
def test_fletcher16_closed_form_equals_the_byte_recurrence(data, m):
    assert fletcher16(data, m) == _recurrence(data, m)


@given(st.integers(8000, 40000), st.integers(0, 2**32 - 1), st.sampled_from([255, 256]))
def test_fletcher16_over_several_8_kib_chunks_equals_the_byte_recurrence(n, seed, m):
    data = np.random.default_rng(seed).integers(0, 256, n, dtype=np.uint8).tobytes()
    assert fletcher16(data, m) == _recurrence(data, m)
    pk = build_packet(data[:30000], encoding=ENCODING_CBOR, sequence=seed % 65536, offset=3, last=False, modulus=m)
    assert parse_packet(pk, m)[1] == data[:30000]  # the header's sums and the piece's, combined without a copy


# --- packets ------------------------------------------------------------------------------------
def test_header_layout_by_hand():
    pk = build_packet(b"{}", encoding=ENCODING_JSON, sequence=0x1234, offset=0, last=True)
    assert pk[:4] == b"OTrk" and pk[4] == 0 and pk[5] == 1
    assert pk[6:8] == b"\x12\x34" and pk[8:12] == b"\x00\x00\x00\x00"
    assert pk[12:14] == (0x8000 | 2).to_bytes(2, "big")
    assert int.from_bytes(pk[14:16], "big") == _recurrence(pk[:14] + b"{}", 256)
    assert len(pk) == 18


@pytest.mark.parametrize("damage, kind", [
    (lambda p: p[:10], "malformed"),                    # shorter than a header
    (lambda p: b"XTrk" + p[4:], "malformed"),           # not OpenTrackIO
    (lambda p: p[:5] + b"\x07" + p[6:], "malformed"),   # unknown encoding
    (lambda p: p[:-1], "malformed"),                    # truncated payload
    (lambda p: p + b"x", "malformed"),                  # trailing bytes
    (lambda p: p[:-1] + bytes([p[-1] ^ 1]), "checksum"),
    (lambda p: p[:14] + bytes([p[14] ^ 0x80]) + p[15:], "checksum"),
])
def test_damaged_packets_are_named(damage, kind):
    pk = build_packet(b'{"a":1}', encoding=ENCODING_JSON, sequence=7)
    with pytest.raises(PacketError) as err:
        parse_packet(damage(pk))
    assert err.value.kind == kind


def test_modulus_255_packets_need_255_or_auto():
    pk = build_packet(b"x" * 300, encoding=ENCODING_CBOR, sequence=1, modulus=255)
    with pytest.raises(PacketError):
        parse_packet(pk, 256)
    assert parse_packet(pk, 255)[1] == b"x" * 300
    assert parse_packet(pk, "auto")[1] == b"x" * 300


@given(st.binary(min_size=1, max_size=5000), st.integers(1, 1500), st.randoms(use_true_random=False))
def test_segments_reassemble_in_any_order(payload, size, rnd):
    packets = packetize(payload, encoding=ENCODING_CBOR, sequence=65535, segment_payload=size)
    assert len(packets) == math.ceil(len(payload) / size)
    rnd.shuffle(packets)
    r = Reassembler()
    done = [r.add(*parse_packet(p)) for p in packets]
    assert done[:-1] == [None] * (len(packets) - 1)
    assert done[-1] == (ENCODING_CBOR, payload)


def test_unfinished_samples_are_bounded():
    r = Reassembler(max_pending=4)
    for seq in range(100):
        first = packetize(b"y" * 100, encoding=ENCODING_JSON, sequence=seq, segment_payload=40)[0]
        assert r.add(*parse_packet(first)) is None
    assert len(r._pending) == 4 and r.dropped == 96


def test_oversized_segments_are_refused():
    pk = build_packet(b"z" * 100, encoding=ENCODING_JSON, sequence=1, offset=65500, last=True)
    with pytest.raises(PacketError, match="beyond"):
        parse_packet(pk)


# --- frames, rotations, timecode -------------------------------------------------------------------
@given(st.floats(-179, 179), st.floats(-89, 89), st.floats(-179, 179))
def test_pan_tilt_roll_inverts_the_rotation(pan, tilt, roll):
    assert np.allclose(pan_tilt_roll(rotation_matrix(pan, tilt, roll)), (pan, tilt, roll), atol=1e-7)


def test_rotations_follow_the_right_hand_rule_of_the_opentrackio_figure():
    fwd = np.array([0.0, 1.0, 0.0])  # the camera looks along +Y at zero rotation
    # pan +90: +X turns to +Y, so the view turns from +Y to -X
    assert np.allclose(rotation_matrix(90, 0, 0) @ fwd, [-1, 0, 0])
    # tilt +90: +Y turns to +Z (looking up)
    assert np.allclose(rotation_matrix(0, 90, 0) @ fwd, [0, 0, 1])
    # roll +90: +Z (up) turns to +X
    assert np.allclose(rotation_matrix(0, 0, 90) @ [0, 0, 1.0], [1, 0, 0])


def test_timecode_by_hand():
    # frame 24 * 3600 + 5 at 24 fps: 01:00:00:05
    tc = timecode_fields(24 * 3600 + 5, 24)
    assert (tc["hours"], tc["minutes"], tc["seconds"], tc["frames"]) == (1, 0, 0, 5)
    # 240 fps counts frame quadruples at 60 fps (frames <= 119 in the schema) with a subFrame
    tc = timecode_fields(240 + 7, 240)
    assert (tc["seconds"], tc["frames"], tc["subFrame"], tc["frameRate"]) == (1, 1, 3, {"num": 60, "denom": 1})


def test_a_frame_survives_a_sample_and_back():
    f = TrackedFrame(time_ns=1_718_806_554_500_000_000, rate=Fraction(24000, 1001), translation_m=(1.0, 2.0, 3.0),
                     rotation_deg=(10.0, -5.0, 2.0), pinhole_focal_length_mm=51.6, focus_from_film_mm=2500.0,
                     fstop=2.8, tstop=3.1, entrance_pupil_mm=49.5,
                     distortion={"model": "Brown-Conrady U-D", "radial": [-3e-5, 1e-8, 0.0], "tangential": [0.0, 0.0]})
    s = sample_from_frame(f, source_id="urn:uuid:96e0c0be-a4aa-4196-8b8b-457545a90f67", sequence_number=5)
    validate_sample(s)
    assert s["lens"]["focusDistance"] == 2.5 and s["lens"]["entrancePupilOffset"] == 0.0495
    back = frame_from_sample(s)
    for k in ("time_ns", "rate", "translation_m", "rotation_deg", "pinhole_focal_length_mm", "fstop", "tstop",
              "distortion"):
        assert getattr(back, k) == getattr(f, k), k
    assert back.focus_from_film_mm == pytest.approx(2500.0, rel=1e-15)
    assert back.entrance_pupil_mm == pytest.approx(49.5, rel=1e-15)


def test_a_chain_of_transforms_composes_in_order():
    s = _base()  # Dolly, Crane Arm (scaled 1, 2, 3), Camera, each (1, 2, 3) m and pan 180, tilt 90, roll 45
    f = frame_from_sample(s)
    m = np.eye(4)
    for t in s["transforms"]:
        a = np.eye(4)
        r = t["rotation"]
        a[:3, :3] = rotation_matrix(r["pan"], r["tilt"], r["roll"]) @ np.diag(
            [t.get("scale", {}).get(k, 1.0) for k in "xyz"])
        a[:3, 3] = [t["translation"][k] for k in "xyz"]
        m = m @ a
    assert np.allclose(f.translation_m, m[:3, 3])
    r = rotation_matrix(*f.rotation_deg)
    # the orientation is the polar factor: m = r P with P symmetric positive definite
    p = r.T @ m[:3, :3]
    assert np.allclose(p, p.T, atol=1e-9) and np.all(np.linalg.eigvalsh((p + p.T) / 2) > 0)
    assert f.notes  # the scale is said


# --- distortion: OpenCV's normalised coefficients in OpenLensIO millimetres ------------------------
def test_the_millimetre_coefficients_distort_like_opencv():
    """OpenLensIO's order (l1..l6 alternating numerator and denominator, camdkit's conversion note)
    against OpenCV's rational model (k1-k6) itself."""
    cv2 = pytest.importorskip("cv2")
    k1, k2, k3, p1, p2, f = -0.12, 0.03, -0.004, 3e-4, -2e-4, 35.0
    k4, k5, k6 = 0.01, -0.002, 0.0005
    dist = opencv_to_opentrackio(k1, k2, k3, p1, p2, f, k4, k5, k6)
    assert dist["model"] == "Brown-Conrady U-D"
    # points in front of a pinhole: OpenCV projects them with K = f (mm as "pixels"), centre 0
    xy = np.stack(np.meshgrid(np.linspace(-0.5, 0.5, 7), np.linspace(-0.35, 0.35, 5)), -1).reshape(-1, 2)
    obj = np.c_[xy, np.ones(len(xy))]
    K = np.array([[f, 0, 0], [0, f, 0], [0, 0, 1.0]])
    img, _ = cv2.projectPoints(obj, np.zeros(3), np.zeros(3), K, np.array([k1, k2, p1, p2, k3, k4, k5, k6]))
    img = img.reshape(-1, 2)
    # OpenLensIO's rational form in mm, applied to eps_u = F x'
    e = f * xy
    r2 = (e ** 2).sum(1)
    l1, l2, l3, l4, l5, l6 = dist["radial"]
    q1, q2 = dist["tangential"]
    R = (1 + l1 * r2 + l3 * r2 ** 2 + l5 * r2 ** 3) / (1 + l2 * r2 + l4 * r2 ** 2 + l6 * r2 ** 3)
    ex = e[:, 0] * R + 2 * q1 * e[:, 0] * e[:, 1] + q2 * (r2 + 2 * e[:, 0] ** 2)
    ey = e[:, 1] * R + 2 * q2 * e[:, 0] * e[:, 1] + q1 * (r2 + 2 * e[:, 1] ** 2)
    assert np.allclose(np.c_[ex, ey], img, atol=1e-9)
    back = opentrackio_to_opencv(dist, f, rational=True)
    assert back == pytest.approx({"k1": k1, "k2": k2, "k3": k3, "p1": p1, "p2": p2, "k4": k4, "k5": k5, "k6": k6},
                                 rel=1e-12)
    with pytest.raises(InputError, match="denominator"):
        opentrackio_to_opencv(dist, f)  # OpenCV's five coefficients cannot hold k4-k6


# the largest finite double, 2**1024 - 2**971 (IEEE 754 binary64), as an integer; an integer past it is no double
_DOUBLE_MAX = 2**1024 - 2**971


class _Count(int):
    """An int subclass (an IntEnum's kind): a number, not one of JSON's own types by name."""


@pytest.mark.parametrize("value, finite", [
    (0, True), (-7, True), (True, True), (None, True), ("", True), (1.5, True), (-0.0, True), (5e-324, True),
    (1.7976931348623157e308, True), (_DOUBLE_MAX, True), (-_DOUBLE_MAX, True), (_Count(3), True),
    (_DOUBLE_MAX + 1, False), (-_DOUBLE_MAX - 1, False), (math.inf, False), (-math.inf, False), (math.nan, False),
    (Fraction(1, 3), True), (Fraction(10**400), False)])
def test_a_decoded_value_is_kept_exactly_when_a_double_holds_it(value, finite):
    """The walk over a decoded sample passes JSON's own scalars at once: an integer up to the largest
    double (2**1024 - 2**971) and a finite float are kept, one past it, inf and NaN are each a problem
    (the sample's value path named), a CBOR rational becomes its float where one holds it."""
    from physcam.live.sample import _non_finite

    doc = {"lens": {"custom": [value]}}
    problem = _non_finite(doc, ())
    assert (problem is None) == finite, problem
    if finite:
        kept = doc["lens"]["custom"][0]
        assert kept == (float(value) if isinstance(value, Fraction) else value) and type(kept) is (
            float if isinstance(value, Fraction) else type(value))
    else:
        assert problem.path == "$.lens.custom[0]"
