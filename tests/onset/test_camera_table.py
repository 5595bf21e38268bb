"""The camera table (physcam/data/cameras.csv): its rows against the text of their cited sources, and
its shape (every format cited and dated, one pitch per camera where sizes are photosites x pitch).

The numbers below are copied from the cited text (the quote is kept beside each), not from the table.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import pytest

from physcam.errors import SensorError
from physcam.optics.sensors import MAKERS, camera_formats, cameras, find_sensor, sensors

TABLE = Path(__file__).resolve().parents[2] / "src" / "physcam" / "data" / "cameras.csv"

REFERENCE = "shared/reference/formats/sensor_formats.csv (the project's checked table, its sources named)"
NEWSSHOOTER = ("newsshooter.com, 'ARRI ALEXA LF & Anamorphic Lenses white paper' (2018-07-31), quoting ARRI and "
               "Netflix's white paper")
#: (format, width mm, height mm, citation with the quoted words); None: the source gives no such number
CITED = [
    ("ARRI ALEXA 35 4.6K 3:2 Open Gate", 27.99, 19.22,
     "forum.arri.com/viewtopic.php?p=3229 (ALEV IV thread answered by ARRI): 'open gate of the ALEV IV is 1.456:1 "
     "(27.99x19.22mm or 4608x3164 pixels)'"),
    ("ARRI ALEXA LF 4.5K LF 3:2 Open Gate", 36.70, 25.54, NEWSSHOOTER + ": 'LF Open Gate – 36.70 x 25.54 mm with "
     "(4448 x 3096)'"),
    ("ARRI ALEXA LF 3.8K LF 16:9 UHD", 31.68, 17.82, NEWSSHOOTER + ": 'LF 16:9 – 31.68 x 1782 mm with (3840 x 2160)' "
     "(17.82 printed without its point)"),
    ("ARRI ALEXA LF 4.5K LF 2.39:1", 36.70, 15.31, NEWSSHOOTER + ": 'LF 2.39:1 – 36.70 x 15.31 mm with (4448 x 1856 "
     "photo sites)'"),
    ("ARRI ALEXA Mini LF 4.5K LF 3:2 Open Gate", 36.70, 25.54, NEWSSHOOTER + " (the Mini LF has the LF's sensor modes)"),
    ("ARRI ALEXA Mini LF 3.8K LF 16:9 UHD", 31.68, 17.82, NEWSSHOOTER),
    ("ARRI ALEXA Mini LF 4.5K LF 2.39:1", 36.70, 15.31, NEWSSHOOTER),
    ("ARRI ALEXA 65 6.5K Open Gate", 54.12, 25.58, NEWSSHOOTER + ": 'ALEXA 65 has a whopping 54.12mm x 25.58mm "
     "(active image area) sensor'"),
    ("ARRI ALEXA 265 6.5K 2.12:1 Open Gate", 54.12, 25.58, NEWSSHOOTER + ": the ALEXA 65's 54.12mm x 25.58mm, the "
     "sensor the ALEXA 265 keeps (EmberLightVFX data/markdown/arri/alexa265.md: 6560 x 3100)"),
    ("RED V-RAPTOR 8K VV 8K 17:9", 40.96, 21.60, NEWSSHOOTER + ": 'The MONSTRO 8K VV sensor ... is 40.96mm x "
     "21.60mm' (RED's VV format, 8192 x 4320 at 5 um)"),
    ("Blackmagic Cinema Camera 2.5K 2.5K 16:9", 15.6, 8.8, "provideocoalition.com, NAB 2012 part 2, citing "
     "blackmagic-design.com techspecs: 'The active area is indeed 15.6 x 8.8mm' ... 'the active area is 2432 x 1366'"),
    ("ARRI ALEXA Mini 2.8K 16:9", 23.76, None, "lightcrafttech.com, ARRI connections: 'the same sensor width when "
     "shooting 1920×1080 16:9 format (23.76 mm wide.)'"),
    ("ARRI ALEXA Mini HD 16:9", 23.76, None, "lightcrafttech.com, ARRI connections (as above)"),
    # the project's shared reference table (shared/reference/formats/sensor_formats.csv), with its sources
    ("ARRI ALEXA 35 4.6K 16:9", 27.99, 15.75, REFERENCE + ": 'ARRI ALEXA 35 4.6K 16:9,27.99,15.75' (cineweb; ember "
     "28.0x15.7)"),
    ("ARRI ALEXA Mini 3.4K Open Gate", 28.25, 18.17, REFERENCE + ": 'ARRI ALEXA Mini 3.4K Open Gate,28.25,18.17' (ember)"),
    ("ARRI ALEXA Mini 2.8K 16:9", 23.76, 13.37, REFERENCE + ": 'ARRI ALEXA (S35 ALEV III) 2.8K/HD 16:9,23.76,13.37' "
     "(nuke; ember; the Mini's ALEV III)"),
    ("ARRI ALEXA Mini 2.8K 4:3", 23.76, 17.82, REFERENCE + ": 'ARRI ALEXA (S35 ALEV III) 4:3 2.8K,23.76,17.82' "
     "(nuke; fdtimes; ember)"),
    ("Sony VENICE 2 8K 8.6K 3:2 FF", 35.94, 23.96, REFERENCE + ": 'Sony VENICE 2 8K 8.6K 3:2 FF,35.94,23.96' (ember)"),
    ("Sony VENICE FF 6K 3:2", 35.9, 24.0, REFERENCE + ": 'Sony VENICE (6K) 3:2 FF,35.9,24.0' (ember; newsshooter "
     "says 36.2x24.1)"),
]
#: (format, image circle mm, citation): the source gives the diagonal
CITED_DIAGONALS = [
    ("ARRI ALEXA Mini LF 2.8K LF 1:1", 33.60, "fdtimes.com 2021-08-04, 'ALEXA Mini LF 1:1 for 2:1 anamorphic': "
     "'ALEXA Mini LF 2.8K 1:1 ... (2880 x 2880) ... has an image circle of 33.60 mm'"),
    ("ARRI ALEXA LF 4.5K LF 3:2 Open Gate", 44.71, NEWSSHOOTER + ": '@ 44.71mm image circle'"),
    ("ARRI ALEXA LF 3.8K LF 16:9 UHD", 36.35, NEWSSHOOTER + ": '@ 36.35mm image circle'"),
    ("ARRI ALEXA LF 4.5K LF 2.39:1", 39.76, NEWSSHOOTER + ": '@ 39.76 mm image circle'"),
]


@pytest.mark.parametrize("name, width, height, citation", CITED, ids=[c[0] for c in CITED])
def test_formats_equal_their_cited_spec(name, width, height, citation):
    s = find_sensor(name)
    assert s.width_mm == pytest.approx(width, abs=0.005), citation
    if height is not None:
        assert s.height_mm == pytest.approx(height, abs=0.005), citation


@pytest.mark.parametrize("name, circle, citation", CITED_DIAGONALS, ids=[c[0] for c in CITED_DIAGONALS])
def test_format_diagonals_equal_their_cited_image_circle(name, circle, citation):
    assert find_sensor(name).diagonal_mm == pytest.approx(circle, abs=0.01), citation


def test_the_table_has_150_formats_each_cited_and_dated():
    rows = list(csv.DictReader(TABLE.read_text(encoding="utf-8").splitlines()))
    assert len(rows) >= 150
    for r in rows:
        assert r["maker"] in MAKERS and r["source"].strip() and r["method"].strip(), r["key"]
        assert len(r["read"]) == 10 and r["read"][4] == "-", r["key"]  # an ISO date
    assert len({r["key"] for r in rows}) == len(rows)
    assert {"ARRI", "Sony", "RED", "Canon", "Blackmagic", "Panasonic"} <= {r["maker"] for r in rows}


def test_photosite_formats_share_one_pitch_per_camera():
    """Where sizes are photosites x pitch the width and the height give the same pitch, one per camera
    (the rounding of 0.01 mm aside)."""
    for name, formats in cameras().items():
        pitches = []
        for s in formats:
            if s.method.startswith("photosites x pitch") and s.pitch_um is not None:
                down = round(s.width_mm * 1000 / s.pitch_um / s.aspect)
                assert s.height_mm * 1000 / down == pytest.approx(s.pitch_um, rel=2e-3), s.name
                pitches.append(s.pitch_um)
        if pitches:
            assert max(pitches) / min(pitches) < 1.002, name


def test_a_camera_alone_asks_which_format():
    with pytest.raises(SensorError) as e:
        find_sensor("FX6")
    msg = str(e.value)
    assert "which one?" in msg and "'FX6 FF 4K 17:9'" in msg and "closest" not in msg
    assert find_sensor("FX6 FF 4K 17:9").name == "Sony FX6 FF 4K 17:9"
    assert find_sensor("sony fx6 ff 4k 17:9").key == "sony-fx6-ff-4k-17-9"
    assert [s.fmt for s in camera_formats("venice 2 8k")][0] == "8.6K 3:2 FF"
    assert find_sensor("VENICE S35 anamorphic 4K 6:5").anamorphic == (2.0,)


def test_existing_names_still_work():
    # the keys and aliases the Blender presets, the docs and the tests use
    for name, key in (("ALEXA 35", "alexa35-og"), ("S35", "s35-4perf"), ("VENICE 2", "venice2-8k"),
                      ("Mini LF", "alexa-lf-og"), ("V-RAPTOR", "vraptor-vv"), ("Super 16", "super16")):
        assert find_sensor(name).key == key


def test_anamorphic_formats_carry_their_desqueeze():
    assert find_sensor("ALEXA 35 3.3K 6:5").anamorphic == (2.0,)
    assert find_sensor("ALEXA Mini LF 2.8K LF 1:1").anamorphic == (2.0,)
    assert find_sensor("ALEXA 35 4K 16:9").anamorphic == ()
    assert all(math.isfinite(s.width_mm) for s in sensors())
