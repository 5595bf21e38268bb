"""A zoom lens's tabulated positions by ray-transfer matrices, worked from its TOML file (not physcam's
code): the oracle of the zoom tests' focal lengths and back focus.

Refraction [[1, 0], [-(n' - n)/R, 1]] and reduced transfer [[1, t/n], [0, 1]] multiplied from the first
vertex to the last, at the d line; EFL = -1/C, BFL = -A/C (Hecht, Optics, 6.2).
"""

from __future__ import annotations


def abcd_position(doc, k):
    """(EFL, BFL, film distance) mm of tabulated position ``k`` of the lens file ``doc`` (parsed TOML): its
    zoom gaps set to the table's k-th thickness; the film distance is the last gap."""
    gaps = {g["surface"]: g["thickness"][k] for g in doc["zoom"]["gap"]}
    a, b, c, d = 1.0, 0.0, 0.0, 1.0
    n = 1.0
    surfaces = doc["surface"]
    for i, s in enumerate(surfaces):
        n2 = 1.0 if s["medium"] == "air" else float(s["medium"]["nd"])
        r = s.get("radius", 0.0)
        power = 0.0 if s["kind"] in ("flat", "stop") or r == 0 else (n2 - n) / r
        a, b, c, d = a, b, c - power * a, d - power * b  # refraction [[1, 0], [-P, 1]] @ M
        n = n2
        if i < len(surfaces) - 1:
            t = float(gaps.get(i, s["thickness"])) / n
            a, b, c, d = a + t * c, b + t * d, c, d  # transfer [[1, t/n], [0, 1]] @ M
    return -1.0 / c, -a / c, float(gaps.get(len(surfaces) - 1, surfaces[-1]["thickness"]))
