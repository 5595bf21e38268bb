"""A plain sequential Snell tracer for spherical and flat surfaces, written apart from physcam.trace.

Used by the analysis tests as an independent computation: one ray at a time, vector Snell's law
(Welford, *Aberrations of Optical Systems*, 4.2), no clipping. Lengths in mm, lens space.
"""

import math


def trace_spherical(lens, start, direction, end_z=None, stop_at=None):
    """Trace one ray; returns the list of hit points (and the end point), and the last direction.

    ``stop_at``: trace only surfaces [0, stop_at] (inclusive). Indices are each medium's nd, so
    the lens must have no dispersion (Vd = 0) or be traced at the d line only.
    """
    p = list(map(float, start))
    n = math.sqrt(sum(c * c for c in direction))
    d = [c / n for c in direction]
    n1 = 1.0
    z = 0.0
    hits = []
    last = len(lens.surfaces) - 1 if stop_at is None else stop_at
    for i, s in enumerate(lens.surfaces[: last + 1]):
        zc = z
        if s.radius == 0.0:
            t = (zc - p[2]) / d[2]
            q = [p[0] + t * d[0], p[1] + t * d[1], zc]
            normal = [0.0, 0.0, 1.0]
        else:
            c = [0.0, 0.0, zc + s.radius]
            oc = [p[0] - c[0], p[1] - c[1], p[2] - c[2]]
            b = sum(a * e for a, e in zip(oc, d))
            cc = sum(a * a for a in oc) - s.radius**2
            disc = b * b - cc
            if disc < 0:
                return None, None
            r = math.sqrt(disc)
            # the vertex-side intersection: near the vertex for the hemisphere facing the ray
            t = -b - r if s.radius > 0 else -b + r
            q = [p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2]]
            normal = [(q[k] - c[k]) / s.radius for k in range(3)]  # points toward +z near the vertex
        n2 = s.medium.nd
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
        n1 = n2
        z += s.thickness
    if end_z is not None:
        t = (end_z - p[2]) / d[2]
        hits.append([p[0] + t * d[0], p[1] + t * d[1], end_z])
    return hits, d
