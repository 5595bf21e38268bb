"""The chart vocabulary of ``physcam calibrate`` without numpy or OpenCV (the command's parser is
built at every start-up; the CLI's start-up goal, docs/performance.md): the chart kinds, the default
ChArUco dictionary and the corners as written (``9x6``)."""

from __future__ import annotations

import re

from ...errors import InputError

__all__ = ["CHARTS", "CHARUCO_DICTIONARY", "MAX_IMAGE_PIXELS", "parse_corners"]

#: The charts physcam detects (OpenCV): a checkerboard or a ChArUco board
CHARTS = ("checkerboard", "charuco")
#: The ArUco dictionary of a ChArUco board unless told (OpenCV's tutorial board)
CHARUCO_DICTIONARY = "DICT_5X5_100"
#: The most pixels an image may have (width x height, from its header, before it is decoded): a 12K
#: cinema frame is 80 Mpx, a 100 Mpx stills back 102 Mpx; a decoded 120 Mpx 16-bit image is 240 MB
#: (``physcam calibrate --max-pixels`` raises it)
MAX_IMAGE_PIXELS = 120_000_000


def parse_corners(text) -> tuple[int, int]:
    """``"9x6"`` -> (9, 6): columns x rows."""
    m = re.fullmatch(r"\s*(\d{1,3})\s*[xX]\s*(\d{1,3})\s*", str(text))
    if not m or min(int(m.group(1)), int(m.group(2))) < 2:
        raise InputError(f"give the chart's corners as COLUMNSxROWS, each 2 or more, e.g. 9x6; got {text!r}")
    return int(m.group(1)), int(m.group(2))
