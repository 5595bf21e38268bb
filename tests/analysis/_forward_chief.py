"""An independent oracle for distortion: chief rays aimed *forward* from object points.

Object points on the plane of sharp focus, each placed where physcam's best-match pinhole
(GaussianData at that focus, camera at the entrance pupil) sees a chosen ideal pixel; their chief
rays are aimed from the object point through the centre of the stop (a Newton iteration written
here) and traced to the film. Independent of physcam.analysis.distortion.stmap's backward chief rays from film
points, its interpolation and its inversion.
"""

from __future__ import annotations

import numpy as np

from physcam.optics.focusing import focus
from physcam.optics.paraxial import gaussian
from physcam.trace import RayBatch, trace_through


def forward_chief_to_film(q, obj_pts, object_z, film_z, wl):
    """Film (x, y) mm of chief rays from object points (n, 2) on z = object_z, aimed at the stop centre."""
    k = q.stop_index
    front = q.with_surfaces(q.surfaces[: k + 1])
    z_ep = gaussian(q, wavelength_nm=wl, object_z=object_z, film_z=film_z).z_entrance_pupil
    # an anamorphic's X meridian has its own entrance pupil: the first aim is the ray towards it
    z_ep_x = gaussian(q, axis="x", wavelength_nm=wl, object_z=object_z, film_z=film_z).z_entrance_pupil
    n = obj_pts.shape[0]

    def at_stop(a, b):
        P = np.tile(obj_pts, (a.size // n, 1))
        pos = np.stack([P[:, 0], P[:, 1], np.full(a.size, object_z)], axis=1)
        d = np.stack([a - P[:, 0], b - P[:, 1], np.full(a.size, z_ep - object_z)], axis=1)
        out = trace_through(front, RayBatch.from_arrays(pos, d, wl), clip=False)
        assert out.ok.all()
        return np.stack([out.x, out.y], axis=1), pos, d

    a = obj_pts[:, 0] * (z_ep_x - z_ep) / (z_ep_x - object_z)
    b = np.zeros(n)
    e = 1e-6
    for _ in range(30):
        s, _, _ = at_stop(np.concatenate([a, a + e, a]), np.concatenate([b, b, b + e]))
        r, ra, rb = s[:n], (s[n:2 * n] - s[:n]) / e, (s[2 * n:] - s[:n]) / e
        if np.abs(r).max() < 1e-10:
            break
        det = ra[:, 0] * rb[:, 1] - rb[:, 0] * ra[:, 1]
        a = a - (rb[:, 1] * r[:, 0] - rb[:, 0] * r[:, 1]) / det
        b = b - (-ra[:, 1] * r[:, 0] + ra[:, 0] * r[:, 1]) / det
    assert np.abs(r).max() < 1e-8
    _, pos, d = at_stop(a, b)
    out = trace_through(q, RayBatch.from_arrays(pos, d, wl), end_z=film_z, clip=False)
    assert out.ok.all()
    return np.stack([out.x, out.y], axis=1)


def forward_chief_marching(q, obj_pts, object_z, film_z, wl, substeps=8):
    """As :func:`forward_chief_to_film` for points along one line from the axis (sorted by distance from
    it), each aimed from the previous one's solution in ``substeps`` steps: a fisheye's wide fields, whose
    rays aimed at the axis of the entrance pupil miss the front element, are reached by continuation."""
    k = q.stop_index
    front = q.with_surfaces(q.surfaces[: k + 1])
    z_ep = gaussian(q, wavelength_nm=wl, object_z=object_z, film_z=film_z).z_entrance_pupil

    def stop_hit(P, a, b):
        pos = np.array([[P[0], P[1], object_z]] * a.size)
        d = np.stack([a - P[0], b - P[1], np.full(a.size, z_ep - object_z)], axis=1)
        out = trace_through(front, RayBatch.from_arrays(pos, d, wl), clip=False)
        return np.stack([out.x, out.y], axis=1), out.ok, pos, d

    film = []
    a = b = 0.0
    prev = np.zeros(2)
    e = 1e-7
    for P in np.asarray(obj_pts, dtype=float):
        for t in np.linspace(0.0, 1.0, substeps + 1)[1:]:
            Pt = prev + t * (P - prev)
            for _ in range(40):
                s, ok, _, _ = stop_hit(Pt, np.array([a, a + e, a]), np.array([b, b, b + e]))
                assert ok.all(), "the continuation lost the chief ray"
                r, ra, rb = s[0], (s[1] - s[0]) / e, (s[2] - s[0]) / e
                if np.abs(r).max() < 1e-10:
                    break
                det = ra[0] * rb[1] - rb[0] * ra[1]
                a, b = a - (rb[1] * r[0] - rb[0] * r[1]) / det, b - (-ra[1] * r[0] + ra[0] * r[1]) / det
            assert np.abs(r).max() < 1e-8
        prev = P
        _, _, pos, d = stop_hit(P, np.array([a]), np.array([b]))
        out = trace_through(q, RayBatch.from_arrays(pos, d, wl), end_z=film_z, clip=False)
        assert out.ok.all()
        film.append((out.x[0], out.y[0]))
    return np.array(film)


def ideal_grid_and_real(lens, focus_mm, sensor, size, nx=11, ny=8, margin=(40, 30)):
    """An ideal pixel grid inside the frame and the forward-traced real pixel of each point."""
    wl = lens.wavelength_nm
    st = focus(lens, focus_mm, axis="y", wavelength_nm=wl)
    q = st.prescription
    gx = gaussian(q, axis="x", wavelength_nm=wl, object_z=st.object_z, film_z=st.film_z)
    gy = gaussian(q, axis="y", wavelength_nm=wl, object_z=st.object_z, film_z=st.film_z)
    sx, sy = size[0] / sensor[0], size[1] / sensor[1]
    X, Y = np.meshgrid(np.linspace(margin[0], size[0] - margin[0], nx), np.linspace(margin[1], size[1] - margin[1], ny))
    ideal = np.stack([X.ravel(), Y.ravel()], axis=1)
    # the object point the pinhole (focal length f, at the entrance pupil) images at the ideal pixel
    Xo = (ideal[:, 0] - size[0] / 2) / sx / gx.pinhole_focal_length * (gx.z_entrance_pupil - st.object_z)
    Yo = (ideal[:, 1] - size[1] / 2) / sy / gy.pinhole_focal_length * (gy.z_entrance_pupil - st.object_z)
    film = forward_chief_to_film(q, np.stack([Xo, Yo], axis=1), st.object_z, st.film_z, wl)
    # the picture is the film image turned by 180 degrees; pixels from the bottom-left corner
    real = np.stack([size[0] / 2 - film[:, 0] * sx, size[1] / 2 - film[:, 1] * sy], axis=1)
    return ideal, real


