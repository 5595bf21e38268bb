"""Aperture shape and shutter opening curve (RenderMan 13 "Advanced Camera Lens Modeling", seed 002).

Aperture ``(nsides, angle_deg, roundness, density)``:

- ``nsides < 3``: a circle. Otherwise a regular polygon with a vertex at ``angle_deg`` from +x.
- ``roundness`` in [-1, 1]: the rim radius at polar angle phi (unit circumradius) is
  r(phi) = p(phi) + roundness (1 - p(phi)), with p(phi) = cos(pi/n) / cos(((phi - angle) mod 2pi/n) - pi/n)
  the straight-sided polygon: 0 straight sides, 1 a circle, between the sides bow out, negative
  values bow them in (vertices stay on the unit circle). This blend is physcam's reading of the
  seed's prose, which gives no formula.
- ``density`` in [-1, 1]: brightness rises linearly with the relative radius s = r / r_rim(phi),
  f(s) = 1 + density (2 s - 1): 0 flat, negative brighter at the centre, positive at the rim.

Samples are importance-sampled (pdf proportional to f over the shape's area): phi from the
tabulated marginal pdf proportional to r_rim(phi)^2, then s from pdf proportional to s f(s) by
inverting its cubic CDF, so every sample carries the same weight.

Shutter ``(opentime, closetime)`` as fractions of the shutter interval: the opening rises
linearly from 0 at t = 0 to 1 at opentime, stays 1 until closetime, falls to 0 at t = 1.
Effective exposure fraction = its integral = (1 + closetime - opentime) / 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, require_finite

__all__ = ["Aperture", "Shutter"]

_TABLE = 4096


@dataclass(frozen=True)
class Aperture:
    """Aperture shape on the unit disk (scale by the stop or thin-lens radius in mm)."""

    nsides: int = 0
    angle_deg: float = 0.0
    roundness: float = 0.0
    density: float = 0.0

    def __post_init__(self):
        require_finite("aperture angle", self.angle_deg)
        for name in ("roundness", "density"):
            v = require_finite(f"aperture {name}", getattr(self, name))
            if not -1.0 <= v <= 1.0:
                raise InputError(f"aperture {name} must lie in -1..1, got {v:g}")
        if int(self.nsides) != self.nsides:
            raise InputError(f"aperture nsides must be an integer, got {self.nsides}")

    @property
    def is_circular(self) -> bool:
        return self.nsides < 3

    def rim_radius(self, phi) -> np.ndarray:
        """Rim radius (unit circumradius) at polar angle ``phi`` (radians)."""
        phi = np.asarray(phi, dtype=float)
        if self.is_circular:
            return np.ones_like(phi)
        wedge = 2 * math.pi / self.nsides
        u = np.mod(phi - math.radians(self.angle_deg), wedge) - wedge / 2
        p = math.cos(wedge / 2) / np.cos(u)
        return p + self.roundness * (1.0 - p)

    def density_at(self, x, y) -> np.ndarray:
        """Relative brightness f(s) at unit-disk point (x, y); 0 outside the shape."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        s = np.hypot(x, y) / self.rim_radius(np.arctan2(y, x))
        return np.where(s <= 1.0, 1.0 + self.density * (2.0 * s - 1.0), 0.0)

    def area(self) -> float:
        """Area of the shape on the unit disk (1/2 integral of r_rim^2 dphi)."""
        phi = (np.arange(_TABLE) + 0.5) * 2 * math.pi / _TABLE
        return float(0.5 * (self.rim_radius(phi) ** 2).sum() * 2 * math.pi / _TABLE)

    def equal_area_scale(self) -> float:
        """sqrt(pi / :meth:`area`): how far out the corners go (in the round iris's radii) when the shape
        has the round iris's area, physcam's meaning of an f-number with blades (docs/conventions.md);
        1 for a circle."""
        return 1.0 if self.is_circular else math.sqrt(math.pi / self.area())

    def corner_semi(self, round_semi: float, widest_semi: float) -> float:
        """The stop radius (mm) the shape's corners reach when it has the area of the round iris of radius
        ``round_semi`` (an f-number with blades, docs/conventions.md): ``round_semi`` x
        :meth:`equal_area_scale`, but never beyond ``widest_semi`` (the lens's widest iris) unless the
        round iris itself is wider. ``round_semi`` for a circle."""
        if self.is_circular:
            return float(round_semi)
        return float(min(round_semi * self.equal_area_scale(), max(widest_semi, round_semi)))

    def sample(self, u) -> np.ndarray:
        """Map (n, 2) uniform numbers in [0, 1) to (n, 2) points on the shape, pdf prop. to density."""
        u = np.atleast_2d(np.asarray(u, dtype=float))
        if u.shape[-1] != 2 or not np.isfinite(u).all():
            raise InputError("aperture samples must be finite numbers of shape (n, 2)")
        u = np.clip(u, 0.0, 1.0)
        # polar angle from the marginal pdf prop. to r_rim(phi)^2 (exact for a circle)
        if self.is_circular:
            phi = 2 * math.pi * u[:, 0]
            rim = np.ones_like(phi)
        else:
            edges = np.linspace(0.0, 2 * math.pi, _TABLE + 1)
            mids = 0.5 * (edges[1:] + edges[:-1])
            cdf = np.concatenate([[0.0], np.cumsum(self.rim_radius(mids) ** 2)])
            cdf /= cdf[-1]
            phi = np.interp(u[:, 0], cdf, edges)
            rim = self.rim_radius(phi)
        # relative radius from pdf prop. to s (1 - d + 2 d s) on [0, 1]: CDF = ((1-d) s^2/2 + 2 d s^3/3) / norm
        d = self.density
        if d == 0.0:
            s = np.sqrt(u[:, 1])
        else:
            norm = (1 - d) / 2 + 2 * d / 3
            target = u[:, 1] * norm
            s = np.sqrt(u[:, 1])  # start: the flat solution; Newton on a monotone cubic
            for _ in range(30):
                g = (1 - d) * s * s / 2 + 2 * d * s**3 / 3 - target
                gp = (1 - d) * s + 2 * d * s * s
                s = np.clip(s - np.where(gp > 0, g / np.where(gp > 0, gp, 1.0), 0.0), 0.0, 1.0)
        r = s * rim
        return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=1)


@dataclass(frozen=True)
class Shutter:
    """Shutter opening curve: fully open between ``opentime`` and ``closetime`` (fractions of the interval)."""

    opentime: float = 0.0
    closetime: float = 1.0

    def __post_init__(self):
        o = require_finite("shutter opentime", self.opentime)
        c = require_finite("shutter closetime", self.closetime)
        if not 0.0 <= o <= c <= 1.0:
            raise InputError(f"shutter opening needs 0 <= opentime <= closetime <= 1, got {o:g}, {c:g}")

    def opening(self, t) -> np.ndarray:
        """Open fraction of the aperture at time ``t`` in [0, 1]."""
        t = np.asarray(t, dtype=float)
        o, c = self.opentime, self.closetime
        rise = np.where(o > 0, t / (o if o > 0 else 1.0), 1.0)
        fall = np.where(c < 1, (1.0 - t) / ((1.0 - c) if c < 1 else 1.0), 1.0)
        return np.clip(np.minimum(np.minimum(rise, fall), 1.0), 0.0, 1.0) * ((t >= 0) & (t <= 1))

    @property
    def exposure_fraction(self) -> float:
        """Integral of the opening over the interval: (1 + closetime - opentime) / 2."""
        return 0.5 * (1.0 + self.closetime - self.opentime)

    def sample_times(self, u) -> np.ndarray:
        """Times in [0, 1] with pdf = opening(t) / exposure_fraction (inverse CDF of the trapezoid)."""
        u = np.asarray(u, dtype=float)
        o, c = self.opentime, self.closetime
        e = self.exposure_fraction
        a = u * e  # area to reach
        a1 = o / 2  # area of the rise
        a2 = a1 + (c - o)  # plus the plateau
        t_rise = np.sqrt(2 * a * o) if o > 0 else np.zeros_like(a)
        t_flat = o + (a - a1)
        rem = np.maximum(e - a, 0.0)  # area left under the fall: (1 - t)^2 / (2 (1 - c))
        t_fall = 1.0 - np.sqrt(2 * rem * (1 - c))
        return np.where(a < a1, t_rise, np.where(a <= a2, t_flat, t_fall))
