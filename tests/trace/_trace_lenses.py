"""Lenses built directly as Prescriptions (independent of the lens file readers)."""

import numpy as np
from physcam.lens.prescription import LensMetadata, Medium, Prescription, Surface

# pbrt-v4 scenes/lenses dgauss.50mm.dat: radius thickness index aperture-DIAMETER
DGAUSS_ROWS = [
    (29.475, 3.76, 1.67, 25.2),
    (84.83, 0.12, 1.0, 25.2),
    (19.275, 4.025, 1.67, 23.0),
    (40.77, 3.275, 1.699, 23.0),
    (12.75, 5.705, 1.0, 18.0),
    (0.0, 4.5, 0.0, 17.1),
    (-14.495, 1.18, 1.603, 17.0),
    (40.77, 6.065, 1.658, 20.0),
    (-20.385, 0.19, 1.0, 20.0),
    (437.065, 3.22, 1.717, 20.0),
    (-39.73, 0.0, 1.0, 20.0),
]
DGAUSS_BFL = 36.1059  # mm behind the last vertex, independently known


def build_pbrt(rows, name="lens", abbe=None):
    surfs = []
    for i, (r, t, n, ap) in enumerate(rows):
        n = 1.0 if n == 0 else n
        vd = 0.0 if (n == 1.0 or abbe is None) else abbe[i]
        kind = "stop" if r == 0 else "spherical"
        surfs.append(Surface(radius=r, thickness=t, medium=Medium(n, vd), semi_diameter=ap / 2, kind=kind))
    return Prescription(tuple(surfs), LensMetadata(name=name)).validate()


def dgauss_lens():
    return build_pbrt(DGAUSS_ROWS, "dgauss.50mm")


def equal_area_disk(radius, n_rings):
    """Deterministic equal-area sampling of a disk of ``radius`` (mm).

    Ring j (1..n_rings) holds m_j = 6 j cells; its radii are chosen so that every cell has the
    same area (r_j = R sqrt(sum_{k<=j} m_k / sum m)); each cell is represented by the point at
    its area-median radius and mid angle. 3 n (n + 1) samples in all.
    """
    xs = [6 * j for j in range(1, n_rings + 1)]
    total = sum(xs)
    # cumulative cell counts define equal-area ring radii
    out_x, out_y = [], []
    cum = 0
    for j, m in enumerate(xs, start=1):
        r_in = radius * np.sqrt(cum / total)
        r_out = radius * np.sqrt((cum + m) / total)
        r_mid = np.sqrt(0.5 * (r_in**2 + r_out**2))
        phi = (np.arange(m) + 0.5) * 2 * np.pi / m + (0.5 * np.pi / m if j % 2 else 0.0)
        out_x.append(r_mid * np.cos(phi))
        out_y.append(r_mid * np.sin(phi))
        cum += m
    return np.concatenate(out_x), np.concatenate(out_y)
