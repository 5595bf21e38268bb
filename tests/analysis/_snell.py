"""A plain sequential Snell tracer for spherical and flat surfaces, written apart from physcam.trace.

Used by the analysis tests as an independent computation: one ray at a time, vector Snell's law
(Welford, *Aberrations of Optical Systems*, 4.2), no clipping. Lengths in mm, lens space.
"""

import math


def trace_spherical(lens, start, direction, end_z=None, stop_at=None, reverse=False):
    """Trace one ray; returns the list of hit points (and the end point) and the last direction,
    or (None, None) when the ray misses a surface or is totally reflected.

    Forward (front to back) by default; ``reverse`` traces a ray travelling toward -z from the
    back surface to the front one. ``stop_at``: the last surface index to trace (forward only).
    Indices are each medium's nd: trace lenses without dispersion (Vd = 0) or at the d line.
    """
    p = list(map(float, start))
    n = math.sqrt(sum(c * c for c in direction))
    d = [c / n for c in direction]
    zv = list(lens.vertex_z)
    surfaces = list(lens.surfaces)
    order = range(len(surfaces))
    if reverse:
        order = reversed(order)
    elif stop_at is not None:
        order = range(stop_at + 1)
    media = [1.0] + [s.medium.nd for s in surfaces]  # media[i] before surface i, media[i + 1] after it
    hits = []
    for i in order:
        s = surfaces[i]
        n1, n2 = (media[i + 1], media[i]) if reverse else (media[i], media[i + 1])
        if s.radius == 0.0:
            t = (zv[i] - p[2]) / d[2]
            q = [p[0] + t * d[0], p[1] + t * d[1], zv[i]]
            normal = [0.0, 0.0, 1.0]
        else:
            c = [0.0, 0.0, zv[i] + s.radius]
            oc = [p[0] - c[0], p[1] - c[1], p[2] - c[2]]
            b = sum(a * e for a, e in zip(oc, d))
            cc = sum(a * a for a in oc) - s.radius**2
            disc = b * b - cc
            if disc < 0:
                return None, None
            r = math.sqrt(disc)
            # the root on the hemisphere that holds the vertex: (q_z - centre_z) has the sign of -R
            q = None
            for t in (-b - r, -b + r):
                cand = [p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]]
                if t > -1e-9 and (cand[2] - c[2]) * s.radius < 0:
                    q = cand
                    break
            if q is None:
                return None, None
            normal = [(q[k] - c[k]) / s.radius for k in range(3)]
        cos_i = sum(a * e for a, e in zip(normal, d))
        if cos_i < 0:
            normal = [-a for a in normal]
            cos_i = -cos_i
        mu = n1 / n2
        k = 1.0 - mu * mu * (1.0 - cos_i * cos_i)
        if k < 0:
            return None, None  # total internal reflection
        d = [mu * d[j] + (math.sqrt(k) - mu * cos_i) * normal[j] for j in range(3)]
        hits.append(q)
        p = q
    if reverse:
        hits.reverse()  # hits[i] is on surface i in either direction
    if end_z is not None:
        t = (end_z - p[2]) / d[2]
        hits.append([p[0] + t * d[0], p[1] + t * d[1], end_z])
    return hits, d
