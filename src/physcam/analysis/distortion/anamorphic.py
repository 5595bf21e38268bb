"""3DEqualizer's "Anamorphic - Standard, Degree 4" and "Degree 6" fitted to an anamorphic lens's traced field.

The data are the traced pairs of :func:`physcam.analysis.distortion.models.samples_from_field`
(picture mm on the physical, squeezed, film; x right, y up): where the real lens images a point
(*distorted*) and where the best-match pinhole at that focus does (*undistorted*, f_x in X, f_y in Y).

The model (Science-D-Visions, Lens Distortion Plugin Kit, ``ldpk_generic_anamorphic_distortion.h``
and ``tde4_ldp_anamorphic_deg_4_rotate_squeeze_xy.h``; "tde4_ldm_standard.pdf") maps distorted to
undistorted in *diagonally normalised* coordinates of a filmback of width ``w_fb = a * W`` (the
desqueezed width: W the physical sensor width, a the pixel aspect) and height ``h_fb = H`` (Unreal's
``UAnamorphicLensDistortionModelHandler`` takes the filmback the same way, SensorWidth * PixelAspect),
r_fb half its diagonal::

    p = (x_desq, y) / r_fb          (lens rotation 0, Squeeze-X = Squeeze-Y = 1: a centred lens)
    q = (p_x / a, p_y)              the pixel aspect undone: physical, squeezed, coordinates / r_fb
    u = (q_x (1 + sum_{i<=j} Cx_ij r^j cos(i phi)), q_y (1 + sum Cy_ij r^j cos(i phi)))
    p_u = (a u_x, u_y)

with (r, phi) the polar form of q and (i, j) over (0,2), (2,2), (0,4), (2,4), (4,4) for degree 4
(10 coefficients) and also (0,6), (2,6), (4,6), (6,6) for degree 6 (18). In physical mm both ends
are in the same (squeezed) frame: undistorted_mm = r_fb u(distorted_mm / r_fb); the desqueeze only
sets r_fb. 3DE's focal length is then the Y pinhole f_y and its pixel aspect f_y / f_x (the
desqueezed pinhole is round). The fit is linear least squares with every residual weighted in
plate pixels, over every traced ray; residuals are reported as RMS and max pixels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from .models import (DEFAULT_MAX_RESIDUAL_PX, DistortionSamples, FittedDistortion, _allowed, _check,
                                _finish, _lstsq, tde4_lens_parameters)

__all__ = ["TDE4_ANAMORPHIC_MODELS", "TDE4Anamorphic", "anamorphic_terms", "fit_tde4_anamorphic",
           "tde4_anamorphic_parameter_names"]

#: 3DE4's model names by degree.
TDE4_ANAMORPHIC_MODELS = {4: "3DE4 Anamorphic - Standard, Degree 4", 6: "3DE4 Anamorphic - Standard, Degree 6"}


def _orders(degree: int) -> list[tuple[int, int]]:
    """(angular i, radial j) of each term, in LDPK's order: by r's power, then the angle's."""
    if degree not in TDE4_ANAMORPHIC_MODELS:
        raise InputError(f"the 3DE4 anamorphic model has degree 4 or 6, got {degree!r}")
    return [(i, j) for j in range(2, degree + 1, 2) for i in range(0, j + 1, 2)]


def tde4_anamorphic_parameter_names(degree: int) -> list[str]:
    """3DE4's parameter names, in its order: "Cx02 - Degree 2", "Cy02 - Degree 2", "Cx22 - Degree 2", ..."""
    return [f"C{axis}{i}{j} - Degree {j}" for i, j in _orders(degree) for axis in "xy"]


def anamorphic_terms(q: np.ndarray, degree: int) -> np.ndarray:
    """(n, k) values of r^j cos(i phi) at the normalised points ``q`` (n, 2), one column per (i, j)."""
    r = np.hypot(q[:, 0], q[:, 1])
    phi = np.arctan2(q[:, 1], q[:, 0])
    return np.stack([r ** j * np.cos(i * phi) for i, j in _orders(degree)], axis=1)


@dataclass
class TDE4Anamorphic(FittedDistortion):
    """3DE4 Anamorphic - Standard, Degree 4 or 6 (module notes); ``coefficients`` keyed by 3DE's
    parameter names, plus ``pixel_aspect``, ``focal_length_mm`` (f_y), ``r_fb_mm`` and ``degree``."""

    def formula(self, p_mm):
        c = self.coefficients
        r_fb, deg = c["r_fb_mm"], int(c["degree"])
        q = np.atleast_2d(np.asarray(p_mm, dtype=float)) / r_fb
        t = anamorphic_terms(q, deg)
        cx = np.array([c[f"Cx{i}{j} - Degree {j}"] for i, j in _orders(deg)])
        cy = np.array([c[f"Cy{i}{j} - Degree {j}"] for i, j in _orders(deg)])
        return np.stack([q[:, 0] * (1.0 + t @ cx), q[:, 1] * (1.0 + t @ cy)], axis=1) * r_fb

    def lens_parameters(self) -> dict:
        """3DE4's built-in lens parameters (cm): the filmback is the desqueezed one (module notes)."""
        return tde4_lens_parameters(self, self.sensor_mm[0] * self.coefficients["pixel_aspect"])

    def unreal_parameters(self) -> dict:
        """Unreal's ``FAnamorphicDistortionParameters`` (CameraCalibrationCore, "3DE4 Anamorphic -
        Standard Degree 4"): PixelAspect, CX02 ... CY44, SqueezeX, SqueezeY, LensRotation; degree 4 only."""
        c = self.coefficients
        if int(c["degree"]) != 4:
            raise InputError("Unreal's anamorphic lens model is the degree-4 one: fit degree 4 for Unreal")
        out = {"PixelAspect": c["pixel_aspect"]}
        for i, j in _orders(4):
            out[f"CX{i}{j}"] = c[f"Cx{i}{j} - Degree {j}"]
        for i, j in _orders(4):
            out[f"CY{i}{j}"] = c[f"Cy{i}{j} - Degree {j}"]
        out.update(SqueezeX=1.0, SqueezeY=1.0, LensRotation=0.0)
        return out

    def to_dict(self) -> dict:
        d = super().to_dict()
        d["lens_parameters"] = self.lens_parameters()
        if int(self.coefficients["degree"]) == 4:
            d["unreal_anamorphic_parameters"] = self.unreal_parameters()
        return d


def fit_tde4_anamorphic(samples: DistortionSamples, degree: int = 4, *,
                        max_residual_px: float = DEFAULT_MAX_RESIDUAL_PX) -> TDE4Anamorphic:
    """Least-squares 3DE4 Anamorphic - Standard, Degree ``degree`` (4 or 6), distorted to undistorted."""
    _check(samples)
    allowed = _allowed(max_residual_px)
    orders = _orders(degree)
    fx, fy = samples.pinhole_focal_length_mm
    aspect = fy / fx
    r_fb = 0.5 * math.hypot(samples.sensor_mm[0] * aspect, samples.sensor_mm[1])
    q, t = samples.distorted_mm / r_fb, samples.undistorted_mm / r_fb
    terms = anamorphic_terms(q, degree)
    wpx = r_fb * samples.px_per_mm  # pixels per normalised unit, in x and in y
    # x and y have their own coefficients: two independent linear fits, each in pixels
    cx = _lstsq(q[:, :1] * terms * wpx[0], (t[:, 0] - q[:, 0]) * wpx[0])
    cy = _lstsq(q[:, 1:] * terms * wpx[1], (t[:, 1] - q[:, 1]) * wpx[1])
    coeffs = {}
    for k, (i, j) in enumerate(orders):
        coeffs[f"Cx{i}{j} - Degree {j}"] = float(cx[k])
        coeffs[f"Cy{i}{j} - Degree {j}"] = float(cy[k])
    coeffs.update(pixel_aspect=float(aspect), focal_length_mm=float(fy), r_fb_mm=float(r_fb), degree=degree)
    notes = [f"diagonally normalised by r_fb = {r_fb:.4f} mm, half the diagonal of the desqueezed filmback "
             f"({samples.sensor_mm[0] * aspect:.3f} x {samples.sensor_mm[1]:.3f} mm); lens rotation 0, "
             "Squeeze-X = Squeeze-Y = 1, lens centre offset 0",
             "focal length = the Y pinhole, pixel aspect = f_y / f_x at this focus"]
    fit = TDE4Anamorphic(TDE4_ANAMORPHIC_MODELS[degree], "D-U", coeffs, math.nan, math.nan, allowed,
                         samples.size_px, samples.sensor_mm, samples.focus_from_film_mm, notes)
    return _finish(fit, samples)
