"""Exit-pupil bounds: per film point, the rectangle on the rear-vertex plane that rays must cross.

For each node of a ``nx`` x ``ny`` grid over the film (mm), rays from the node to a dense
``samples`` x ``samples`` grid over the rear element's bounding square are traced film -> scene;
the rectangle around those that pass, grown by one sample spacing, is stored. A film point gets
the union of the rectangles of the four surrounding nodes, so bounds are conservative between
nodes. A 2-D grid (not pbrt's radial table) works for anamorphic lenses and avoids interpolating
across film radii, the source of ring artefacts; the rectangle is per axis, so a squeezed pupil
keeps its aspect.

Where the last surface lies close to the film (a flat cover glass a millimetre in front of it), the
passing rays cross the rear-vertex plane in a spot smaller than one sample spacing of the rear
element's square, and the grid can miss it. A node with fewer than :data:`MIN_HITS` passing samples
is therefore searched again in a window about the point straight ahead of it, half as wide as the
film-to-rear-vertex distance (rays up to 27 degrees off axis) and doubled while the passing samples
touch its edge or none pass, until it is the whole square.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, OpticsError, require_positive

__all__ = ["PupilBounds", "exit_pupil_bounds", "MIN_HITS"]

#: Passing samples below which a film node's spot is searched for again in a finer window (module notes).
MIN_HITS = 16


@dataclass
class PupilBounds:
    """Rectangles (x0, x1, y0, y1) in mm on the plane z = ``z_plane`` per film grid node."""

    xs: np.ndarray
    ys: np.ndarray
    rects: np.ndarray  # (ny, nx, 4); an empty node holds (0, 0, 0, 0)
    z_plane: float

    def rect_at(self, fx, fy):
        """Conservative (x0, x1, y0, y1) arrays for film points (``fx``, ``fy``) in mm."""
        fx = np.asarray(fx, dtype=float)
        fy = np.asarray(fy, dtype=float)
        i = np.clip(np.searchsorted(self.xs, fx) - 1, 0, len(self.xs) - 2)
        j = np.clip(np.searchsorted(self.ys, fy) - 1, 0, len(self.ys) - 2)
        corners = [self.rects[j + a, i + b] for a in (0, 1) for b in (0, 1)]
        valid = [c[..., 1] > c[..., 0] for c in corners]
        big = np.inf
        x0 = np.min([np.where(v, c[..., 0], big) for c, v in zip(corners, valid)], axis=0)
        x1 = np.max([np.where(v, c[..., 1], -big) for c, v in zip(corners, valid)], axis=0)
        y0 = np.min([np.where(v, c[..., 2], big) for c, v in zip(corners, valid)], axis=0)
        y1 = np.max([np.where(v, c[..., 3], -big) for c, v in zip(corners, valid)], axis=0)
        none = ~np.any(valid, axis=0)
        z = np.zeros_like(x0)
        return (np.where(none, z, x0), np.where(none, z, x1), np.where(none, z, y0), np.where(none, z, y1))


def exit_pupil_bounds(lens, film_half_width: float, film_half_height: float, film_z: float | None = None, *,
                      nx: int = 17, ny: int = 17, samples: int = 64, backend: str = "auto") -> PupilBounds:
    """Tabulate :class:`PupilBounds` over the film rectangle (half sizes in mm) at ``film_z``."""
    from .trace import paraxial_image_z

    hw = require_positive("film half width", film_half_width)
    hh = require_positive("film half height", film_half_height)
    if nx < 2 or ny < 2 or samples < 4:
        raise InputError("pupil bounds need nx, ny >= 2 and samples >= 4")
    if film_z is None:
        film_z = paraxial_image_z(lens)
    r = lens.surfaces[-1].semi_diameter
    u = (np.arange(samples) + 0.5) / samples
    uu, vv = [a.ravel() for a in np.meshgrid(u, u)]
    xs = np.linspace(-hw, hw, nx)
    ys = np.linspace(-hh, hh, ny)
    rects = np.zeros((ny, nx, 4))
    for j, fy in enumerate(ys):
        for i, fx in enumerate(xs):
            rects[j, i] = _node_rect(lens, fx, fy, film_z, r, uu, vv, backend)
    if not (rects[..., 1] > rects[..., 0]).any():
        raise OpticsError(f"no ray from the film reaches the scene through {lens.name!r}")
    return PupilBounds(xs, ys, rects, float(lens.vertex_z[-1]))


def _window_hits(lens, fx, fy, film_z, r, box, uu, vv, backend):
    """(x, y) of the aims that pass among the grid (``uu``, ``vv`` in [0, 1]) over ``box`` (x0, x1, y0,
    y1 on the rear-vertex plane, inside the rear element's square of half side ``r``)."""
    from .trace import camera_rays

    x0, x1, y0, y1 = box
    px, py = x0 + uu * (x1 - x0), y0 + vv * (y1 - y0)
    film = np.broadcast_to([fx, fy], (uu.size, 2))
    res = camera_rays(lens, film, np.stack([(px + r) / (2 * r), (py + r) / (2 * r)], axis=1), film_z, backend=backend)
    return px[res.ok], py[res.ok]


def _node_rect(lens, fx, fy, film_z, r, uu, vv, backend) -> tuple:
    """(x0, x1, y0, y1) around the aims from film point (fx, fy) that pass, grown by a sample spacing
    and kept inside the rear element's square; (0, 0, 0, 0) when none passes (module notes)."""
    full = (-r, r, -r, r)
    hits = _window_hits(lens, fx, fy, film_z, r, full, uu, vv, backend)
    box = full
    if hits[0].size < MIN_HITS:
        h = 0.5 * (film_z - lens.vertex_z[-1])
        while h < r + max(abs(fx), abs(fy)):
            win = (max(fx - h, -r), min(fx + h, r), max(fy - h, -r), min(fy + h, r))
            if win[1] > win[0] and win[3] > win[2]:
                got = _window_hits(lens, fx, fy, film_z, r, win, uu, vv, backend)
                if got[0].size and not _touches(got, win, full, uu):
                    hits, box = got, win
                    break
            h *= 2
    if not hits[0].size:
        return (0.0, 0.0, 0.0, 0.0)
    n = round(math.sqrt(uu.size))
    sx, sy = (box[1] - box[0]) / n, (box[3] - box[2]) / n
    px, py = hits
    return (max(px.min() - sx, -r), min(px.max() + sx, r), max(py.min() - sy, -r), min(py.max() + sy, r))


def _touches(hits, win, full, uu) -> bool:
    """Whether a passing aim lies in the outermost samples of window ``win`` on a side where the
    window stops short of the rear element's square ``full`` (the spot may reach beyond it)."""
    n = round(math.sqrt(uu.size))
    px, py = hits
    sx, sy = (win[1] - win[0]) / n, (win[3] - win[2]) / n
    return bool((win[0] > full[0] and px.min() < win[0] + sx) or (win[1] < full[1] and px.max() > win[1] - sx)
                or (win[2] > full[2] and py.min() < win[2] + sy) or (win[3] < full[3] and py.max() > win[3] - sy))
