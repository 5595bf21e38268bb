"""3DEqualizer lens files from a fitted "3DE4 Radial - Standard, Degree 4" model (docs/distortion.md).

The file is 3DE4's plain-text lens format, the one its *Import Lens...* script reads (a line each,
in order): the lens name; ``filmback width, filmback height, focal length, film aspect, lens centre
x, lens centre y, pixel aspect`` (lengths in cm, separated by spaces); the dynamic distortion mode;
the distortion model's name; then for each model parameter its name, its value and its curve (a
key count, 0 here: a static lens); and ``<end_of_file>``. Lens centre offsets are 0 (physcam's
lenses are centred); the focus distance the fit was made at is in the lens name.
"""

from __future__ import annotations

import math

from ..analysis.distortion_models import TDE4_MODEL, TDE4_PARAMETERS, TDE4RadialStandard
from ..errors import InputError

__all__ = ["tde4_lens_text"]


def _num(v: float) -> str:
    if not math.isfinite(v):
        raise InputError(f"a 3DE4 lens value must be finite, got {v!r}")
    return repr(float(v))


def tde4_lens_text(fit: TDE4RadialStandard, name: str | None = None) -> str:
    """The 3DE4 lens file of ``fit`` (module notes); refuses a fit whose residual is not acceptable."""
    if not isinstance(fit, TDE4RadialStandard):
        raise InputError(f"tde4_lens_text takes a TDE4RadialStandard fit, got {type(fit).__name__}")
    fit.require_acceptable("3DE4 lens file")
    lp = fit.lens_parameters()
    if name is None:
        name = "physcam lens"
    focus = "infinity" if math.isinf(fit.focus_from_film_mm) else f"{fit.focus_from_film_mm / 1000:g} m"
    title = " ".join(f"{name} (physcam fit at focus {focus})".split())
    w, h = lp["tde4_filmback_width_cm"], lp["tde4_filmback_height_cm"]
    lines = [
        title,
        " ".join(_num(v) for v in (w, h, lp["tde4_focal_length_cm"], w / h, lp["tde4_lens_center_offset_x_cm"],
                                    lp["tde4_lens_center_offset_y_cm"], lp["tde4_pixel_aspect"])),
        "DISTORTION_STATIC",
        TDE4_MODEL,
    ]
    for p in TDE4_PARAMETERS:
        lines += [p, _num(fit.coefficients[p]), "0"]
    lines.append("<end_of_file>")
    return "\n".join(lines) + "\n"
