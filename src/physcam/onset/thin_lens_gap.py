"""How far a renderer's thin-lens camera is from the real lens, at one stop and focus.

Renderers' built-in cameras (Blender's, RenderMan's PxrCamera, Mitsuba's ``thinlens``, USD's
UsdGeomCamera) are a pinhole that frames like physcam's best-match pinhole plus a thin-lens blur
of the entrance pupil's diameter (docs/lens-report.md). A real prescription differs at working
apertures: distortion widens or narrows the real field, and aberrations, vignetting and the
pupils' real positions change the blur. This module measures both gaps so every thin-lens export
can print them instead of calling the thin-lens blur "the lens's":

* **field of view**: the pinhole's horizontal field against the real chief rays' from the film
  edge (:func:`physcam.analysis.framing.field_of_view.real_field_of_view`, kept in the report);
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
from ..optics.state import CameraState, OfACamera

__all__ = ["ThinLensGap", "thin_lens_gap"]

#: Rays per traced bokeh: 1 % noise on its second-moment diameter (docs/ray-tracing.md).
BOKEH_RAYS = 60_000


@dataclass(frozen=True)
class ThinLensGap(OfACamera):
    """The thin-lens camera against the real lens of ``camera`` at its stop and focus (module notes)."""

    lens_name: str
    camera: CameraState  # the report's camera: its focus (.focus_from_film_mm) and f-stop (.fstop)
    hfov_difference_pct: float | None
    #: (light distance from the film mm, thin-lens diameter mm, real diameter mm, difference %)
    bokeh: tuple[tuple[float, float, float, float], ...] = ()
    notes: tuple[str, ...] = field(default_factory=tuple)

    def summary(self, units: str = "m") -> str:
        """One line for a note or a script's comment, its distances in ``units`` (``--units``): metres to three
        figures (``m``, what files carry), or feet and inches (``ft``, :func:`physcam.units.format_distance`)."""
        parts = []
        if self.hfov_difference_pct is not None:
            parts.append(f"horizontal field of view {self.hfov_difference_pct:+.2f} %")
        for light, _, _, pct in self.bokeh:
            parts.append(f"bokeh {pct:+.0f} % for a light {_distance(light, units)} from the film")
        focus = "infinity" if math.isinf(self.focus_from_film_mm) else _distance(self.focus_from_film_mm, units)
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


def _distance(mm: float, units: str) -> str:
    """A distance of :meth:`ThinLensGap.summary`: metres to three figures, or feet and inches."""
    from ..units import format_distance

    return format_distance(mm, "ft") if units == "ft" else f"{mm / 1000.0:.3g} m"


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
    from ..analysis.defocus.blob import equivalent_diameter
    from ..analysis.defocus.bokeh import bokeh_image

    st = state()  # the lens focused at the report's mark, its film there, the iris set
    img = bokeh_image(st.with_aperture(None), light_from_film_mm, rays=BOKEH_RAYS, pixels=128, fresnel=False)
    x0, x1, _, _ = img.extent_mm
    return equivalent_diameter(img.image.sum(axis=2), pixel=(x1 - x0) / img.image.shape[1])


def _lights_mm(report) -> list[float]:
    """Half and twice the focus distance from the film (1 m when focused at infinity), in front of the lens."""
    mark = report.focus_from_film_mm
    front = report.camera.lens_model.focus_state(mark).film_z  # the front vertex's distance from the film
    lights = [1000.0] if math.isinf(mark) else [0.5 * mark, 2.0 * mark]
    return [d for d in lights if d > front + 10.0]


def _camera(report):
    """The camera of ``report`` with its iris set to the report's f-stop, made once when first asked (an
    f-stop solved from measured limits faster than the lens opens is then a note of each light)."""
    import functools

    return functools.cache(report.stopped_camera)


def thin_lens_gap(report, lens=None) -> ThinLensGap:
    """The thin-lens camera of ``report`` against the real lens of its camera (module notes).

    ``report`` must come from :func:`physcam.onset.report.solve_report` of a prescription's camera.
    A bokeh that cannot be traced (the light inside the lens's closest focus, everything vignetted)
    is left out with a note. ``lens`` (the prescription, or the camera again) is the pre-issue-43 form:
    the report holds its camera; given, it must be that camera's lens (DeprecationWarning)."""
    from ..errors import InputError
    from .report import LensReport

    require_type("report", report, LensReport, "solve one with physcam.onset.report.solve_report(camera)")
    if not report.camera.traceable:
        raise InputError("the thin-lens gap compares with a traced lens: give the report of a prescription's camera")
    if lens is not None:
        import warnings

        warnings.warn("thin_lens_gap(report, lens): the report holds its camera; call thin_lens_gap(report) (the lens "
                      "argument goes in physcam 0.3)", DeprecationWarning, stacklevel=2)
        from ..lens.prescription import Prescription

        require_type("lens", lens, (Prescription, CameraState), "physcam.lens.library.load_lens(name or file)")
        given = lens.lens if isinstance(lens, CameraState) else lens
        if isinstance(lens, CameraState) and (lens.focus_from_film_mm, lens.fstop) != (report.focus_from_film_mm,
                                                                                         report.fstop):
            raise InputError(f"the camera state (focus {lens.focus_from_film_mm:g} mm, f/{lens.fstop:g}) is not the "
                             f"report's (focus {report.focus_from_film_mm:g} mm, f/{report.fstop:g})")
        if given is not report.camera.lens and given != report.camera.lens:
            raise InputError("the lens is not the one the report was solved for")
    state = _camera(report)
    name = report.camera.lens.name
    hfov = None if report.real_fov is None else report.real_fov.get("horizontal_deg")
    hfov_pct = None if not hfov else (report.hfov_focus_deg - hfov) / hfov * 100.0
    rows, notes = [], []
    for light in _lights_mm(report):
        try:
            thin, real = _thin_lens_blur_mm(report, light), _real_blur_mm(state, light)
        except PhysCamError as exc:
            notes.append(f"bokeh at {light:g} mm not measured: {str(exc).splitlines()[0]}")
            continue
        if not real > 0:
            raise OpticsError(f"no light from {light:g} mm reaches the film through {name!r}")
        rows.append((light, thin, real, (thin - real) / real * 100.0))
    return ThinLensGap(name, report.camera, hfov_pct, tuple(rows), tuple(notes))
