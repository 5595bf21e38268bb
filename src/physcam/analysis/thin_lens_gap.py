"""How far a renderer's thin-lens camera is from the real lens, at one stop and focus.

Renderers' built-in cameras (Blender's, RenderMan's PxrCamera, Mitsuba's ``thinlens``, USD's
UsdGeomCamera) are a pinhole that frames like physcam's best-match pinhole plus a thin-lens blur
of the entrance pupil's diameter (docs/lens-report.md). A real prescription differs at working
apertures: distortion widens or narrows the real field, and aberrations, vignetting and the
pupils' real positions change the blur. This module measures both gaps so every thin-lens export
can print them instead of calling the thin-lens blur "the lens's":

* **field of view**: the pinhole's horizontal field against the real chief rays' from the film
  edge (:func:`physcam.analysis.field_of_view.real_field_of_view`, kept in the report);
* **bokeh**: the thin lens's blur diameter on the film, A f_pin |1/d - 1/s| (A the entrance
  pupil's diameter, f_pin the pinhole's focal length, d and s the light's and the focus plane's
  distances from the entrance pupil), against the second-moment diameter sqrt(8 E[r^2]) of the
  real lens's traced image of an on-axis point light (a uniform disk of diameter c has
  sqrt(8 E[r^2]) = c), at half and at twice the focus distance.

Each figure is (thin lens - real lens) / real lens, in percent: negative means the renderer's
camera frames narrower or blurs less than the real lens.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import OpticsError, PhysCamError, require_type

__all__ = ["ThinLensGap", "thin_lens_gap"]

#: Rays per traced bokeh: 1 % noise on its second-moment diameter (docs/ray-tracing.md).
BOKEH_RAYS = 60_000


@dataclass(frozen=True)
class ThinLensGap:
    """The thin-lens camera against the real lens at one stop and focus (module notes)."""

    lens_name: str
    fstop: float
    focus_from_film_mm: float
    hfov_difference_pct: float | None
    #: (light distance from the film mm, thin-lens diameter mm, real diameter mm, difference %)
    bokeh: tuple[tuple[float, float, float, float], ...] = ()
    notes: tuple[str, ...] = field(default_factory=tuple)

    def summary(self) -> str:
        """One line for a note or a script's comment."""
        parts = []
        if self.hfov_difference_pct is not None:
            parts.append(f"horizontal field of view {self.hfov_difference_pct:+.2f} %")
        for light, _, _, pct in self.bokeh:
            parts.append(f"bokeh {pct:+.0f} % for a light {light / 1000.0:.3g} m from the film")
        focus = "infinity" if math.isinf(self.focus_from_film_mm) else f"{self.focus_from_film_mm / 1000.0:.3g} m"
        what = "; ".join(parts) if parts else "not measured"
        return (f"a thin-lens camera is not {self.lens_name} at f/{self.fstop:.3g}, focus {focus}: "
                f"{what} (thin lens against the real lens's traced rays)")

    def to_dict(self) -> dict:
        return {
            "lens": self.lens_name, "fstop": self.fstop,
            "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
            "hfov_difference_pct": self.hfov_difference_pct,
            "bokeh": [{"light_from_film_mm": l, "thin_lens_diameter_mm": t, "real_diameter_mm": r,
                       "difference_pct": p} for l, t, r, p in self.bokeh],
            "definition": "(thin lens - real lens) / real lens in percent; bokeh diameters sqrt(8 E[r^2]) on the "
                          "film of an on-axis point light",
            "notes": list(self.notes),
        }


def _thin_lens_blur_mm(report, light_from_film_mm: float) -> float:
    """The renderer's thin-lens blur diameter on the film for a light on the axis (module notes)."""
    pupil = report.entrance_pupil_from_film_mm
    pupil = report.h1_from_film_mm if pupil is None else pupil
    d = light_from_film_mm - pupil
    s = report.focus_from_film_mm - pupil
    inv_s = 0.0 if math.isinf(s) else 1.0 / s
    return report.aperture_diameter_mm * report.pinhole[0] * abs(1.0 / d - inv_s)


def _real_blur_mm(state, light_from_film_mm: float) -> float:
    """sqrt(8 E[r^2]) of the real lens's traced image of an on-axis point light; ``state()`` gives the
    camera state (made when first asked, so a stop the lens cannot open to is a note of each light)."""
    from .blob import equivalent_diameter
    from .bokeh import bokeh_image

    st = state()
    img = bokeh_image(st.focused, light_from_film_mm, film_z=st.film_z, rays=BOKEH_RAYS, pixels=128,
                      fresnel=False, stop_semi_diameter=st.stop_semi_diameter)
    x0, x1, _, _ = img.extent_mm
    return equivalent_diameter(img.image.sum(axis=2), pixel=(x1 - x0) / img.image.shape[1])


def _lights_mm(report, lens) -> list[float]:
    """Half and twice the focus distance from the film (1 m when focused at infinity), in front of the lens."""
    from ..optics import focusing

    mark = report.focus_from_film_mm
    front = focusing.focus(lens, mark).film_z  # the front vertex's distance from the film
    lights = [1000.0] if math.isinf(mark) else [0.5 * mark, 2.0 * mark]
    return [d for d in lights if d > front + 10.0]


def _camera(report, lens):
    """The camera state of ``report`` (its focus mark and f-stop) on ``lens``, made once when first
    asked; a CameraState given as ``lens`` must be the report's."""
    import functools

    from ..errors import InputError
    from ..optics.state import CameraState, camera_state

    if isinstance(lens, CameraState):
        if (lens.focus_from_film_mm, lens.fstop) != (report.focus_from_film_mm, report.fstop):
            raise InputError(f"the camera state (focus {lens.focus_from_film_mm:g} mm, f/{lens.fstop:g}) is not the "
                             f"report's (focus {report.focus_from_film_mm:g} mm, f/{report.fstop:g})")
        return lambda: lens
    return functools.cache(lambda: camera_state(lens, focus_mm=report.focus_from_film_mm, fstop=report.fstop))


def thin_lens_gap(report, lens) -> ThinLensGap:
    """The thin-lens camera of ``report`` against the real ``lens`` it was solved from (module notes).

    ``report`` must come from :func:`physcam.onset.report.solve_lens_report` with ``lens``, a
    Prescription or the :class:`~physcam.optics.state.CameraState` at the report's focus and f-stop.
    A bokeh that cannot be traced (the light inside the lens's closest focus, everything vignetted)
    is left out with a note."""
    from ..lens.prescription import Prescription
    from ..onset.report import LensReport
    from ..optics.state import CameraState

    require_type("report", report, LensReport, "solve one with physcam.onset.report.solve_lens_report")
    if not isinstance(lens, CameraState):
        require_type("lens", lens, Prescription, "physcam.lens.library.load_lens(name or file) or a CameraState")
    state = _camera(report, lens)
    lens = lens.lens if isinstance(lens, CameraState) else lens
    hfov = None if report.real_fov is None else report.real_fov.get("horizontal_deg")
    hfov_pct = None if not hfov else (report.hfov_focus_deg - hfov) / hfov * 100.0
    rows, notes = [], []
    for light in _lights_mm(report, lens):
        try:
            thin, real = _thin_lens_blur_mm(report, light), _real_blur_mm(state, light)
        except PhysCamError as exc:
            notes.append(f"bokeh at {light:g} mm not measured: {str(exc).splitlines()[0]}")
            continue
        if not real > 0:
            raise OpticsError(f"no light from {light:g} mm reaches the film through {lens.name!r}")
        rows.append((light, thin, real, (thin - real) / real * 100.0))
    return ThinLensGap(lens.name, report.fstop, report.focus_from_film_mm, hfov_pct, tuple(rows), tuple(notes))
