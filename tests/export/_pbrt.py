"""Test-side readers and a pbrt-style lens tracer, independent of physcam's code.

- :func:`parse_scene`: pbrt-v4 scene statements (``Film "rgb" "integer xresolution" [1920] ...``) as
  (directive, type, {name: (type, values)}), refusing malformed text;
- :func:`read_dat`: a lens ``.dat`` as rows (radius, thickness, eta, aperture diameter), ``#`` comments;
- :func:`thick_lens_film_distance`: pbrt-v4's thick-lens focusing worked from the book (Pharr, Jakob,
  Humphreys, *PBR* 4th ed., 5.3.3): a vector Snell tracer in pbrt's lens space (film at z = 0, the
  lens at negative z), two rays parallel to the axis at height 0.001 x film diagonal, the cardinal
  points where they cross the axis and where they return to their height, and the Gaussian lens
  equation solved for the lens's translation;
- :func:`paraxial_cardinal_points`: the same points from a y-nu paraxial trace (closed form).
"""

from __future__ import annotations

import math
import re

_SCENE_TOKEN = re.compile(r'(?P<c>#[^\n]*)|(?P<s>"[^"\n]*")|(?P<o>\[)|(?P<e>\])|(?P<n>[-+]?(?:\d+\.?\d*|\.\d+)'
                          r'(?:[eE][-+]?\d+)?)|(?P<w>[A-Z][A-Za-z]*)|(?P<sp>\s+)|(?P<bad>.)')


def parse_scene(text: str):
    out = []
    toks = []
    for m in _SCENE_TOKEN.finditer(text):
        k = m.lastgroup
        if k in ("c", "sp"):
            continue
        if k == "bad":
            raise ValueError(f"unexpected {m.group()!r}")
        toks.append((k, m.group()))
    i = 0
    while i < len(toks):
        k, v = toks[i]
        if k != "w" or i + 1 >= len(toks) or toks[i + 1][0] != "s":
            raise ValueError(f"expected Directive \"type\", got {v!r}")
        directive, typ = v, toks[i + 1][1][1:-1]
        i += 2
        ps = {}
        while i < len(toks) and toks[i][0] == "s":
            decl = toks[i][1][1:-1].split()
            if len(decl) != 2 or decl[0] not in ("integer", "float", "string", "bool", "spectrum", "rgb"):
                raise ValueError(f"bad parameter declaration {toks[i][1]}")
            if i + 1 >= len(toks) or toks[i + 1][0] != "o":
                raise ValueError(f"parameter {decl[1]} needs [values]")
            i += 2
            vals = []
            while i < len(toks) and toks[i][0] in ("n", "s"):
                k2, v2 = toks[i]
                if decl[0] == "string":
                    if k2 != "s":
                        raise ValueError(f"{decl[1]} is a string parameter")
                    vals.append(v2[1:-1])
                else:
                    if k2 != "n":
                        raise ValueError(f"{decl[1]} is a number parameter")
                    x = float(v2)
                    if decl[0] == "integer" and x != int(x):
                        raise ValueError(f"{decl[1]} is an integer parameter")
                    vals.append(int(x) if decl[0] == "integer" else x)
                i += 1
            if i >= len(toks) or toks[i][0] != "e":
                raise ValueError("unterminated [")
            i += 1
            ps[decl[1]] = vals[0] if len(vals) == 1 else vals
        out.append((directive, typ, ps))
    return out


def read_dat(text: str):
    rows = []
    for line in text.splitlines():
        body = line.split("#", 1)[0].split()
        if not body:
            continue
        if len(body) != 4:
            raise ValueError(f"a .dat row has 4 numbers: {line!r}")
        rows.append(tuple(float(x) for x in body))
    return rows


def _refract(d, n, eta_i, eta_t):
    """Refract unit direction d at unit normal n (any orientation), from index eta_i into eta_t."""
    cos_i = -(d[0] * n[0] + d[1] * n[1] + d[2] * n[2])
    if cos_i < 0:
        n = (-n[0], -n[1], -n[2])
        cos_i = -cos_i
    r = eta_i / eta_t
    k = 1.0 - r * r * (1.0 - cos_i * cos_i)
    if k < 0:
        raise ValueError("total internal reflection")
    c = r * cos_i - math.sqrt(k)
    return tuple(r * d[j] + c * n[j] for j in range(3))


def _vertex_z(rows):
    """pbrt lens space: the last surface sits its thickness in front of the film (z = 0)."""
    z, out = 0.0, []
    for row in reversed(rows):
        z -= row[1]
        out.append(z)
    return out[::-1]


def _eta(v):
    return 1.0 if v == 0.0 else v


def trace(rows, o, d, *, from_scene: bool, flats=()):
    """Trace a ray through ``rows`` (pbrt's .dat rows; indices in ``flats`` are flat refracting
    surfaces) in pbrt's lens space; returns the position and direction as it leaves."""
    zs = _vertex_z(rows)
    order = range(len(rows)) if from_scene else range(len(rows) - 1, -1, -1)
    for i in order:
        radius, _, eta, _ = rows[i]
        z0 = zs[i]
        if radius == 0.0 or i in flats:  # the stop, or a flat: a plane
            t = (z0 - o[2]) / d[2]
            hit = tuple(o[j] + t * d[j] for j in range(3))
            normal = (0.0, 0.0, 1.0)
        else:
            cz = z0 + radius
            oc = (o[0], o[1], o[2] - cz)
            b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2]
            c = oc[0] ** 2 + oc[1] ** 2 + oc[2] ** 2 - radius * radius
            disc = b * b - c
            roots = [-b - math.sqrt(disc), -b + math.sqrt(disc)]
            hits = [tuple(o[j] + t * d[j] for j in range(3)) for t in roots]
            hit = min(hits, key=lambda p: abs(p[2] - z0))  # the cap at the vertex
            normal = tuple(v / radius for v in (hit[0], hit[1], hit[2] - cz))
        if radius == 0.0 and i not in flats:
            o = hit
            continue
        before = _eta(rows[i - 1][2]) if i > 0 else 1.0
        after = _eta(eta)
        eta_i, eta_t = (before, after) if from_scene else (after, before)
        d = _refract(d, normal, eta_i, eta_t)
        o = hit
    return o, d


def thick_lens_film_distance(rows, focus_from_film_mm, film_diagonal_mm, *, flats=()):
    """(film distance, rear principal z, rear focal z, front principal z, front focal z) as pbrt-v4 works it."""
    x = 1e-3 * film_diagonal_mm
    zs = _vertex_z(rows)
    o, d = trace(rows, (x, 0.0, zs[0] - 1000.0), (0.0, 0.0, 1.0), from_scene=True, flats=flats)
    fz_rear = o[2] - o[0] / d[0] * d[2]
    pz_rear = o[2] + (x - o[0]) / d[0] * d[2]
    o, d = trace(rows, (x, 0.0, zs[-1] + 1000.0), (0.0, 0.0, -1.0), from_scene=False, flats=flats)
    fz_front = o[2] - o[0] / d[0] * d[2]
    pz_front = o[2] + (x - o[0]) / d[0] * d[2]
    return _focus(rows, focus_from_film_mm, pz_rear, fz_rear, pz_front), pz_rear, fz_rear, pz_front, fz_front


def _focus(rows, D, p_rear, f_rear, p_front):
    """Move the lens by delta (toward the subject) so that 1/s + 1/s' = 1/f between the planes:
    s = (p_front - delta) - z with z = -D, s' = delta - p_rear (solved by hand: see the module notes)."""
    f = f_rear - p_rear
    a, b = -p_rear, p_front + D  # s' = delta + a, s = b - delta
    # 1/(delta + a) + 1/(b - delta) = 1/f  ->  delta^2 + (a - b) delta + (a + b) f - a b = 0, far root
    qb, qc = a - b, (a + b) * f - a * b
    delta = (-qb - math.sqrt(qb * qb - 4 * qc)) / 2.0
    return rows[-1][1] + delta


def paraxial_cardinal_points(rows):
    """(rear principal z, rear focal z, front principal z, front focal z) in pbrt lens space by a y-nu trace."""
    zs = _vertex_z(rows)

    def run(order, start_index):
        y, nu, n = 1.0, 0.0, 1.0
        z_prev = None
        for i in order:
            radius, _, eta, _ = rows[i]
            if z_prev is not None:
                y += nu / n * (zs[i] - z_prev) * (1 if start_index == 0 else -1)
            z_prev = zs[i]
            before = _eta(rows[i - 1][2]) if i > 0 else 1.0
            after = _eta(eta)
            n_i, n_t = (before, after) if start_index == 0 else (after, before)
            if radius != 0.0:
                power = (n_t - n_i) / radius * (1 if start_index == 0 else -1)
                nu = nu - y * power
            n = n_t
        return y, nu, z_prev

    y, nu, zl = run(range(len(rows)), 0)  # from the scene, + z
    f_rear = zl + (-y / nu)
    p_rear = f_rear - (1.0 / -nu)  # efl = -1 / nu for a unit-height ray
    y, nu, zf = run(range(len(rows) - 1, -1, -1), 1)  # from the film, - z
    f_front = zf - (-y / nu)
    p_front = f_front + (1.0 / -nu)
    return p_rear, f_rear, p_front, f_front
