"""The Blender extension's focus tables against physcam's exact focus solve, per bundled lens.

Run:  .venv/bin/python benchmarks/blender_focus_tables.py [--lenses dgauss_50mm,...] [--sub 8]

For each bundled lens (a zoom at u = 0, 0.5 and 1, on the zoom's shared focus axis) the table's
geometry (:func:`physcam.export.blender_focus.focus_geometry`) is blended as the shader blends it
(:func:`~physcam.export.blender_focus.blended_geometry`) at ``--sub`` - 1 points inside every interval
between marks, and compared with :func:`physcam.optics.focusing.focus` at that mark: the film plane's
and the largest gap's error (mm), the defocus (the paraxial image of the mark through the blended
lens less the blended film plane, mm) and the mark that the blended state focuses at (% of the mark).
``before``: the same for the tables of physcam 0.2 to round 6 (marks uniform in 1/distance, every
table linear in it). Only paraxial solves: about a minute for every lens.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from physcam.export.blender_focus import N_FOCUS, blended_geometry, focus_axis, focus_geometry
from physcam.export.blender_zoom import N_FOCUS_ZOOM, N_ZOOM_GEOMETRY, zoom_focus_axis
from physcam.lens.library import list_lenses, load_lens
from physcam.lens.zoom import prescription_at
from physcam.optics import paraxial
from physcam.optics.focusing import closest_focus, focus, image_distance


def sharpness(q, film, vz_film_first, mark_mm):
    """(defocus mm: the paraxial image of the mark through the lens at these vertices less the film plane,
    the mark mm from the film that this state focuses at)."""
    vz = np.asarray(vz_film_first)[::-1]  # lens order, first vertex first
    thick = {i: float(vz[i + 1] - vz[i]) for i in range(len(vz) - 1)}
    qb = q.with_thicknesses(thick)
    d_obj = mark_mm - (film - vz[0])
    defocus = vz[-1] + image_distance(qb, d_obj) - film
    # the object x in front of the first vertex whose image lands on the film: with the lens's ABCD
    # matrix on (y, n u), a ray from the axial object (y = x, n u = 1 at the first vertex: A x + B, C x + D)
    # meets the axis back / n' behind the last vertex: -(A x + B) n' / (C x + D) = back, linear in x
    a, b, c, d = paraxial.system_matrix(qb, "y")
    n_img = paraxial.media_indices(qb)[-1]
    back = film - vz[-1]
    x = -(b * n_img + back * d) / (a * n_img + back * c)
    return defocus, x + film - vz[0]


def errors(q, axis, geometry, sub: int, blend=blended_geometry) -> dict:
    out = {"film": 0.0, "gap": 0.0, "defocus": 0.0, "mark_pct": 0.0}
    for k in range(axis.n - 1):
        for j in range(1, sub):
            mark = axis.mark(k + j / sub)
            film, vz = blend(axis, geometry, mark)
            st = focus(q, mark)
            exact_vz = np.array(st.prescription.vertex_z[::-1])
            dz, sharp = sharpness(q, film, vz, mark)
            out["film"] = max(out["film"], abs(film - st.film_z))
            out["gap"] = max(out["gap"], float(np.abs(np.diff(vz) - np.diff(exact_vz)).max()))
            out["defocus"] = max(out["defocus"], abs(dz))
            out["mark_pct"] = max(out["mark_pct"], abs(sharp - mark) / mark * 100)
    return out


class _UniformAxis:
    """The focus axis before round 7: marks uniform in 1/distance."""

    def __init__(self, axis):
        self.n, self.near_mm = axis.n, axis.near_mm

    def index(self, focus_mm):
        return min(max(self.near_mm / focus_mm * (self.n - 1), 0.0), self.n - 1.0)

    def mark(self, index):
        return math.inf if index <= 0 else self.near_mm * (self.n - 1) / index


def _linear(axis, geometry, focus_mm):
    film_z, _, vz = geometry
    x = axis.index(focus_mm)
    k0 = min(int(math.floor(x)), axis.n - 2)
    t = x - k0
    return film_z[k0] + t * (film_z[k0 + 1] - film_z[k0]), vz[k0] + t * (vz[k0 + 1] - vz[k0])


def _before(q, axis, sub):
    old = _UniformAxis(axis)
    film, vz = [], []
    for k in range(axis.n):
        st = focus(q, old.mark(k) if k < axis.n - 1 else axis.near_mm)
        film.append(st.film_z)
        vz.append(st.prescription.vertex_z[::-1])
    return errors(q, old, (np.array(film), None, np.array(vz)), sub, blend=_linear)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lenses", help="comma-separated bundled slugs (default: all)")
    ap.add_argument("--sub", type=int, default=8, help="points per interval between marks, plus one")
    args = ap.parse_args()
    slugs = args.lenses.split(",") if args.lenses else [r.slug for r in list_lenses()]
    print("| lens | marks | closest (m) | before: film / gap / defocus (mm), mark (%) | now: film / gap / defocus (mm), mark (%) |")
    print("|---|---|---|---|---|")
    for slug in slugs:
        lens = load_lens(slug)
        if lens.zoom is not None and not lens.is_anamorphic:
            axis = zoom_focus_axis([prescription_at(lens, float(u)) for u in np.linspace(0, 1, N_ZOOM_GEOMETRY)],
                                   N_FOCUS_ZOOM)
            cases = [(f"{slug} u={u:g}", prescription_at(lens, u)) for u in (0.0, 0.5, 1.0)]
        else:
            axis = focus_axis(closest_focus(lens), N_FOCUS)
            cases = [(slug, lens)]
        for name, q in cases:
            before, now = _before(q, axis, args.sub), errors(q, axis, focus_geometry(q, axis), args.sub)
            cell = [f"{e['film']:.4f} / {e['gap']:.4f} / {e['defocus']:.4f}, {e['mark_pct']:.2f}" for e in (before, now)]
            print(f"| {name} | {axis.n} | {axis.closest_mm / 1000:.3f} | {cell[0]} | {cell[1]} |", flush=True)


if __name__ == "__main__":
    main()
