"""3DEqualizer lens files from a fitted "3DE4 Radial - Standard, Degree 4" model (docs/distortion.md).

The file is 3DE4's plain-text lens format, the one its *Import Lens...* script reads (a line each,
in order): the lens name; ``filmback width, filmback height, focal length, film aspect, lens centre
x, lens centre y, pixel aspect`` (lengths in cm, separated by spaces); the dynamic distortion mode;
the distortion model's name; then for each model parameter its name, its value and its curve (a
key count, 0 here: a static lens); and ``<end_of_file>``. The focus distance the fit was made at is
in the lens name.

**Lens centre offset** (3DE4's ``tde4_lens_center_offset_x_cm`` / ``_y_cm``): where the lens centre,
the point the distortion model is centred on, lies from the filmback's centre, in cm on the
filmback, x to the right, y *up*. That is 3DE4's own convention as its Lens Distortion Plugin Kit
writes it (Science-D-Visions, LDPK ``ldpk_ldp_builtin.h`` / ``tde4_ldp_common_sdv.h``,
``map_unit_to_dn``): a point's diagonally normalised coordinate is
``((unit - 1/2) * filmback - lens centre offset) / r_fb``; Natron's port of that code
(openfx-misc ``Distortion/Distortion.cpp``) makes the unit coordinates from Nuke's pixel
coordinates, (0, 0) at the image's lower-left corner, so y is up. physcam's fits are made about the principal point
(a prescription's lens: the frame centre, offset 0; a chart calibration: the measured principal
point, ``MarkCalibration.principal_offset_mm``, also x right, y up from the frame centre), so the
offset written is that point's, divided by 10.
"""

from __future__ import annotations

import math

from ..analysis.distortion.models import TDE4_MODEL, TDE4_PARAMETERS, TDE4RadialStandard
from ..errors import InputError
from ._codetext import printable_line

__all__ = ["tde4_lens_text", "tde4_anamorphic_lens_text"]


def _num(v: float) -> str:
    if not math.isfinite(v):
        raise InputError(f"a 3DE4 lens value must be finite, got {v!r}")
    return repr(float(v))


def _offset_cm(offset_mm) -> tuple[float, float]:
    if isinstance(offset_mm, (str, bytes)) or not hasattr(offset_mm, "__len__") or len(offset_mm) != 2:
        raise InputError(f"the lens centre offset is (x, y) in mm from the filmback centre, got {offset_mm!r}")
    try:
        x, y = (float(v) for v in offset_mm)
    except (TypeError, ValueError):
        raise InputError(f"the lens centre offset is two numbers of mm, got {offset_mm!r:.60}") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise InputError(f"the lens centre offset must be finite, got {offset_mm!r}")
    return x / 10.0, y / 10.0


def tde4_lens_text(fit: TDE4RadialStandard, name: str | None = None, *,
                   lens_center_offset_mm=(0.0, 0.0)) -> str:
    """The 3DE4 lens file of ``fit`` (module notes); refuses a fit whose residual is not acceptable.
    ``lens_center_offset_mm``: the point ``fit`` is centred on (the principal point) from the filmback
    centre, mm, x right, y up; written in 3DE4's cm, same signs (module notes)."""
    if not isinstance(fit, TDE4RadialStandard):
        raise InputError(f"tde4_lens_text takes a TDE4RadialStandard fit, got {type(fit).__name__}")
    return _lens_text(fit, name, lens_center_offset_mm, TDE4_MODEL, TDE4_PARAMETERS)


def tde4_anamorphic_lens_text(fit, name: str | None = None, *, lens_center_offset_mm=(0.0, 0.0)) -> str:
    """The 3DE4 lens file of a fitted "3DE4 Anamorphic - Standard, Degree 4/6"
    (:func:`physcam.analysis.distortion.anamorphic.fit_tde4_anamorphic`): the desqueezed filmback, the Y
    pinhole as focal length and f_y / f_x as pixel aspect; Lens Rotation 0, Squeeze-X and -Y 1."""
    from ..analysis.distortion.anamorphic import TDE4Anamorphic, tde4_anamorphic_parameter_names

    if not isinstance(fit, TDE4Anamorphic):
        raise InputError(f"tde4_anamorphic_lens_text takes a TDE4Anamorphic fit, got {type(fit).__name__}")
    coeffs = dict(fit.coefficients, **{"Lens Rotation": 0.0, "Squeeze-X": 1.0, "Squeeze-Y": 1.0})
    names = (*tde4_anamorphic_parameter_names(int(fit.coefficients["degree"])), "Lens Rotation", "Squeeze-X",
             "Squeeze-Y")
    return _lens_text(fit, name, lens_center_offset_mm, fit.model, names, coeffs)


def _lens_text(fit, name, lens_center_offset_mm, model: str, parameters, coefficients=None) -> str:
    """The lens file's lines (module notes) for any fitted 3DE4 model with ``lens_parameters``."""
    fit.require_acceptable("3DE4 lens file")
    coefficients = fit.coefficients if coefficients is None else coefficients
    lp = dict(fit.lens_parameters())
    lp["tde4_lens_center_offset_x_cm"], lp["tde4_lens_center_offset_y_cm"] = _offset_cm(lens_center_offset_mm)
    if name is None:
        name = "physcam lens"
    focus = "infinity" if math.isinf(fit.focus_from_film_mm) else f"{fit.focus_from_film_mm / 1000:g} m"
    title = " ".join(printable_line(f"{name} (physcam fit at focus {focus})").split())
    w, h = lp["tde4_filmback_width_cm"], lp["tde4_filmback_height_cm"]
    lines = [
        title,
        " ".join(_num(v) for v in (w, h, lp["tde4_focal_length_cm"], w / h, lp["tde4_lens_center_offset_x_cm"],
                                    lp["tde4_lens_center_offset_y_cm"], lp["tde4_pixel_aspect"])),
        "DISTORTION_STATIC",
        model,
    ]
    for p in parameters:
        lines += [p, _num(coefficients[p]), "0"]
    lines.append("<end_of_file>")
    return "\n".join(lines) + "\n"
