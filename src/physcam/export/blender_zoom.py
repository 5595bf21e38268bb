"""A zoom lens's tables for the Blender extension's shader: zoom x focus (docs/blender.md, "Zoom").

The shader of a zoom lens takes the zoom as a focal length (``zoom_focal_length``, mm: the paraxial
EFL at infinity focus, as ``physcam --zoom 135mm`` names a position, :mod:`physcam.optics.zoom`) and
finds the encoder u from :data:`N_ZOOM_EFL` EFLs uniform in u (linear between them: within 0.07 % of
the library's bisection on the bundled zooms). The lens's state is tabulated on two grids sharing
one focus axis (:data:`N_FOCUS_ZOOM` marks of a :class:`~physcam.export.blender_focus.FocusAxis`,
infinity to the closest focus every zoom position reaches):

- the geometry (film plane, vertices) at :data:`N_ZOOM_GEOMETRY` positions uniform in u: each is
  :func:`physcam.lens.zoom.prescription_at` (the gaps on their pchip cams) focused by
  :func:`physcam.optics.focusing.focus`; the shader blends them linearly in u and, along focus, as
  :func:`~physcam.export.blender_focus.blend_weights` says (cubic in the axis's index).
  Linear in u between 33 nodes follows the pchip cams within 0.02 mm on the bundled zooms (0.85 mm
  between the tabulated positions and their midpoints alone). The entrance pupil (the camera's
  origin) and the iris rule's K and f-numbers come from :data:`N_ZOOM_ROWS` of those positions
  (the report's rows, which the panel reads too), linear in u between them;
- the pupil sampling tables (:mod:`physcam.export.blender_pupil`, the costly part) and the centre's
  normalisation only at the source's tabulated positions, blended linearly in u (the ellipses grown
  by their centres' and axes' spread between the two positions: a sampling region, not the image).

The iris levels are common to every position (the widest iris and the file's stop of the position
that opens most), so one level index means one iris radius at every position.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..errors import InputError
from ..lens.prescription import Prescription, takes_prescription
from .blender_focus import FocusAxis

__all__ = ["ZoomGrid", "zoom_focus_table", "zoom_focus_axis", "rows_to_geometry", "N_FOCUS_ZOOM", "N_ZOOM_GEOMETRY",
           "N_ZOOM_ROWS", "N_ZOOM_EFL", "ZOOM_PUPIL_STRIDE"]

#: Focus marks of a zoom lens's tables (fewer than a prime's 32: the pupil tables are per position).
N_FOCUS_ZOOM = 12
#: Zoom positions of the geometry, uniform in the encoder u.
N_ZOOM_GEOMETRY = 33
#: Zoom positions (uniform in u, every other geometry position) of the report rows (the panel's numbers
#: and the entrance pupil, the camera's origin) and of the iris rule: slowly varying, and the costly
#: part of the geometry (paraxial solves in Python); linear in u to the geometry's positions.
N_ZOOM_ROWS = 17
#: EFL samples, uniform in u, from which the shader finds u for a focal length.
N_ZOOM_EFL = 65
#: Every ZOOM_PUPIL_STRIDE-th focus mark (and the last) of a tabulated position has its pupil tables traced,
#: the marks between interpolated (:func:`physcam.export.blender_focus.fill_pupil_tables`): the 12 marks are
#: twice as far apart in s as a prime's 32, so every other one.
ZOOM_PUPIL_STRIDE = 2


@dataclasses.dataclass
class ZoomGrid:
    """The zoom axis of a zoom lens's focus table (module notes)."""

    geometry_u: np.ndarray  # (N_ZOOM_GEOMETRY,) encoder of each geometry row block
    pupil_u: np.ndarray  # (n,) the tabulated positions: encoder of each pupil-table block
    efl_u_mm: np.ndarray  # (N_ZOOM_EFL,) paraxial EFL at infinity focus, u uniform 0..1
    iris_k: np.ndarray  # (N_ZOOM_GEOMETRY,) iris semi-diameter x f-number at each geometry position
    fstop_open: np.ndarray  # (N_ZOOM_GEOMETRY,) the lens wide open there
    fstop_min: np.ndarray  # (N_ZOOM_GEOMETRY,) the fastest f-stop physcam's camera state opens to there
    levels: np.ndarray  # the common iris radii (mm) of the pupil and normalisation tables

    @property
    def range_mm(self) -> tuple[float, float]:
        return float(self.efl_u_mm.min()), float(self.efl_u_mm.max())


def _iris_rule(q: Prescription) -> tuple[float, float, float]:
    """(K, widest f-number, fastest accepted f-number) of a plain prescription: blender_focus's rule."""
    from ..optics.focusing import gaussian_at_focus
    from ..optics.paraxial import STOP_OPENING_TOLERANCE
    from ..optics.state import camera_state

    n_open = gaussian_at_focus(q, math.inf).f_number * (1 + 1e-9)
    k = camera_state(q, fstop=n_open).stop_semi_diameter * n_open
    return float(k), float(n_open), float(n_open / (1 + STOP_OPENING_TOLERANCE))


@takes_prescription
def zoom_focus_table(lens: Prescription, *, n_focus: int = N_FOCUS_ZOOM, n_geometry: int = N_ZOOM_GEOMETRY,
                     pupil_stride: int = ZOOM_PUPIL_STRIDE, positions: dict | None = None):
    """The :class:`~physcam.export.blender_focus.FocusTable` of a zoom lens over zoom x focus (module
    notes): ``film_z`` and ``vertex_z`` hold ``n_geometry`` blocks of ``n_focus`` states (u major),
    ``radial`` and ``norm`` one block per tabulated position (traced at every ``pupil_stride``-th mark and the
    last, :func:`~physcam.export.blender_focus.fill_pupil_tables` between); ``zoom`` the :class:`ZoomGrid`. Its
    ``fstop_open``/``fstop_min`` are the slowest over the zoom (an f-stop every position reaches) and
    ``closest_mm`` the farthest closest focus (a mark every position focuses to). ``positions``: a dict that
    receives the plain prescription at each geometry position, by its encoder; each keeps its marks' focus
    states (:func:`~physcam.export.blender_focus.focus_geometry`), so the caller's camera states of it at
    those marks solve no focus again."""
    from ..lens.zoom import prescription_at, tabulated_encoders
    from ..optics.focusing import focus
    from ..optics.zoom import efl_at
    from ..trace.camera_tracer import CameraTracer
    from .blender_focus import FocusTable, _centre_bounds, _state_norms, fill_pupil_tables, focus_geometry, pupil_marks
    from .blender_pupil import iris_levels, radial_pupil_table, _tables_backend

    if lens.zoom is None:
        raise InputError(f"{lens.name!r} is not a zoom lens: use blender_focus.focus_table")
    if lens.is_anamorphic:
        raise InputError(f"{lens.name!r} is an anamorphic zoom: the extension's zoom control takes lenses with "
                         "rotational symmetry")
    geo_u = np.linspace(0.0, 1.0, n_geometry)
    pupil_u = np.array(tabulated_encoders(lens), dtype=float)
    geo_q = [prescription_at(lens, float(u)) for u in geo_u]
    if positions is not None:
        positions.update(zip(geo_u.tolist(), geo_q))
    axis = zoom_focus_axis(geo_q, n_focus)
    marks = axis.marks_mm
    rows_u = np.linspace(0.0, 1.0, N_ZOOM_ROWS)
    rule_rows = np.array([_iris_rule(prescription_at(lens, float(u))) for u in rows_u])  # K, n_open, n_min
    rule = np.stack([np.interp(geo_u, rows_u, rule_rows[:, c]) for c in range(3)], axis=1)
    pupil_q = [prescription_at(lens, float(u)) for u in pupil_u]
    pupil_rule = np.array([_iris_rule(q) for q in pupil_q])
    both = np.concatenate([rule_rows, pupil_rule])
    levels = iris_levels(float(np.max(both[:, 0] / both[:, 2])), float(np.max(both[:, 0] / both[:, 1])))
    geometry = [focus_geometry(q, axis) for q in geo_q]
    film_z, slope, vz = (np.concatenate([g[i] for g in geometry]) for i in range(3))
    traced = pupil_marks(n_focus, pupil_stride)
    radial, norm = [], []
    backend = _tables_backend("auto", len(pupil_q) * len(traced), len(lens.surfaces))  # once, for every table
    for q in pupil_q:
        block, block_norm = [], []
        for mk in marks[traced]:
            st = focus(q, float(mk))
            tracer = CameraTracer(st.prescription, st.film_z)  # the lens at this zoom and focus as the file stops it
            block.append(radial_pupil_table(tracer.lens, st.film_z, levels, backend=backend))
            block_norm.append(_state_norms(tracer, block[-1], levels, backend))
        if not all(min(v) > 0 for v in block_norm):
            from ..errors import OpticsError

            raise OpticsError(f"no ray from the film centre passes through {lens.name!r} at some zoom and focus")
        block, _, _, block_norm = fill_pupil_tables(traced, n_focus, radial=block, norm=block_norm)
        radial.extend(block)
        norm.extend(block_norm)
    st0 = focus(geo_q[0], math.inf)
    tracer0 = CameraTracer(st0.prescription, st0.film_z)
    b = _centre_bounds(tracer0.lens, radial[0][0, 0])
    loss = tracer0.centre_weight(b, samples=64, fresnel=True) / tracer0.centre_weight(b, samples=64)
    grid = ZoomGrid(geo_u, pupil_u, np.array([efl_at(lens, float(u)) for u in np.linspace(0.0, 1.0, N_ZOOM_EFL)]),
                    rule[:, 0], rule[:, 1], rule[:, 2], levels)
    table0 = tracer0.film_side_table
    n_open, n_min = float(rule_rows[:, 1].max()), float(rule_rows[:, 2].max())
    return FocusTable(lens, axis, film_z, slope, vz, np.array(radial), None, None, np.array(norm),
                      table0, None, float(rule[0, 0]), n_open, n_min, axis.near_mm, float(loss), zoom=grid)


def zoom_focus_axis(geometry_prescriptions: list[Prescription], n_focus: int = N_FOCUS_ZOOM) -> FocusAxis:
    """The focus axis (:class:`~physcam.export.blender_focus.FocusAxis`) a zoom lens's tables share: down to
    the farthest closest focus of the plain prescriptions at the geometry's zoom positions."""
    from ..optics.focusing import closest_focus
    from .blender_focus import focus_axis

    return focus_axis(max(closest_focus(q) for q in geometry_prescriptions), n_focus)


def rows_to_geometry(values, n_focus: int) -> np.ndarray:
    """Per-row values (:data:`N_ZOOM_ROWS` zoom positions x ``n_focus``, u major) at the geometry's
    :data:`N_ZOOM_GEOMETRY` positions: linear in u, per focus mark."""
    a = np.asarray(values, dtype=float).reshape(N_ZOOM_ROWS, n_focus)
    rows_u, geo_u = np.linspace(0.0, 1.0, N_ZOOM_ROWS), np.linspace(0.0, 1.0, N_ZOOM_GEOMETRY)
    return np.stack([np.interp(geo_u, rows_u, a[:, k]) for k in range(n_focus)], axis=1).ravel()
