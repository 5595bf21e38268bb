"""Lens diagram: elements, stop, real marginal and chief rays, cardinal points.

Drawn in one meridian (Y by default; X shows an anamorphic's cylinders) in lens
space: z along the axis from the first vertex (+z toward the film), millimetres.
Element outlines come from each surface's sag (physcam.lens.geometry.sag) over its
clear semi-diameter. Rays are traced for real, meridionally, inside this module
(surface intersection by Newton iteration on the sag, Snell's law in vector form,
as in Welford, *Aberrations of Optical Systems*, ch. 4): a marginal fan from an
axial object at the focus distance, and the chief and rim rays of an off-axis field
aimed at the paraxial entrance pupil (the rim rays at the edges of the part of that
pencil every aperture passes: a vignetted field's pencil is narrower). A ray that misses a surface, leaves its
clear aperture or is totally reflected stops where that happens.
Cardinal points (F, F', H, H', entrance and exit pupils) are the Gaussian ones of
:mod:`physcam.optics.paraxial` at the same focus.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ...errors import InputError
from ...lens.geometry import sag
from ...lens.prescription import Prescription, takes_prescription
from ...optics import focusing, paraxial
from ...optics.state import CameraState, takes_camera
from ...figures import styled

__all__ = ["DIAGRAM_FORMATS", "trace_meridional_ray", "LensDiagram", "lens_diagram", "save_lens_diagram"]

DIAGRAM_FORMATS = ("png", "svg", "pdf")


@takes_prescription
def trace_meridional_ray(prescription: Prescription, y0: float, z0: float, dy: float, dz: float, *, axis: str = "y",
                         wavelength_nm=None, film_z: float | None = None):
    """Trace a real ray in the meridian plane; return its polyline [(z, height), ...].

    The ray starts at (z0, y0) with direction (dz, dy) in object space and goes through the
    tracer (:func:`physcam.trace.trace_path`). The polyline ends at the film plane
    (``film_z``), or at the surface whose clear aperture blocks the ray, or where it misses a
    surface or is totally reflected.
    """
    wl = prescription.wavelength_nm if wavelength_nm is None else wavelength_nm
    return _meridional_polylines(prescription, [(y0, z0, dy, dz)], axis, wl, film_z)[0]


def _meridional_polylines(prescription: Prescription, starts, axis: str, wl, film_z):
    """The polylines of :func:`trace_meridional_ray` of the rays ``starts`` [(y0, z0, dy, dz), ...], traced in
    one batch (each ray's fate in the kernel is its own: the same numbers as one ray at a time)."""
    from ...trace import OK, RayBatch, trace_path

    pos = [[0.0, y0, z0] if axis == "y" else [y0, 0.0, z0] for y0, z0, _, _ in starts]
    d = [[0.0, dy, dz] if axis == "y" else [dy, 0.0, dz] for _, _, dy, dz in starts]
    rays = RayBatch.from_arrays(pos, d, wl)
    # unclipped, to draw the ray up to the surface that stops it; a lost ray repeats its last point
    pts, out = trace_path(prescription, rays, end_z=film_z, clip=False)
    return [_polyline(prescription, pts[:, i, 2], pts[:, i, 1] if axis == "y" else pts[:, i, 0], out.flag[i] == OK,
                      film_z) for i in range(len(starts))]


def _polyline(prescription: Prescription, z, h, ok: bool, film_z):
    """One traced ray's polyline: its points up to where it is lost (module notes)."""
    import numpy as np

    poly = [(float(z[0]), float(h[0]))]
    for k, surf in enumerate(prescription.surfaces, start=1):
        if (z[k], h[k]) == (z[k - 1], h[k - 1]) and not ok:
            return poly  # missed or totally reflected here
        poly.append((float(z[k]), float(h[k])))
        if abs(h[k]) > surf.semi_diameter * (1 + 1e-9):
            return poly  # vignetted by this surface's clear aperture
    if film_z is not None and ok and np.isfinite(z[-1]):
        poly.append((float(z[-1]), float(h[-1])))
    return poly


@dataclass
class LensDiagram:
    """What a diagram shows (lens-space z, mm), computed once; :meth:`figure` draws it."""

    prescription: Prescription
    gaussian: paraxial.GaussianData
    axis: str
    field_deg: float
    rays: list[tuple[str, list[tuple[float, float]]]]
    camera: CameraState | None = None  # the camera drawn: its focus and iris

    @property
    def focus_from_film_mm(self) -> float:
        """The camera's focus mark in front of the film (inf at infinity)."""
        return math.inf if self.camera is None else self.camera.focus_from_film_mm

    @property
    def fstop(self) -> float | None:
        """The f-stop the iris is drawn at; None: the stop as in the file."""
        return self.camera.fstop if self.camera is not None and self.camera.iris_set else None

    def to_dict(self) -> dict:
        """The diagram's numbers: the rays drawn, as (z, height) points in lens space (mm), and the film."""
        return {"lens": self.prescription.name, "axis": self.axis, "field_deg": self.field_deg,
                "focus_from_film_mm": None if math.isinf(self.focus_from_film_mm) else self.focus_from_film_mm,
                "fstop": self.fstop, "film_z_mm": self.gaussian.z_film,
                "reference": "lens space: z from the first vertex, + toward the film",
                "rays": [{"kind": kind, "points_mm": [list(q) for q in pts]} for kind, pts in self.rays]}

    @styled
    def figure(self, *, width_in: float = 10.0, units: str = "m", text_pt: float | None = None):
        """A matplotlib Figure (Agg canvas). The view spans the lens and film; an object closer than
        infinity is marked by where its rays enter the view (its distance is in the title, in
        ``units``: m or ft). ``text_pt``: every text that size (a phone's narrow figure: physcam serve),
        else the style's."""
        import matplotlib

        from ...figures import new_figure

        rc = {} if text_pt is None else {k: text_pt for k in ("font.size", "axes.titlesize", "axes.labelsize",
                                                              "xtick.labelsize", "ytick.labelsize")}
        with matplotlib.rc_context(rc):
            fig = new_figure(figsize=(width_in, width_in * (0.45 if text_pt is None else 1.0)))
            ax = fig.add_subplot(1, 1, 1)
            self.draw(ax, units=units, width_in=width_in, label_pt=text_pt or 8.0)
            fig.tight_layout()
        return fig

    @styled
    def draw(self, ax, *, units: str = "m", width_in: float = 10.0, title: bool = True, label_pt: float = 8.0) -> None:
        """Draw the diagram on matplotlib axes ``ax`` (what :meth:`figure` shows; the lens card's
        section); ``width_in`` is the width the title is wrapped to, ``label_pt`` the size of the labels."""
        from ...figures import PALETTE, fit_title, unbroken
        from ...units import format_distance

        p, g, axis = self.prescription, self.gaussian, self.axis
        zv = p.vertex_z
        sds = [s.semi_diameter for s in p.surfaces]
        hmax = max(sds)
        # elements: glass between surface i and i+1
        for i in range(len(p.surfaces) - 1):
            a, b = p.surfaces[i], p.surfaces[i + 1]
            if a.medium.nd == 1.0 and a.medium.vd == 0.0:
                continue
            k = 24
            front = [(zv[i] + sag(a, a.semi_diameter * (2 * j / k - 1), axis), a.semi_diameter * (2 * j / k - 1)) for j in range(k + 1)]
            back = [(zv[i + 1] + sag(b, b.semi_diameter * (1 - 2 * j / k), axis), b.semi_diameter * (1 - 2 * j / k)) for j in range(k + 1)]
            poly = front + back
            ax.fill([q[0] for q in poly], [q[1] for q in poly], facecolor="#cfe3f5", edgecolor=PALETTE[0], linewidth=1.0)
        # the aperture stop
        k = p.stop_index
        r = g.stop_semi_diameter
        for sgn in (1, -1):
            ax.plot([zv[k], zv[k]], [sgn * r, sgn * (r + 0.25 * hmax)], color="black", linewidth=2.5)
        ax.text(zv[k], 1.3 * hmax, "stop", ha="center", fontsize=label_pt)
        # rays
        colours = {"marginal": PALETTE[1], "chief": PALETTE[2], "rim": PALETTE[5]}
        for kind, pts in self.rays:
            ax.plot([q[0] for q in pts], [q[1] for q in pts], color=colours[kind], linewidth=0.9 if kind != "rim" else 0.6)
        # film plane: tall enough for every ray that lands on it (a wide field's chief ray lands beyond the
        # largest element's rim)
        landed = [abs(pts[-1][1]) for _, pts in self.rays if pts and abs(pts[-1][0] - g.z_film) < 1e-6]
        half_film = max([hmax] + landed)
        hmax = max(hmax, half_film / 1.25)  # the view's height below follows
        ax.plot([g.z_film, g.z_film], [-half_film, half_film], color="0.3", linewidth=1.5)
        ax.text(g.z_film, -1.3 * hmax, "film", ha="center", fontsize=label_pt)
        # cardinal points on the axis
        ax.axhline(0.0, color="0.5", linewidth=0.5, linestyle="-.")
        marks = [("F", g.z_front_focal_point), ("F'", g.z_rear_focal_point), ("H", g.z_front_principal_plane),
                 ("H'", g.z_rear_principal_plane)]
        for label, zp in marks:
            ax.plot([zp], [0.0], marker="o", color=PALETTE[4], markersize=4)
            ax.annotate(label, (zp, 0.0), textcoords="offset points", xytext=(0, 6 if "H" in label else -12),
                        ha="center", fontsize=label_pt, color=PALETTE[4])
        for label, zp, d in (("EP", g.z_entrance_pupil, g.entrance_pupil_diameter), ("XP", g.z_exit_pupil, g.exit_pupil_diameter)):
            ax.plot([zp, zp], [-d / 2, d / 2], color=PALETTE[3], linewidth=1.2, linestyle="--")
            ax.annotate(label, (zp, d / 2), textcoords="offset points", xytext=(0, 3), ha="center", fontsize=label_pt, color=PALETTE[3])
        # the view: the lens and film (rays from a near object enter from the left); points outside are
        # listed below the plot
        z_view = -max(0.3 * p.total_track, 10.0)
        z_lo = max(min(min(q[0] for _, pts in self.rays for q in pts), -0.05 * g.z_film), z_view)
        z_hi = 1.08 * g.z_film if g.z_film > 0 else p.total_track + 10.0
        ax.set_xlim(z_lo, z_hi)
        ax.set_ylim(-1.6 * hmax, 1.6 * hmax)
        outside = [f"{lbl} at z = {zp:.1f} mm" for lbl, zp in marks + [("EP", g.z_entrance_pupil), ("XP", g.z_exit_pupil)]
                   if not z_lo <= zp <= z_hi]
        if math.isfinite(g.z_object) and g.z_object < z_lo:
            outside.insert(0, f"object at z = {g.z_object:.0f} mm")
        if outside:
            note = "outside the view: " + ", ".join(outside)
            if label_pt == 8.0:
                ax.text(0.01, 0.02, note, transform=ax.transAxes, fontsize=7, color="0.3")
            else:  # a phone's figure: below the plot, wrapped to the figure's width
                from ...figures import fit_title

                ax.set_title(fit_title(note, 0.8 * width_in, fontsize=label_pt - 1), fontsize=label_pt - 1,
                             color="0.3", loc="left", y=-0.62 if title else -0.45)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("z from the first vertex (mm, + toward the film)" if label_pt == 8.0 else "z (mm, toward the film)")
        ax.set_ylabel(f"{axis} (mm)")
        fnum = g.f_number if self.fstop is None else self.fstop
        if title:
            ax.set_title(fit_title(
                f"{p.name}: {unbroken(f'EFL {g.efl:.2f} mm')}, f/{fnum:.3g}, "
                f"{unbroken('focus ' + format_distance(self.focus_from_film_mm, units))}, "
                f"{unbroken(f'half-field {self.field_deg:.1f}°')} ({axis.upper()} meridian)",
                width_in if label_pt == 8.0 else 0.8 * width_in, fontsize=None if label_pt == 8.0 else label_pt))


def _default_field(p: Prescription, g: paraxial.GaussianData, axis: str, wavelength_nm) -> float:
    """Half-field (rad) of the widest paraxially unvignetted pencil (Smith 7.2), 90% of it.

    At every surface the chief-ray height plus the marginal-ray height must fit
    inside the clear semi-diameter; falls back to 70% of the chief-ray limit when
    even the axial pencil fills a surface.
    """
    n = paraxial.media_indices(p, wavelength_nm)
    zep, a = g.z_entrance_pupil, g.entrance_pupil_diameter / 2
    # chief ray with unit slope through the EP centre (height -zep at the first vertex)
    yc, _ = paraxial.paraxial_trace(p, -zep, n[0], axis, wavelength_nm)
    if math.isinf(g.z_object):
        ym, _ = paraxial.paraxial_trace(p, a, 0.0, axis, wavelength_nm)
    else:
        u = a / (zep - g.z_object)
        ym, _ = paraxial.paraxial_trace(p, -u * g.z_object, n[0] * u, axis, wavelength_nm)
    free = [(s.semi_diameter - abs(m)) / abs(c) for s, c, m in zip(p.surfaces, yc, ym) if abs(c) > 1e-12 and not s.is_stop]
    chief = [s.semi_diameter / abs(c) for s, c in zip(p.surfaces, yc) if abs(c) > 1e-12 and not s.is_stop]
    if not chief:
        return math.atan(0.3)
    u = 0.9 * min(free) if min(free) > 0 else 0.7 * min(chief)
    return math.atan(min(u, 1.5))


def _pencil_edges(p: Prescription, ray, a: float, axis: str, wavelength_nm) -> tuple[float, ...]:
    """The rim of a pencil: the lowest and highest pupil heights ``h`` in [-0.98 a, 0.98 a] whose ray
    ``ray(h) -> (y0, z0, dy, dz)`` passes every clear aperture and the stop (a vignetted pencil is
    narrower than the paraxial pupil; real pupil aberration moves its edge). The pupil is sampled and
    the run of passing rays nearest h = 0 refined to 1e-4 a by bisection, the midpoints of both ends' steps
    in one batch (each ray's fate is its own: the same steps as one at a time); () when none passes."""
    import numpy as np

    from ...trace import OK, RayBatch, trace_through
    from .._chief import bisect_together

    def passes(hs):
        y0, z0, dy, dz = (np.broadcast_to(np.asarray(v, dtype=float), np.shape(hs)) for v in ray(np.asarray(hs)))
        zero = np.zeros(np.shape(hs))
        pos = np.stack([zero, y0, z0] if axis == "y" else [y0, zero, z0], axis=1)
        d = np.stack([zero, dy, dz] if axis == "y" else [dy, zero, dz], axis=1)
        # whether it passes, not its path: every surface in one call of the kernel
        out = trace_through(p, RayBatch.from_arrays(pos, d, wavelength_nm), clip=True, backend="numpy")
        return out.flag == OK

    hs = np.linspace(-0.98 * a, 0.98 * a, 49)
    ok = passes(hs)
    if not ok.any():
        return ()
    lo = hi = int(np.flatnonzero(ok)[np.argmin(np.abs(hs[ok]))])  # the passing sample nearest h = 0
    while lo > 0 and ok[lo - 1]:
        lo -= 1
    while hi < len(hs) - 1 and ok[hi + 1]:
        hi += 1
    ends = [[hs[k], hs[k + step] if 0 <= k + step < len(hs) else None] for k, step in ((lo, -1), (hi, 1))]
    bisect_together(passes, [e for e in ends if e[1] is not None], 1e-4 * a)  # a batch for many steps
    return tuple(float(e[0]) for e in ends)


@takes_camera
def lens_diagram(camera: CameraState, *, axis: str = "y", field_deg: float | None = None, wavelength_nm=None,
                 rays: int = 3) -> LensDiagram:
    """Compute a :class:`LensDiagram` of a :class:`~physcam.optics.state.CameraState` (the lens focused at
    its mark, its iris at its f-stop or as in its file), focused at ``wavelength_nm`` (None: the camera's
    primary wavelength)."""
    if axis not in paraxial.AXES:
        raise InputError(f"meridian must be 'x' or 'y', got {axis!r}")
    cam = camera
    prescription, focus_mm = cam.lens, cam.focus_from_film_mm
    fstop = cam.fstop if cam.iris_set else None
    if wavelength_nm is None:  # the state's primary wavelength (a lens's: its design wavelength)
        wavelength_nm = cam.wavelengths_nm[0]
    st = focusing.focus(prescription, focus_mm, axis="y", wavelength_nm=wavelength_nm)
    p = st.prescription
    iris = cam.stop_semi_diameter if cam.iris_set else None
    g = paraxial.gaussian(p, axis=axis, wavelength_nm=wavelength_nm, stop_semi_diameter=iris, object_z=st.object_z,
                          film_z=st.film_z)
    if fstop is not None:  # draw the stop at the asked opening
        from dataclasses import replace

        k = p.stop_index
        s = list(p.surfaces)
        s[k] = replace(s[k], semi_diameter=g.stop_semi_diameter)
        p = p.with_surfaces(s)
    if field_deg is None:
        half = _default_field(p, g, axis, wavelength_nm)
    else:
        half = math.radians(float(field_deg))
        if not (0 <= half < math.pi / 2):
            raise InputError(f"field angle must be between 0 and 90 degrees, got {field_deg}")
    track = p.total_track
    z_start = -max(0.3 * track, 10.0)
    if math.isfinite(st.object_z):
        z_start = max(z_start, st.object_z)
    ep, a = g.z_entrance_pupil, g.entrance_pupil_diameter / 2
    if math.isinf(st.object_z):  # the axial pencil: parallel rays at pupil height h, or a fan from the object
        def marginal(h):
            return h, z_start, 0.0, 1.0
    else:
        def marginal(h):
            return 0.0, st.object_z, h, ep - st.object_z
    lo_hi = _pencil_edges(p, marginal, a, axis, wavelength_nm) or (-a, a)
    fan = [lo_hi[0] + (lo_hi[1] - lo_hi[0]) * j / (rays - 1) for j in range(rays)] if rays > 1 else [lo_hi[1]]
    # the marginal fan from the axial object, its outer rays at the pencil's rim
    drawn = [("marginal", marginal(h)) for h in fan]
    tu = math.tan(half)

    def field(h):
        return h - tu * (ep - z_start), z_start, tu, 1.0

    rims = _pencil_edges(p, field, a, axis, wavelength_nm)  # the rim of what passes of the off-axis pencil
    drawn += [(kind, field(h)) for h, kind in ((0.0, "chief"),) + tuple((h, "rim") for h in rims[::-1])]  # at the EP
    lines = _meridional_polylines(p, [start for _, start in drawn], axis, wavelength_nm, g.z_film)
    out = [(kind, line) for (kind, _), line in zip(drawn, lines)]
    return LensDiagram(p, g, axis, math.degrees(half), out, cam)


@takes_camera
@styled
def save_lens_diagram(camera: CameraState, path, *, force: bool = False, **kwargs) -> Path:
    """Draw the diagram to ``path`` (.png, .svg or .pdf) through atomic_write; kwargs as :func:`lens_diagram`,
    and ``units`` (m or ft) for the focus in the title."""
    from ...figures import figure_format, save_figure
    from ...io import check_writable

    p = Path(path)
    figure_format(p)  # before the work of drawing, as the output's place
    check_writable(p, force=force)
    units = kwargs.pop("units", "m")
    return save_figure(lens_diagram(camera, **kwargs).figure(units=units), p, force=force, dpi=150)
