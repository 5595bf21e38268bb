"""A zoom lens's tabulated positions by ray-transfer matrices, worked from its TOML file (not physcam's
code): the oracle of the zoom tests' focal lengths and back focus.

Refraction [[1, 0], [-(n' - n)/R, 1]] and reduced transfer [[1, t/n], [0, 1]] multiplied from the first
vertex to the last, at the d line; EFL = -1/C, BFL = -A/C (Hecht, Optics, 6.2).
"""

from __future__ import annotations


def abcd_matrix(doc, k):
    """((A, B, C, D), track): the ray-transfer matrix of tabulated position ``k`` of the lens file ``doc``
    (parsed TOML) from its first vertex to its last (in air on both sides), and the first-to-last
    vertex length, mm."""
    gaps = {g["surface"]: g["thickness"][k] for g in doc["zoom"]["gap"]}
    a, b, c, d = 1.0, 0.0, 0.0, 1.0
    n, track = 1.0, 0.0
    surfaces = doc["surface"]
    for i, s in enumerate(surfaces):
        n2 = 1.0 if s["medium"] == "air" else float(s["medium"]["nd"])
        r = s.get("radius", 0.0)
        power = 0.0 if s["kind"] in ("flat", "stop") or r == 0 else (n2 - n) / r
        a, b, c, d = a, b, c - power * a, d - power * b  # refraction [[1, 0], [-P, 1]] @ M
        n = n2
        if i < len(surfaces) - 1:
            track += float(gaps.get(i, s["thickness"]))
            t = float(gaps.get(i, s["thickness"])) / n
            a, b, c, d = a + t * c, b + t * d, c, d  # transfer [[1, t/n], [0, 1]] @ M
    return (a, b, c, d), track


def abcd_position(doc, k):
    """(EFL, BFL, film distance) mm of tabulated position ``k`` of the lens file ``doc`` (parsed TOML): its
    zoom gaps set to the table's k-th thickness; the film distance is the last gap."""
    (a, b, c, d), _ = abcd_matrix(doc, k)
    surfaces = doc["surface"]
    gaps = {g["surface"]: g["thickness"][k] for g in doc["zoom"]["gap"]}
    return -1.0 / c, -a / c, float(gaps.get(len(surfaces) - 1, surfaces[-1]["thickness"]))


def abcd_unit_focus_magnification(doc, k, mark_mm):
    """The paraxial magnification (image over object, negative: inverted) of tabulated position ``k``
    focused as a whole (unit focus: the film distance set so the film is conjugate to the subject) on a
    subject ``mark_mm`` in front of the film. With the subject s in front of the first vertex, the film
    t behind the last: B of T(t) M T(s) is 0, so t = -(A s + B) / (C s + D) and m = A + t C; s by
    bisection on s + track + t = mark, farther than the 1:1 conjugate (where s + track + t is least)."""
    (a, b, c, d), track = abcd_matrix(doc, k)

    def film(s):
        return -(a * s + b) / (c * s + d)

    lo, hi = -d / c - 2.0 / c, mark_mm  # from the 1:1 conjugate (the subject 2 f beyond the front focal point)
    for _ in range(200):
        s = 0.5 * (lo + hi)
        if s + track + film(s) > mark_mm:
            hi = s
        else:
            lo = s
    s = 0.5 * (lo + hi)
    return a + film(s) * c
