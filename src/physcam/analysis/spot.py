"""Spot diagram: where rays from one field point land on the film, and how spread they are.

For each field angle (degrees, in the Y-Z meridian) a collimated beam fills the paraxial entrance
pupil (overfilled by ``overfill`` so real pupil shifts are covered; the stop and element rims
clip what does not pass) with deterministic equal-area samples, and is traced to the film plane
(``film_z``, mm in lens space; default the paraxial image plane at the design wavelength).
RMS radius is about the centroid, sqrt(mean(dx^2 + dy^2)); geometric radius the largest
distance from the centroid. Both in micrometres.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError, OpticsError, require_finite
from ..lens.prescription import Prescription

__all__ = ["equal_area_disk", "SpotField", "SpotDiagram", "spot_diagram"]


def equal_area_disk(radius: float, n_rings: int):
    """Deterministic equal-area samples of a disk: ring j holds 6 j cells of equal area,
    each represented by its area-median radius and mid angle (3 n (n + 1) points)."""
    counts = 6 * np.arange(1, n_rings + 1)
    cum = np.concatenate([[0], np.cumsum(counts)])
    total = cum[-1]
    xs, ys = [], []
    for j, m in enumerate(counts, start=1):
        r_mid = radius * np.sqrt((cum[j - 1] + m / 2) / total)
        phi = (np.arange(m) + 0.5) * 2 * np.pi / m + (0.5 * np.pi / m if j % 2 else 0.0)
        xs.append(r_mid * np.cos(phi))
        ys.append(r_mid * np.sin(phi))
    return np.concatenate(xs), np.concatenate(ys)


@dataclass
class SpotField:
    field_deg: float
    rays_launched: int
    rays_passed: int
    centroid_x_mm: float
    centroid_y_mm: float
    rms_radius_um: float
    geometric_radius_um: float
    x_mm: np.ndarray = field(repr=False)
    y_mm: np.ndarray = field(repr=False)

    def to_dict(self) -> dict:
        return {k: getattr(self, k) for k in (
            "field_deg", "rays_launched", "rays_passed", "centroid_x_mm", "centroid_y_mm",
            "rms_radius_um", "geometric_radius_um")}


@dataclass
class SpotDiagram:
    lens_name: str
    wavelength_nm: float
    film_z_mm: float
    fields: list[SpotField]

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "wavelength_nm": self.wavelength_nm, "film_z_mm": self.film_z_mm,
                "film_z_reference": "lens space: mm from the first vertex, +z toward the film",
                "fields": [f.to_dict() for f in self.fields]}

    def plot(self, path=None, *, force: bool = False):
        """Draw one panel per field (positions relative to the centroid, um); write it to ``path`` (PNG/SVG/PDF) and return the path, else return the figure."""
        from ..figures import pyplot

        plt = pyplot()

        n = len(self.fields)
        fig, axes = plt.subplots(1, n, figsize=(3.2 * n, 3.4), squeeze=False)
        for ax, f in zip(axes[0], self.fields):
            ax.scatter((f.x_mm - f.centroid_x_mm) * 1e3, (f.y_mm - f.centroid_y_mm) * 1e3, s=0.3, c="k", lw=0)
            ax.set_aspect("equal")
            ax.set_title(f"{f.field_deg:g} deg\nRMS {f.rms_radius_um:.2f} um, GEO {f.geometric_radius_um:.2f} um",
                         fontsize=8)
            ax.set_xlabel("x (um)")
        axes[0][0].set_ylabel("y (um)")
        fig.suptitle(f"{self.lens_name}: spot diagram at {self.wavelength_nm:g} nm", fontsize=9)
        fig.tight_layout()
        if path is None:
            return fig
        from ..figures import save_figure

        return save_figure(fig, path, force=force)


def spot_diagram(
    lens: Prescription,
    fields_deg=(0.0,),
    *,
    wavelength_nm: float | None = None,
    film_z: float | None = None,
    rings: int = 40,
    overfill: float = 1.3,
    pupil_radius: float | None = None,
    fstop: float | None = None,
    backend: str = "auto",
) -> SpotDiagram:
    """Spot diagram of ``lens`` at the given field angles (see module notes).

    ``pupil_radius`` (mm) replaces the overfilled entrance pupil by a disk of that radius on the
    entrance-pupil plane (e.g. to compare with a published figure at a given beam size).
    ``fstop`` stops the lens down (the stop's semi-diameter scaled to that f-number).
    """
    from ..optics.paraxial import gaussian
    from ..trace import RayBatch, paraxial_image_z, trace_to_film

    wl = lens.wavelength_nm if wavelength_nm is None else require_finite("wavelength_nm", wavelength_nm)
    if film_z is None:
        film_z = paraxial_image_z(lens, wl)
    if not 1 <= rings <= 2000:
        raise InputError(f"rings must lie between 1 and 2000 (3 n (n + 1) rays per field), got {rings}")
    stop = None
    if fstop is not None:
        from ..optics.paraxial import stop_semi_diameter_for_fstop

        stop = stop_semi_diameter_for_fstop(lens, fstop, wavelength_nm=wl)
    g = gaussian(lens, wavelength_nm=wl, fstop=fstop)
    z_ep, r_ep = g.z_entrance_pupil, g.entrance_pupil_diameter / 2
    beam = r_ep * overfill if pupil_radius is None else require_finite("pupil_radius", pupil_radius)
    if beam <= 0:
        raise InputError(f"pupil_radius must be > 0 mm, got {beam:g}")
    px, py = equal_area_disk(beam, rings)
    out = []
    for fd in fields_deg:
        fd = require_finite("field angle", fd)
        if not -89.0 < fd < 89.0:
            raise InputError(f"field angle must lie between -89 and 89 degrees, got {fd:g}")
        th = np.radians(fd)
        d = np.array([0.0, np.sin(th), np.cos(th)])
        z0 = min(z_ep, 0.0) - 1.0
        back = (z_ep - z0) / d[2]
        start = np.stack([px, py - back * d[1], np.full(px.size, z0)], axis=1)
        rays = RayBatch.from_arrays(start, d[None, :], wl)
        res = trace_to_film(lens, rays, film_z, stop_semi_diameter=stop, backend=backend)
        ok = res.ok
        if not ok.any():
            raise OpticsError(f"no ray at field {fd:g} deg passes through {lens.name!r}; choose a smaller field angle")
        x, y = res.x[ok], res.y[ok]
        cx, cy = float(x.mean()), float(y.mean())
        r2 = (x - cx) ** 2 + (y - cy) ** 2
        out.append(SpotField(fd, int(len(rays)), int(ok.sum()), cx, cy, float(np.sqrt(r2.mean()) * 1e3),
                             float(np.sqrt(r2.max()) * 1e3), x, y))
    return SpotDiagram(lens.name, wl, float(film_z), out)
