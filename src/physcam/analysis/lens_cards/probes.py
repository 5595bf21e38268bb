"""The ray-traced probes of ``physcam lens check`` (:func:`physcam.lens.check.check` takes them as
``probes``): the on-axis beam at full aperture against the stop, and, with a sensor, the corner's
relative illumination and image circle. They live here, not in ``physcam.lens``, because they trace
rays (the layering: lens files below optics and tracing)."""

from __future__ import annotations

__all__ = ["ray_probes"]


def ray_probes(sensor_name: str | None):
    """Ray-traced checks for :func:`physcam.lens.check.check` (they need the trace and analysis layers):
    the on-axis beam clipped by element rims at full aperture and, with a sensor, vignetting and the
    image circle at its corner."""
    import math

    from ...lens.check import Finding

    def beam(p):
        import numpy as np

        from ...optics.paraxial import gaussian
        from ...trace import OK, RayBatch, trace_to_film

        g = gaussian(p)
        r = 0.5 * g.entrance_pupil_diameter
        n = 101
        u = np.linspace(-r, r, n)
        x, y = np.meshgrid(u, u)
        inside = x * x + y * y <= r * r
        x, y = x[inside], y[inside]
        out = trace_to_film(p, RayBatch.collimated(x, y, -1.0), backend="numpy")
        frac = 1.0 - float(np.count_nonzero(out.flag == OK)) / len(x)
        if frac > 0.01:
            return [Finding("warning" if frac > 0.10 else "note", "beam_clipped",
                            f"element rims clip {100 * frac:.1f} % of the on-axis beam at full aperture "
                            f"(rays filling the paraxial entrance pupil, {2 * r:.3f} mm)",
                            "the lens is slower on axis than its stop says; the working aperture is set by a rim, "
                            "not the stop", p.stop_index, values={"clipped_fraction": frac})]
        return []

    def corner(p):
        from .. import _chief
        from ..image_quality.illumination import relative_illumination
        from ...errors import OpticsError
        from ...optics.sensors import find_sensor
        from ...optics.paraxial import gaussian
        from ...optics.state import as_designed

        s = find_sensor(sensor_name)
        half = 0.5 * s.diagonal_mm
        efl = gaussian(p).efl
        corner_deg = float(_chief.field_angles_deg(None, None, 2, half, efl)[-1])
        try:
            res = relative_illumination(as_designed(p, sensor=s), [corner_deg], grid=64, backend="numpy")
        except OpticsError as exc:
            limit = _chief.field_limit_deg(p, "y", wavelength_nm=p.wavelength_nm)
            circle = 2 * abs(efl) * math.tan(math.radians(limit))
            return [Finding("warning", "image_circle",
                            f"no chief ray reaches the corner of {s.name} ({s.diagonal_mm:.2f} mm diagonal, "
                            f"{corner_deg:.2f} deg): chief rays pass up to {limit:.2f} deg, an image circle of about "
                            f"{circle:.1f} mm", f"the corners of {s.name} stay dark ({str(exc).splitlines()[0]})",
                            values={"sensor_diagonal_mm": s.diagonal_mm, "field_limit_deg": limit,
                                    "image_circle_mm": circle})]
        pt = res.points[-1]
        out = []
        sev = "warning" if pt.relative_illumination < 0.25 else "note"
        out.append(Finding(sev, "corner_vignetting",
                           f"at the corner of {s.name} ({corner_deg:.2f} deg) the relative illumination is "
                           f"{100 * pt.relative_illumination:.1f} % (vignetting factor {pt.vignetting_factor:.3f}, "
                           f"cos^4 {pt.cos4:.3f})", f"{-math.log2(max(pt.relative_illumination, 1e-9)):.2f} stops "
                           "darker than the centre at full aperture",
                           values={"relative_illumination": pt.relative_illumination,
                                   "vignetting_factor": pt.vignetting_factor, "field_deg": corner_deg,
                                   "sensor_diagonal_mm": s.diagonal_mm}))
        return out

    return [beam] + ([corner] if sensor_name else [])
