"""Rays as a structure of arrays.

A :class:`RayBatch` holds one float64 array per component: position ``x, y, z`` (mm, lens
space: z = 0 at the first vertex, +z toward the film; docs/conventions.md), direction
cosines ``L, M, N`` (unit vector, L^2 + M^2 + N^2 = 1), ``wavelength_nm``, ``weight``
(radiometric throughput of unpolarised light, 0 for a lost ray), ``weight_sp`` and ``flag``
(uint8, one of :data:`OK`, :data:`MISSED`, :data:`CLIPPED`, :data:`TIR`). A lost ray keeps its
last finite position and direction, never NaN; a ray flagged OK has finite position, direction
and weights (the kernels flag MISSED whatever overflows or divides 0 by 0).

Polarisation (Fresnel): unpolarised light is half s- and half p-polarised, and the two are
transmitted differently at each surface. With A and B the throughputs of the s and p halves
(each starting at the ray's weight), ``weight`` = (A + B) / 2 and ``weight_sp`` = (A - B) / 2,
so through several surfaces T = (prod Ts + prod Tp) / 2, not prod((Ts + Tp) / 2). Both columns
scale together under any polarisation-blind factor (aperture density, cos^4, clipping to 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..optics.glass import require_wavelength

__all__ = ["OK", "MISSED", "CLIPPED", "TIR", "FLAG_NAMES", "RayBatch"]

OK = 0  #: the ray went through every surface
MISSED = 1  #: the ray did not meet a surface (or met it behind itself)
CLIPPED = 2  #: the ray met a surface outside its clear semi-diameter (or the stop)
TIR = 3  #: total internal reflection
FLAG_NAMES = {OK: "ok", MISSED: "missed", CLIPPED: "clipped", TIR: "tir"}


@dataclass
class RayBatch:
    """Rays in lens space, one float64 array per component (see module notes)."""

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    L: np.ndarray
    M: np.ndarray
    N: np.ndarray
    wavelength_nm: np.ndarray
    weight: np.ndarray
    flag: np.ndarray
    #: (s - p) / 2 throughput (module notes). None means all zeros (unpolarised, no Fresnel
    #: surface yet); :meth:`columns` then allocates it with ``np.zeros`` (calloc: pages are mapped
    #: only where the kernels write), so batches traced without Fresnel do not pay for copying it.
    weight_sp: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.x.shape[0])

    @classmethod
    def from_arrays(cls, position, direction, wavelength_nm=587.5618, weight=1.0) -> "RayBatch":
        """Rays from an (n, 3) ``position`` (mm) and an (n, 3) ``direction`` (normalised here).

        Raises :class:`InputError` on NaN/inf, a zero direction or mismatched shapes.
        """
        p = np.atleast_2d(np.asarray(position, dtype=np.float64))
        d = np.atleast_2d(np.asarray(direction, dtype=np.float64))
        if p.ndim != 2 or p.shape[1] != 3:
            raise InputError(f"ray positions must have shape (n, 3), got {p.shape}")
        try:
            p, d = np.broadcast_arrays(p, d)
        except ValueError:
            raise InputError(f"ray directions must have shape {p.shape}, got {d.shape}") from None
        if d.shape != p.shape:
            raise InputError(f"ray directions must have shape {p.shape}, got {d.shape}")
        return cls.from_columns(p[:, 0], p[:, 1], p[:, 2], d[:, 0], d[:, 1], d[:, 2], wavelength_nm, weight)

    @classmethod
    def from_columns(cls, x, y, z, dx, dy, dz, wavelength_nm=587.5618, weight=1.0) -> "RayBatch":
        """:meth:`from_arrays` with the positions (mm) and directions (normalised here) as six 1-D
        arrays of one length, with no (n, 3) array built on the way."""
        cols = [np.asarray(c, dtype=np.float64) for c in (x, y, z, dx, dy, dz)]
        n = cols[0].shape[0] if cols[0].ndim == 1 else -1
        if any(c.shape != (n,) for c in cols):
            raise InputError(f"ray columns must be six 1-D arrays of one length, got shapes {[c.shape for c in cols]}")
        if not all(np.isfinite(c).all() for c in cols):
            raise InputError("ray positions and directions must be finite numbers (found NaN or inf)")
        # normalise without overflow or underflow: scale by the largest component first
        dx, dy, dz = cols[3:]
        big = np.maximum(np.maximum(np.abs(dx), np.abs(dy)), np.abs(dz))
        if (big == 0).any():
            raise InputError("a ray direction is the zero vector; give a non-zero direction")
        dx, dy, dz = dx / big, dy / big, dz / big
        norm = np.sqrt(dx * dx + dy * dy + dz * dz)
        wl_in, w_in = np.asarray(wavelength_nm, dtype=np.float64), np.asarray(weight, dtype=np.float64)
        wl = np.broadcast_to(wl_in, (n,)).copy()
        if n:  # the values, checked before broadcasting
            require_wavelength(float(wl_in) if wl_in.ndim == 0 else wl_in, "ray wavelength")
        w = np.broadcast_to(w_in, (n,)).copy()
        if n and not (np.isfinite(w_in).all() and (w_in >= 0).all()):
            raise InputError("ray weights must be finite and >= 0")
        # own, writable, contiguous columns: a broadcast input (read-only, possibly one element,
        # which ascontiguousarray would pass through as is) must never reach the kernels
        return cls(
            np.array(cols[0], order="C"), np.array(cols[1], order="C"), np.array(cols[2], order="C"),
            dx / norm, dy / norm, dz / norm,
            wl, w, np.zeros(n, dtype=np.uint8),
        )

    @classmethod
    def collimated(cls, x, y, z0: float, direction=(0.0, 0.0, 1.0), wavelength_nm=587.5618) -> "RayBatch":
        """Parallel rays starting at heights ``x, y`` (mm) on the plane z = ``z0``, all along ``direction``."""
        x = np.asarray(x, dtype=np.float64).ravel()
        y = np.asarray(y, dtype=np.float64).ravel()
        p = np.stack([x, y, np.full_like(x, float(z0))], axis=1)
        return cls.from_arrays(p, np.asarray(direction, dtype=np.float64)[None, :], wavelength_nm)

    def _base(self):
        return (self.x, self.y, self.z, self.L, self.M, self.N, self.wavelength_nm, self.weight)

    def copy(self) -> "RayBatch":
        sp = None if self.weight_sp is None else np.array(self.weight_sp, copy=True)
        return RayBatch(np.array(self.x, copy=True), np.array(self.y, copy=True), np.array(self.z, copy=True),
                        np.array(self.L, copy=True), np.array(self.M, copy=True), np.array(self.N, copy=True),
                        np.array(self.wavelength_nm, copy=True), np.array(self.weight, copy=True),
                        np.array(self.flag, copy=True), sp)

    def columns(self):
        """The arrays in the kernels' order: x y z L M N wavelength_nm weight weight_sp flag
        (``weight_sp`` allocated as zeros here if it was None)."""
        if self.weight_sp is None:
            self.weight_sp = np.zeros(self.weight.shape, dtype=self.weight.dtype)
        return self._base() + (self.weight_sp, self.flag)

    @property
    def dtype(self) -> np.dtype:
        """The precision of the float columns: float64, or float32 for rendering-style work."""
        return self.x.dtype

    def astype(self, dtype) -> "RayBatch":
        """The rays with float columns in ``dtype`` (``np.float64`` or ``np.float32``), copied.

        A float32 batch is traced in single precision (about 2x the rays per second; errors
        against double measured in docs/ray-tracing.md): for images and renderer camera rays, not
        for analyses. Flags are kept.
        """
        dt = np.dtype(dtype)
        if dt not in (np.dtype(np.float64), np.dtype(np.float32)):
            raise InputError(f"rays are traced in float64 or float32, not {dt}")
        sp = None if self.weight_sp is None else np.array(self.weight_sp, dtype=dt)
        return RayBatch(*(np.array(a, dtype=dt) for a in self._base()), flag=np.array(self.flag, copy=True),
                        weight_sp=sp)

    def take(self, index) -> "RayBatch":
        """The rays selected by a boolean mask or index array."""
        sp = None if self.weight_sp is None else self.weight_sp[index]
        return RayBatch(*(a[index] for a in self._base()), flag=self.flag[index], weight_sp=sp)

    @property
    def weight_s(self) -> np.ndarray:
        """Throughput of the s-polarised half (A; ``weight`` is the mean of s and p)."""
        return self.weight + self.columns()[8]

    @property
    def weight_p(self) -> np.ndarray:
        """Throughput of the p-polarised half (B)."""
        return self.weight - self.columns()[8]

    def scale_weight(self, factor, where=None) -> None:
        """Multiply both weight columns by a polarisation-blind ``factor`` (at the mask ``where``)."""
        sp = self.columns()[8]
        if where is None:
            self.weight *= factor
            sp *= factor
        else:
            self.weight[where] *= factor
            sp[where] *= factor

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of rays that went through."""
        return self.flag == OK

    def counts(self) -> dict[str, int]:
        """How many rays carry each flag, by name."""
        c = np.bincount(self.flag, minlength=4)
        return {FLAG_NAMES[i]: int(c[i]) for i in range(4)}
