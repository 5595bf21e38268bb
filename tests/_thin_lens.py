"""Thin-lens closed forms worked by hand, shared by tests as an oracle (not physcam's code).

A thin lens focused at a mark D from the film: s + s' = D and 1/s + 1/s' = 1/f, so
s'^2 - D s' + f D = 0, whose smaller root is the image distance: s' = (D - sqrt(D^2 - 4 f D)) / 2.
The best-match pinhole of a thin lens (pupils on the lens) is a pinhole s' from the film.
"""

import math


def image_distance_at_mark(f: float, mark: float) -> float:
    return (mark - math.sqrt(mark * mark - 4.0 * f * mark)) / 2.0


def fov_deg(size: float, focal: float) -> float:
    return math.degrees(2.0 * math.atan(size / (2.0 * focal)))
