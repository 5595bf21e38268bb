"""Focus breathing from real rays: the field of view at the sensor edge and corner against focus.

For each focus mark (mm in front of the film plane) the lens is focused with
:func:`physcam.optics.focusing.focus` (unit or internal focusing, in the Y meridian as on set).
From the sensor edge (w/2, 0) and corner (w/2, h/2) on the film, the real chief ray is aimed
backward through the centre of the stop (:mod:`physcam.analysis._chief`) and traced out of the
lens; its angle to the axis in object space is the real half field of view at that mark
(HFOV = 2 x the edge angle, DFOV = 2 x the corner angle). The paraxial figures are those of
:func:`physcam.optics.focusing.breathing_table` (paraxial chief ray, X meridian), so the two
columns differ only by the real rays: distortion, pupil aberration. Angles in degrees.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM, DEFAULT_SENSOR_WIDTH_MM
from ...errors import OpticsError, require_positive
from ...lens.prescription import Prescription, takes_prescription
from ...figures import styled

__all__ = ["RealBreathingRow", "RealBreathing", "real_breathing"]


@dataclass(frozen=True)
class RealBreathingRow:
    focus_from_film_mm: float
    hfov_paraxial_deg: float
    hfov_real_deg: float
    dfov_real_deg: float | None  # None where the corner's chief ray is clipped (lens does not cover it)
    change_paraxial_pct: float  # HFOV change from infinity (or the first mark), paraxial
    change_real_pct: float
    back_focus_mm: float

    def to_dict(self) -> dict:
        d = {k: getattr(self, k) for k in self.__dataclass_fields__}
        if math.isinf(d["focus_from_film_mm"]):
            d["focus_from_film_mm"] = None
        return d


@dataclass
class RealBreathing:
    lens_name: str
    wavelength_nm: float
    sensor_mm: tuple[float, float]
    method: str
    rows: list[RealBreathingRow]

    def to_dict(self) -> dict:
        return {"lens": self.lens_name, "wavelength_nm": self.wavelength_nm, "sensor_mm": list(self.sensor_mm),
                "method": self.method, "rows": [r.to_dict() for r in self.rows],
                "conventions": "focus marks in mm in front of the film plane (null = infinity); "
                               "changes relative to the first row"}

    @styled
    def plot(self, path=None, *, force: bool = False, units: str = "m"):
        """HFOV change against the focus mark (log axis, a tick at each mark in ``units``: m, or ft for
        feet and inches; infinity at the right); PNG/SVG/PDF if ``path``, else the Figure."""
        from .._plot import distance_ticks, figure, per_unit, save, unit_words

        per = per_unit(units)
        fig, ax = figure(5.2, 3.6)
        marks = [r.focus_from_film_mm for r in self.rows]
        finite = [m for m in marks if math.isfinite(m)]
        x_inf = 2 * max(finite) / per if finite else 1.0
        ax.set_xscale("log")
        xs = distance_ticks(ax, marks, units, x_of_inf=x_inf)
        ax.plot(xs, [r.change_paraxial_pct for r in self.rows], "o--", ms=3, label="paraxial HFOV")
        ax.plot(xs, [r.change_real_pct for r in self.rows], "s-", ms=3, label="real chief ray HFOV")
        ax.tick_params(axis="x", labelsize=7)
        ax.set_xlabel(f"focus mark from the film ({unit_words(units)}; rightmost point = infinity)")
        ax.set_ylabel("HFOV change (%)")
        ax.set_title(f"{self.lens_name}: focus breathing, {self.sensor_mm[0]:g} x {self.sensor_mm[1]:g} mm",
                     fontsize=8)
        ax.legend(fontsize=7)
        return save(fig, path, force)


def _real_half_angles(st, w, h, wl, backend):
    from ...trace import RayBatch, trace_through
    from .._chief import aim_from_film

    lens, film_z = st.prescription, st.film_z
    aimed = aim_from_film(lens, [[w / 2.0, 0.0], [w / 2.0, h / 2.0]], film_z, wavelength_nm=wl, backend=backend)
    out = trace_through(lens, RayBatch.from_arrays(aimed.start, aimed.direction, wl), reverse=True, backend=backend)
    ok = aimed.ok & out.ok
    if not ok[0]:
        raise OpticsError(
            f"at focus {st.focus_from_film_mm:g} mm the chief ray from the sensor edge ({w / 2:g} mm) does not pass "
            f"{lens.name!r}: the lens does not cover a {w:g} mm wide sensor; give a smaller sensor"
        )
    # the angle to the axis toward the scene (-z): beyond 90 deg for a fisheye corner, not folded back
    ang = np.degrees(np.arctan2(np.hypot(out.L, out.M), -out.N))
    return float(ang[0]), (float(ang[1]) if ok[1] else None)


@takes_prescription
def real_breathing(
    lens: Prescription,
    focus_marks_mm=None,
    *,
    sensor_width_mm: float = DEFAULT_SENSOR_WIDTH_MM,
    sensor_height_mm: float = DEFAULT_SENSOR_HEIGHT_MM,
    method: str = "auto",
    wavelength_nm: float | None = None,
    backend: str = "auto",
) -> RealBreathing:
    """Real against paraxial breathing of ``lens`` (module notes); marks default as in the breathing table.

    The sensor is ``sensor_width_mm`` x ``sensor_height_mm`` (default Super 35, 24.89 x 18.66 mm: :data:`physcam.data.default_sensor.DEFAULT_SENSOR`, the CLI's default too).
    """
    from ...optics.focusing import breathing_table, focus, focus_method

    w = require_positive("sensor width", sensor_width_mm)
    h = require_positive("sensor height", sensor_height_mm)
    wl = lens.wavelength_nm if wavelength_nm is None else require_positive("wavelength", wavelength_nm, unit="nm")
    table = breathing_table(lens, focus_marks_mm, sensor_width_mm=w, method=method, wavelength_nm=wl)
    m = focus_method(lens, method)
    rows = []
    first = None
    for row in table:
        st = focus(lens, row.focus_from_film_mm, method=m, axis="y", wavelength_nm=wl)
        edge, corner = _real_half_angles(st, w, h, wl, backend)
        hf = 2.0 * edge
        if first is None:
            first = (row.hfov_deg, hf)
        rows.append(RealBreathingRow(row.focus_from_film_mm, row.hfov_deg, hf, None if corner is None else 2.0 * corner,
                                     100.0 * (row.hfov_deg / first[0] - 1.0), 100.0 * (hf / first[1] - 1.0),
                                     st.back_focus_mm))
    return RealBreathing(lens.name, float(wl), (w, h), m, rows)
