"""Frame rates as exact fractions: the NTSC family (23.976, 29.97, 59.94 ...) is N x 1000/1001.

Cameras and files write the NTSC-family rates in decimals: 23.976 or 23.98 for 24000/1001, 29.97 for 30000/1001,
47.952 or 47.95, 59.94, 119.88, 239.76 (SMPTE ST 12-1 counts their timecode at the nominal N; Sony's VENICE
writes ``captureFps`` "23.98p", Avid and Resolve say 23.98). physcam reads each as its exact fraction wherever a
rate enters (camera metadata, OpenTrackIO ``live send``/``record``, animated USD), so a clip, a stream and a
stage of one shot line up frame for frame. Nothing but :mod:`physcam.errors` imported: the metadata readers
run without numpy.
"""

from __future__ import annotations

from fractions import Fraction

from .errors import require_finite

#: The nominal rates N whose NTSC rate N x 1000/1001 is written to two decimals (23.98, 47.95) as often as to
#: three: a rate within 0.005 of one of these N x 1000/1001 is that rate.
NTSC_NOMINAL = (24, 30, 48, 60, 96, 120, 240)
#: Largest denominator of a rate that is not of the NTSC family (the nearest fraction to a decimal rate).
MAX_DENOMINATOR = 1001


def exact_frame_rate(rate) -> Fraction:
    """``rate`` (a number, or a Fraction) as an exact fraction: an NTSC-family rate, written to three decimals
    (any N: r x 1.001 within 5e-4 of N) or to two (N of :data:`NTSC_NOMINAL`: r within 0.005 of N x 1000/1001),
    is N x 1000/1001 (a Fraction too: a file's "23.976" read exactly is 2997/125); any other the nearest
    fraction with a denominator up to :data:`MAX_DENOMINATOR` (a Fraction with one is kept). Zero and negative
    rates are returned for the caller to refuse; NaN, infinity or what is not a number is an InputError.

    >>> exact_frame_rate(23.976), exact_frame_rate(23.98), exact_frame_rate(29.97), exact_frame_rate(25)
    (Fraction(24000, 1001), Fraction(24000, 1001), Fraction(30000, 1001), Fraction(25, 1))
    """
    r = require_finite("frame rate", rate)
    n = round(r * 1.001)
    if r > 0 and abs(r - n) > 1e-6 and (abs(r * 1.001 - n) < 5e-4 or
                                         (n in NTSC_NOMINAL and abs(r - n * 1000 / 1001) < 0.005)):
        return Fraction(n * 1000, 1001)
    if isinstance(rate, Fraction) and rate.denominator <= MAX_DENOMINATOR:
        return rate
    return Fraction(r).limit_denominator(MAX_DENOMINATOR)
