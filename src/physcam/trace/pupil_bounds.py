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

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, OpticsError, require_positive

__all__ = ["PupilBounds", "exit_pupil_bounds", "stopped_pupil_bounds", "iris_camera_rays", "MIN_HITS"]

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
    return stopped_pupil_bounds(lens, [None], film_half_width, film_half_height, film_z, nx=nx, ny=ny,
                                samples=samples, backend=backend)[0]


#: The stop's semi-diameter (mm) while one trace serves several irises: a power of two, so the stop
#: crossing (x, y), handed over on the stop's unit disk, comes back exact (x / 2^k * 2^k == x).
_OPEN_STOP = 2.0 ** 20


def stopped_pupil_bounds(lens, stop_semi_diameter, film_half_width: float, film_half_height: float,
                         film_z: float | None = None, *, nx: int = 17, ny: int = 17, samples: int = 64,
                         backend: str = "auto", mirror: bool = False) -> list[PupilBounds]:
    """:func:`exit_pupil_bounds` with the stop's semi-diameter set to each size of the sequence
    ``stop_semi_diameter`` (mm; None: the lens's own), one :class:`PupilBounds` each. The aims of every node are traced in
    one call for all irises (:func:`iris_camera_rays`), and so are the windows of every node still
    searching (module notes), round by round.

    ``mirror`` (odd ``nx`` and ``ny``): only the nodes with x >= 0 and y >= 0 are traced, the others are their
    mirror images. Every prescription physcam reads is symmetric about the planes x = 0 and y = 0 (spherical,
    aspheric and cylindrical surfaces centred on the axis, the cylinders' axes along x or y, round apertures), so
    the rays from node (-x, y) to the mirrored aims pass where those from (x, y) do, and the window search mirrors
    too: the rectangles are the whole grid's to the rounding of the aims' places (5.3e-15 mm on the anamorphic
    lenses of the Blender extension's tests, tests/export/test_blender_pupil_mirrored.py), for 25 of 81 nodes."""
    from .trace import paraxial_image_z

    hw = require_positive("film half width", film_half_width)
    hh = require_positive("film half height", film_half_height)
    if nx < 2 or ny < 2 or samples < 4:
        raise InputError("pupil bounds need nx, ny >= 2 and samples >= 4")
    if mirror and not (nx % 2 and ny % 2):
        raise InputError(f"mirrored pupil bounds need an odd number of nodes each way (a centre row and column), "
                         f"got nx={nx}, ny={ny}")
    sd = [s if s is None else require_positive("stop semi-diameter", s) for s in stop_semi_diameter]
    if any(s is None for s in sd) and not all(s is None for s in sd):  # the lens's own among others
        sd = [float(lens.surfaces[lens.stop_index].semi_diameter) if s is None else s for s in sd]
    if film_z is None:
        film_z = paraxial_image_z(lens)
    r = lens.surfaces[-1].semi_diameter
    xs = np.linspace(-hw, hw, nx)
    ys = np.linspace(-hh, hh, ny)
    traced_x, traced_y = (xs[nx // 2:], ys[ny // 2:]) if mirror else (xs, ys)
    fy, fx = (a.ravel() for a in np.meshgrid(traced_y, traced_x, indexing="ij"))  # the nodes traced, row by row
    ext, box = _node_hits(lens, fx, fy, film_z, sd, samples, backend)
    out = []
    for e, b in zip(ext, box):
        rects = _rects(e, b, r, samples).reshape(traced_y.size, traced_x.size, 4)
        if mirror:
            rects = _mirrored(rects)
        if not (rects[..., 1] > rects[..., 0]).any():
            raise OpticsError(f"no ray from the film reaches the scene through {lens.name!r}")
        out.append(PupilBounds(xs, ys, rects, float(lens.vertex_z[-1])))
    return out


def _node_hits(lens, fx, fy, film_z: float, sd, samples: int, backend: str):
    """Per stop and film node (``fx``, ``fy``): the extremes and count of the passing aims (stops, nodes, 5) and the box
    they were found on (stops, nodes, 4): first the rear rim's square, then windows about the node doubling in size
    while a node has too few hits (module notes)."""
    r = lens.surfaces[-1].semi_diameter
    u = (np.arange(samples) + 0.5) / samples
    uu, vv = [a.ravel() for a in np.meshgrid(u, u)]
    full = np.array([-r, r, -r, r])
    box = np.broadcast_to(full, (len(sd), fx.size, 4)).copy()  # per stop and node: the box its hits are on
    ext = _box_hits(lens, fx, fy, film_z, box[0], uu, vv, sd, backend)  # (stops, nodes, 5): extremes, count
    pending = ext[..., 4] < MIN_HITS
    h = 0.5 * (film_z - lens.vertex_z[-1])
    while pending.any():
        live = pending.any(axis=0) & (h < r + np.maximum(np.abs(fx), np.abs(fy)))
        if not live.any():
            break
        win = np.stack([np.maximum(fx - h, -r), np.minimum(fx + h, r), np.maximum(fy - h, -r), np.minimum(fy + h, r)],
                       axis=1)
        nodes = np.flatnonzero(live & (win[:, 1] > win[:, 0]) & (win[:, 3] > win[:, 2]))
        if nodes.size:
            got = _box_hits(lens, fx[nodes], fy[nodes], film_z, win[nodes], uu, vv, sd, backend)
            take = pending[:, nodes] & (got[..., 4] > 0) & ~_touches(got, win[nodes], full, samples)
            k, i = np.nonzero(take)
            ext[k, nodes[i]], box[k, nodes[i]] = got[k, i], win[nodes[i]]
            pending[k, nodes[i]] = False
        h *= 2
    return ext, box


def _mirrored(quarter: np.ndarray) -> np.ndarray:
    """The whole grid of rectangles (x0, x1, y0, y1) from its quarter of nodes with x >= 0 and y >= 0 (rows from the
    centre row up, columns from the centre column right): each node (-x, y) holds (x, y)'s rectangle mirrored in x,
    each (x, -y) mirrored in y."""
    qy, qx = quarter.shape[:2]
    rects = np.zeros((2 * qy - 1, 2 * qx - 1, 4))
    x_mirror = np.stack([-quarter[..., 1], -quarter[..., 0], quarter[..., 2], quarter[..., 3]], axis=-1)
    rects[qy - 1:, :qx] = x_mirror[:, ::-1]  # the centre column from its own rectangle, mirrored onto itself
    rects[qy - 1:, qx - 1:] = quarter
    rows = rects[qy - 1:]  # the centre row up; the rows below mirror those above it
    rects[:qy - 1] = np.stack([rows[..., 0], rows[..., 1], -rows[..., 3], -rows[..., 2]], axis=-1)[:0:-1]
    return rects + 0.0  # no negative zeros (an empty node is (0, 0, 0, 0))


class _StopCrossing:
    """An iris shape for the tracer (``density_at`` gets every ray's crossing on the stop's unit disk)
    that keeps the crossings and passes every ray (a density of 1.0: the tracer leaves the rays as they are)."""

    def __init__(self):
        self.x = self.y = None

    def density_at(self, x, y):
        self.x, self.y = x, y
        return 1.0


def iris_camera_rays(lens, film_xy, pupil_samples, film_z: float, stop_semi_diameter, *, bounds=None,
                     backend: str = "auto"):
    """:func:`~physcam.trace.trace.camera_rays` for several irises in one trace: (the rays, traced with
    the stop opened to :data:`_OPEN_STOP`; per stop semi-diameter of the sequence ``stop_semi_diameter`` (mm), which
    rays pass it). A ray passes an iris of radius s when it passes every other surface and crosses the
    stop plane at x^2 + y^2 <= s^2: the tracer's own test, so each mask is camera_rays' ``ok`` with
    ``stop_semi_diameter=s``, and where it holds the weight is the same too."""
    from .trace import camera_rays

    probe = _StopCrossing()
    res = camera_rays(lens, film_xy, pupil_samples, film_z, bounds=bounds, stop_semi_diameter=_OPEN_STOP,
                      aperture=probe, backend=backend)
    x, y = probe.x * _OPEN_STOP, probe.y * _OPEN_STOP
    r2 = x * x + y * y
    return res, [res.ok & (r2 <= float(s) * float(s)) for s in stop_semi_diameter]


def _box_hits(lens, fx, fy, film_z, boxes, uu, vv, stops, backend) -> np.ndarray:
    """Per stop and film point (``fx``, ``fy``): (x min, x max, y min, y max, count) of the aims that
    pass among the grid (``uu``, ``vv`` in [0, 1]) over its box (x0, x1, y0, y1 on the rear-vertex
    plane, inside the rear element's square of half side ``r``), all in one trace; the extremes are
    inf where none passes."""
    r = lens.surfaces[-1].semi_diameter
    x0, x1, y0, y1 = (boxes[:, c:c + 1] for c in range(4))
    px, py = x0 + uu * (x1 - x0), y0 + vv * (y1 - y0)  # (nodes, aims)
    m = uu.size
    film = np.stack([np.repeat(fx, m), np.repeat(fy, m)], axis=1)
    uv = np.stack([((px + r) / (2 * r)).ravel(), ((py + r) / (2 * r)).ravel()], axis=1)
    if all(s is None for s in stops):  # no stop to size: the lens as it is
        from .trace import camera_rays

        passing = [camera_rays(lens, film, uv, film_z, backend=backend).ok] * len(stops)
    else:
        passing = iris_camera_rays(lens, film, uv, film_z, stops, backend=backend)[1]
    out = np.empty((len(stops), fx.size, 5))
    for k, ok in enumerate(passing):
        ok = ok.reshape(px.shape)
        out[k, :, 0], out[k, :, 1] = np.where(ok, px, np.inf).min(axis=1), np.where(ok, px, -np.inf).max(axis=1)
        out[k, :, 2], out[k, :, 3] = np.where(ok, py, np.inf).min(axis=1), np.where(ok, py, -np.inf).max(axis=1)
        out[k, :, 4] = ok.sum(axis=1)
    return out


def _touches(ext, win, full, samples) -> np.ndarray:
    """Per stop and node, whether a passing aim (extremes ``ext`` of :func:`_box_hits`) lies in the
    outermost samples of its window ``win`` on a side where the window stops short of the rear
    element's square ``full`` (the spot may reach beyond it)."""
    sx, sy = (win[:, 1] - win[:, 0]) / samples, (win[:, 3] - win[:, 2]) / samples
    return (((win[:, 0] > full[0]) & (ext[..., 0] < win[:, 0] + sx)) | ((win[:, 1] < full[1]) & (ext[..., 1] > win[:, 1] - sx))
            | ((win[:, 2] > full[2]) & (ext[..., 2] < win[:, 2] + sy)) | ((win[:, 3] < full[3]) & (ext[..., 3] > win[:, 3] - sy)))


def _rects(ext, box, r, samples) -> np.ndarray:
    """Per node, the rectangle around its passing aims (extremes ``ext`` of :func:`_box_hits` on the
    grid over ``box``), grown by a sample spacing and kept inside the rear element's square; (0, 0, 0,
    0) where none passes."""
    sx, sy = (box[:, 1] - box[:, 0]) / samples, (box[:, 3] - box[:, 2]) / samples
    rect = np.stack([np.maximum(ext[:, 0] - sx, -r), np.minimum(ext[:, 1] + sx, r), np.maximum(ext[:, 2] - sy, -r),
                     np.minimum(ext[:, 3] + sy, r)], axis=1)
    rect[ext[:, 4] == 0] = 0.0
    return rect
