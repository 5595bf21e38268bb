"""Exit-pupil bounds: per film point, the rectangle on the rear-vertex plane that rays must cross.

For each node of a ``nx`` x ``ny`` grid over the film (mm), rays from the node to a dense
``samples`` x ``samples`` grid over the rear element's bounding square are traced film -> scene;
the rectangle around those that pass, grown by one sample spacing, is stored. A film point gets
the union of the rectangles of the four surrounding nodes, so bounds are conservative between
nodes. A 2-D grid (not pbrt's radial table) works for anamorphic lenses and avoids interpolating
across film radii, the source of ring artefacts; the rectangle is per axis, so a squeezed pupil
keeps its aspect.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, OpticsError, require_positive

__all__ = ["PupilBounds", "exit_pupil_bounds"]


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
    from .trace import camera_rays, paraxial_image_z

    hw = require_positive("film half width", film_half_width)
    hh = require_positive("film half height", film_half_height)
    if nx < 2 or ny < 2 or samples < 4:
        raise InputError("pupil bounds need nx, ny >= 2 and samples >= 4")
    if film_z is None:
        film_z = paraxial_image_z(lens)
    r = lens.surfaces[-1].semi_diameter
    step = 2 * r / samples
    u = (np.arange(samples) + 0.5) / samples
    uu, vv = [a.ravel() for a in np.meshgrid(u, u)]
    xs = np.linspace(-hw, hw, nx)
    ys = np.linspace(-hh, hh, ny)
    rects = np.zeros((ny, nx, 4))
    for j, fy in enumerate(ys):
        for i, fx in enumerate(xs):
            film = np.broadcast_to([fx, fy], (uu.size, 2))
            res = camera_rays(lens, film, np.stack([uu, vv], axis=1), film_z, backend=backend)
            ok = res.ok
            if ok.any():
                px = -r + uu[ok] * 2 * r
                py = -r + vv[ok] * 2 * r
                rects[j, i] = (max(px.min() - step, -r), min(px.max() + step, r),
                               max(py.min() - step, -r), min(py.max() + step, r))
    if not (rects[..., 1] > rects[..., 0]).any():
        raise OpticsError(f"no ray from the film reaches the scene through {lens.name!r}")
    return PupilBounds(xs, ys, rects, float(lens.vertex_z[-1]))
