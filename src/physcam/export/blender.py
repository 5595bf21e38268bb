"""A real-lens camera for Blender Cycles: one self-contained OSL camera shader per lens and focus.

:func:`osl_camera_shader` writes the OSL source of a Cycles custom camera (``camera.data.type =
"CUSTOM"``) that traces every camera ray from the film through the lens as physcam's tracer does
(:func:`physcam.trace.camera_rays`): the focused prescription (physcam's focus solution), the
surface rows of :func:`physcam.trace.surfaces.surface_table` baked as arrays sized to the lens,
the same intersections (quadric root nearest the vertex, even asphere by Newton iteration), clipping
at semi-diameters and at the stop with the aperture shape, Snell refraction, TIR, optional
per-sample wavelength with the exact index formula of :func:`physcam.optics.glass.evaluate`, and
optional unpolarised Fresnel transmission (s and p carried separately). Rays are aimed at the exit
pupil through a table of physcam's :func:`~physcam.trace.pupil_bounds.exit_pupil_bounds`, and each
carries physcam's weight cos^4(theta) A / d^2 divided by its mean at the image centre (a uniform
white scene renders 1 at the centre; the falloff elsewhere is physcam's relative illumination).

Conventions (verified by rendering, ``tests/blender/test_blender_camera.py``, docs/blender.md):

- Cycles' OSL camera space: +X right, +Y up, **+Z toward the scene** (Blender's camera object
  looks down its local -Z; the OSL frame is that frame with Z negated), lengths in scene units
  (metres at the default unit scale). physcam's lens space is x right, y up, +z toward the film,
  mm, so a lens-space point (x, y, z) becomes (x, y, film_z - z) / 1000 and a direction
  (L, M, N) becomes (L, M, -N). The camera object's origin is the film centre.
- ``camera_shader_raster_position()`` is (0, 0) at the bottom-left of the rendered image and
  (1, 1) at the top-right. The lens inverts the image, so raster (u, v) reads the film at
  (-(2u - 1) w/2, -(2v - 1) h/2): the rendered picture is upright, as on a camera's monitor.
- The render is the film image: an anamorphic's picture comes out squeezed (desqueeze in comp).

OSL works in 32-bit floats: the even-asphere Newton iteration stops at a step below
1e-5 (1 + |t|) mm instead of the float64 tracer's 1e-12 mm.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np

from ..errors import InputError, require_positive
from ..lens.prescription import Prescription, takes_prescription

__all__ = ["BakedCamera", "bake_camera", "osl_camera_shader", "blender_setup_script", "write_blender_camera",
           "PUPIL_GRID", "WAVELENGTH_RANGE_NM"]

#: Film grid of the baked exit-pupil table (nodes per axis).
PUPIL_GRID = (9, 9)
#: Wavelengths sampled per ray when dispersion is on (uniform; see :func:`osl_camera_shader`).
WAVELENGTH_RANGE_NM = (400.0, 700.0)


@dataclasses.dataclass
class BakedCamera:
    """What the shader bakes in: the focused, stopped-down prescription and everything derived."""

    lens: Prescription  # focused, with the stop at its working semi-diameter
    film_z: float  # mm, lens space
    table: object  # SurfaceTable, film side first (tracing order)
    bounds: object  # PupilBounds on the rear vertex plane
    aperture: object  # Aperture or None
    norm: float  # mean camera_rays weight at the film centre
    sensor_width_mm: float
    sensor_height_mm: float
    focus_mm: float
    fstop: float | None
    wavelength_nm: float


def _aperture(aperture):
    from ..trace.aperture import Aperture

    if aperture is None or isinstance(aperture, Aperture):
        return aperture
    if isinstance(aperture, dict):
        try:
            return Aperture(**aperture)
        except TypeError as e:
            raise InputError(f"aperture keys are nsides, angle_deg, roundness, density ({e})") from None
    if isinstance(aperture, (tuple, list)) and 1 <= len(aperture) <= 4:
        return Aperture(*aperture)
    if isinstance(aperture, (int, np.integer)) and not isinstance(aperture, bool):
        return Aperture(int(aperture))
    raise InputError("aperture must be a physcam.trace.aperture.Aperture, a number of blades, "
                     "a tuple (blades, angle_deg, roundness, density) or a dict of those")


@takes_prescription
def bake_camera(lens: Prescription, *, focus_mm, fstop=None, sensor_width_mm, sensor_height_mm, aperture=None,
                fresnel: bool = False) -> BakedCamera:
    """Focus ``lens`` on a subject ``focus_mm`` in front of the film (:func:`physcam.optics.focusing.focus`:
    internal focusing when the lens has focus groups, else unit focusing), stop it to ``fstop``,
    and tabulate what the OSL camera needs. Raises :class:`~physcam.errors.OpticsError` for a
    focus closer than the lens reaches or an f-number faster than it opens."""
    from ..optics.focusing import focus, iris_semi_diameter
    from ..trace.pupil_bounds import exit_pupil_bounds
    from ..trace.surfaces import surface_table
    from ..trace.trace import camera_rays

    sw = require_positive("sensor width", sensor_width_mm)
    sh = require_positive("sensor height", sensor_height_mm)
    if sw > 1000 or sh > 1000:
        raise InputError(f"a {sw:g} x {sh:g} mm sensor is not a camera sensor (at most 1000 mm a side)")
    if isinstance(focus_mm, bool) or not isinstance(focus_mm, (int, float, np.floating, np.integer)):
        raise InputError(f"focus distance must be a number of mm, got {focus_mm!r}")
    f = float(focus_mm)
    if not (f > 0):
        raise InputError(f"focus distance must be > 0 mm, got {f:g}")
    ap = _aperture(aperture)
    state = focus(lens, f)
    q = state.prescription
    if fstop is not None:
        semi = iris_semi_diameter(lens, fstop)
        k = q.stop_index
        s = list(q.surfaces)
        s[k] = dataclasses.replace(s[k], semi_diameter=float(semi))
        q = q.with_surfaces(s)
    film_z = float(state.film_z)
    table = surface_table(q, reverse=True, coating="none")
    nx, ny = PUPIL_GRID
    bounds = exit_pupil_bounds(q, sw / 2, sh / 2, film_z, nx=nx, ny=ny, samples=64)
    # mean weight at the film centre over a stratified pupil grid (the shader divides by it)
    m = 128
    u = (np.arange(m) + 0.5) / m
    uu, vv = [a.ravel() for a in np.meshgrid(u, u)]
    cr = camera_rays(q, np.zeros((uu.size, 2)), np.stack([uu, vv], axis=1), film_z, bounds=bounds, aperture=ap,
                     fresnel=fresnel)
    norm = float(np.mean(cr.weight))
    if not norm > 0:
        from ..errors import OpticsError

        raise OpticsError(f"no ray from the film centre passes through {lens.name!r} at this focus and stop")
    return BakedCamera(q, film_z, table, bounds, ap, norm, sw, sh, f, fstop, float(lens.wavelength_nm))


def _num(x) -> str:
    x = float(x)
    if not math.isfinite(x):
        raise InputError(f"cannot write the non-finite number {x} into an OSL shader")
    r = repr(x)
    return r if ("." in r or "e" in r) else r + ".0"


def _arr(name: str, values, size: str) -> str:
    vals = ", ".join(_num(v) for v in np.asarray(values, dtype=float).ravel())
    return f"    float {name}[{size}] = {{{vals}}};"


def _ident(name: str) -> str:
    s = re.sub(r"[^0-9A-Za-z]+", "_", name).strip("_").lower() or "lens"
    return s if not s[0].isdigit() else "lens_" + s


_RANDOM = """
    // a third decorrelated uniform number for the wavelength, from the two the camera gets
    float u_wl = hashnoise(point(u0 * 7.31 + rs[0], u1 * 3.17 + rs[1], u0 + u1));"""


def osl_camera_shader(lens: Prescription, *, focus_mm, fstop=None, sensor_width_mm, sensor_height_mm,
                      aperture=None, dispersion: bool = False, fresnel: bool = False) -> str:
    """OSL source of a Cycles camera shader that traces real rays through ``lens`` focused at
    ``focus_mm`` (mm in front of the film plane; ``math.inf`` for infinity) and stopped to ``fstop``.

    ``aperture``: an :class:`~physcam.trace.aperture.Aperture` (blades, angle, roundness, density),
    a number of blades, or a tuple/dict of its fields; ``None`` the round stop. ``dispersion``
    samples one wavelength per ray, uniform over :data:`WAVELENGTH_RANGE_NM`, with the exact index
    of each medium, and colours it with three tent functions (peaks 450, 550, 650 nm; they sum to
    1 at every wavelength, so white light stays white); ``fresnel`` multiplies the unpolarised
    Fresnel transmission (uncoated surfaces). See the module docstring for the conventions.
    """
    if not isinstance(dispersion, bool) or not isinstance(fresnel, bool):
        raise InputError("dispersion and fresnel must be True or False")
    b = bake_camera(lens, focus_mm=focus_mm, fstop=fstop, sensor_width_mm=sensor_width_mm,
                    sensor_height_mm=sensor_height_mm, aperture=aperture, fresnel=fresnel)
    return _emit(b, dispersion=dispersion, fresnel=fresnel)


def _emit(b: BakedCamera, *, dispersion: bool, fresnel: bool) -> str:
    from ..trace.kernels._layout import index_rows, pack, NA, NB, SA, SB

    t = b.table
    n = len(t)
    S, kinds = pack(t)
    with np.errstate(all="ignore"):
        n1 = index_rows(S, NB, SB, b.wavelength_nm)
        n2 = index_rows(S, NA, SA, b.wavelength_nm)
    nx, ny = len(b.bounds.xs), len(b.bounds.ys)
    rects = b.bounds.rects  # (ny, nx, 4)
    k_stop = int(np.flatnonzero(t.kind == 1)[0])
    ap = b.aperture
    use_ap = ap is not None
    nsides = int(ap.nsides) if use_ap else 0
    d = b.film_z - float(b.bounds.z_plane)
    name = _ident(b.lens.name)
    fno = "open" if b.fstop is None else f"f/{b.fstop:g}"
    focus_txt = "infinity" if math.isinf(b.focus_mm) else f"{b.focus_mm:g} mm"
    L = []
    a = L.append
    a(f"// physcam real-lens camera: {b.lens.name}")
    a(f"// focus {focus_txt} from the film, {fno}; sensor {b.sensor_width_mm:g} x {b.sensor_height_mm:g} mm;")
    a(f"// dispersion {'on' if dispersion else 'off'}, Fresnel {'on' if fresnel else 'off'}, aperture "
      f"{'round' if not use_ap else f'{nsides} blades, {ap.angle_deg:g} deg, roundness {ap.roundness:g}, density {ap.density:g}'}.")
    a("// Generated by physcam.export.blender.osl_camera_shader: surfaces film side first (tracing order),")
    a("// lens space mm (+z toward the film); output in Cycles' OSL camera space (+Z toward the scene, metres).")
    a("")
    a(f"#define N_SURF {n}")
    a(f"#define STOP_ROW {k_stop}")
    a(f"#define N_BX {nx}")
    a(f"#define N_BY {ny}")
    a(f"#define N_RECT {nx * ny * 4}")
    a(f"#define N_ASPH {n * 7}  // OSL array sizes must be plain integer literals")
    a(f"#define N_DISP {n * 9}")
    a("")
    a(f"shader physcam_{name}(")
    a("    output point position = point(0, 0, 0),")
    a("    output vector direction = vector(0, 0, 1),")
    a("    output color throughput = color(0))")
    a("{")
    a(f"    float FILM_Z = {_num(b.film_z)};")
    a(f"    float REAR_Z = {_num(b.bounds.z_plane)};")
    a(f"    float HALF_W = {_num(b.sensor_width_mm / 2)};")
    a(f"    float HALF_H = {_num(b.sensor_height_mm / 2)};")
    a(f"    float NORM = {_num(b.norm)};")
    a(f"    int KIND[N_SURF] = {{{', '.join(str(int(k)) for k in kinds)}}};")
    a(_arr("VZ", t.vertex_z, "N_SURF"))
    a(_arr("AX", t.ax, "N_SURF"))
    a(_arr("AY", t.ay, "N_SURF"))
    a(_arr("AZ", t.az, "N_SURF"))
    a(_arr("CV", t.curvature, "N_SURF"))
    a(_arr("CK", t.conic, "N_SURF"))
    a(_arr("SEMI", t.semi_diameter, "N_SURF"))
    if np.any(t.aspheric != 0.0):
        a("#define HAS_ASPHERE 1")
        a(_arr("ASPH", t.aspheric, "N_ASPH"))
    if dispersion:
        a(_arr("DB", t.disp_before, "N_DISP"))
        a(_arr("DA", t.disp_after, "N_DISP"))
    else:
        a(_arr("N1", n1, "N_SURF"))
        a(_arr("N2", n2, "N_SURF"))
    if fresnel:
        a(_arr("RSC", t.r_scale, "N_SURF"))
    a(_arr("RECT", rects, "N_RECT"))
    a("")
    a("    // film position: the lens inverts the image, so the picture comes out upright")
    a("    point rs = camera_shader_raster_position();")
    a("    point ru = camera_shader_random_sample();")
    a("    float u0 = ru[0];")
    a("    float u1 = ru[1];")
    a("    float fx = -(2.0 * rs[0] - 1.0) * HALF_W;")
    a("    float fy = -(2.0 * rs[1] - 1.0) * HALF_H;")
    a("    throughput = color(0);")
    a("")
    a("    // exit-pupil rectangle on the rear vertex plane: union of the four surrounding table nodes")
    a("    int i0 = (int)floor((fx + HALF_W) / (2.0 * HALF_W) * (N_BX - 1));")
    a("    int j0 = (int)floor((fy + HALF_H) / (2.0 * HALF_H) * (N_BY - 1));")
    a("    i0 = clamp(i0, 0, N_BX - 2);")
    a("    j0 = clamp(j0, 0, N_BY - 2);")
    a("    float x0 = 1e30; float x1 = -1e30; float y0 = 1e30; float y1 = -1e30;")
    a("    for (int jj = 0; jj < 2; jj++) {")
    a("        for (int ii = 0; ii < 2; ii++) {")
    a("            int o = ((j0 + jj) * N_BX + (i0 + ii)) * 4;")
    a("            if (RECT[o + 1] > RECT[o]) {")
    a("                x0 = min(x0, RECT[o]); x1 = max(x1, RECT[o + 1]);")
    a("                y0 = min(y0, RECT[o + 2]); y1 = max(y1, RECT[o + 3]);")
    a("            }")
    a("        }")
    a("    }")
    a("    if (x1 <= x0) return;")
    a("    float d = FILM_Z - REAR_Z;")
    a("    float tx = x0 + u0 * (x1 - x0);")
    a("    float ty = y0 + u1 * (y1 - y0);")
    a("    vector dr = normalize(vector(tx - fx, ty - fy, -d));")
    a("    float cz = -dr[2];")
    a("    float w = cz * cz * cz * cz * (x1 - x0) * (y1 - y0) / (d * d) / NORM;")
    a("    float px = fx; float py = fy; float pz = FILM_Z;")
    a("    float dx = dr[0]; float dy = dr[1]; float dz = dr[2];")
    if dispersion:
        lo, hi = WAVELENGTH_RANGE_NM
        a(_RANDOM)
        a(f"    float lam = {_num(lo)} + {_num(hi - lo)} * u_wl;")
        a("    float l2 = (lam / 1000.0) * (lam / 1000.0);")
        a("    float ul = 1.0 / l2;")
    if fresnel:
        a("    float Ts = 1.0; float Tp = 1.0;  // s- and p-polarised throughputs")
    a("")
    a("    for (int s = 0; s < N_SURF; s++) {")
    a("        int kd = KIND[s];")
    a("        float qz = pz - VZ[s];")
    a("        float t = 0.0;")
    a("        if (kd <= 1) {")
    a("            if (dz == 0.0) return;")
    a("            t = -qz / dz;")
    a("        } else {")
    a("            float A = AX[s] * dx * dx + AY[s] * dy * dy + AZ[s] * dz * dz;")
    a("            float B = AX[s] * px * dx + AY[s] * py * dy + AZ[s] * qz * dz - dz;")
    a("            float C = AX[s] * px * px + AY[s] * py * py + AZ[s] * qz * qz - 2.0 * qz;")
    a("            float disc = B * B - A * C;")
    a("            if (disc < 0.0) return;")
    a("            float sq = sqrt(disc);")
    a("            float den = (B >= 0.0) ? (-B - sq) : (-B + sq);")
    a("            if (den == 0.0) return;")
    a("            t = C / den;")
    a("            // the branch through the vertex has AZ z < 1; else take the other root")
    a("            if (AZ[s] * (qz + t * dz) >= 1.0) {")
    a("                if (A == 0.0) return;")
    a("                t = den / A;")
    a("                if (!(AZ[s] * (qz + t * dz) < 1.0)) return;")
    a("            }")
    a("        }")
    a("        float dsr = 0.0;")
    a("#ifdef HAS_ASPHERE")
    a("        if (kd == 3) {")
    a("            float cv = CV[s];")
    a("            float ck1 = (1.0 + CK[s]) * cv * cv;")
    a("            int done = 0;")
    a("            for (int it = 0; it < 40; it++) {")
    a("                float X = px + t * dx; float Y = py + t * dy; float Z = qz + t * dz;")
    a("                float r2 = X * X + Y * Y;")
    a("                float arg = 1.0 - ck1 * r2;")
    a("                if (arg < 0.0) return;")
    a("                float sa = sqrt(arg);")
    a("                float sag = cv * r2 / (1.0 + sa);")
    a("                float ds = cv / sa;")
    a("                float pp = r2 * r2; float qq = r2;")
    a("                for (int j = 0; j < 7; j++) {")
    a("                    float cj = ASPH[s * 7 + j];")
    a("                    sag += cj * pp;")
    a("                    ds += (2.0 * j + 4.0) * cj * qq;")
    a("                    pp *= r2; qq *= r2;")
    a("                }")
    a("                float gp = dz - ds * (X * dx + Y * dy);")
    a("                if (gp == 0.0) return;")
    a("                float dt = (Z - sag) / gp;")
    a("                t -= dt;")
    a("                if (abs(dt) < 1e-5 * (1.0 + abs(t))) { done = 1; break; }")
    a("            }")
    a("            if (!done) return;")
    a("            float X = px + t * dx; float Y = py + t * dy;")
    a("            float r2 = X * X + Y * Y;")
    a("            float arg = 1.0 - ck1 * r2;")
    a("            if (arg < 0.0) return;")
    a("            dsr = cv / sqrt(arg);")
    a("            float qq = r2;")
    a("            for (int j = 0; j < 7; j++) { dsr += (2.0 * j + 4.0) * ASPH[s * 7 + j] * qq; qq *= r2; }")
    a("        }")
    a("#endif")
    a("        px += t * dx; py += t * dy; pz += t * dz;")
    a("        float rr = px * px + py * py;")
    a("        if (!(rr <= SEMI[s] * SEMI[s])) return;  // clipped (NaN fails too)")
    a("        if (kd == 1) {")
    if use_ap:
        wedge = 2 * math.pi / nsides if nsides >= 3 else 0.0
        a("            // aperture shape at the stop (physcam.trace.aperture.Aperture.density_at)")
        a("            float ux = px / SEMI[s]; float uy = py / SEMI[s];")
        if nsides >= 3:
            a(f"            float wedge = {_num(wedge)};")
            a(f"            float ph = mod(atan2(uy, ux) - {_num(math.radians(ap.angle_deg))}, wedge) - wedge / 2.0;")
            a(f"            float pg = {_num(math.cos(wedge / 2))} / cos(ph);")
            a(f"            float rim = pg + {_num(ap.roundness)} * (1.0 - pg);")
        else:
            a("            float rim = 1.0;")
        a("            float sr = sqrt(ux * ux + uy * uy) / rim;")
        a("            if (!(sr <= 1.0)) return;")
        a(f"            float dens = 1.0 + {_num(ap.density)} * (2.0 * sr - 1.0);")
        a("            if (!(dens > 0.0)) return;")
        a("            w *= dens;")
    a("            continue;")
    a("        }")
    if dispersion:
        a("        int o = s * 9;")
        a("        float n1 = DB[o] + (DB[o + 1] + DB[o + 2] * ul) * ul;")
        a("        if (DB[o + 3] != 0.0 || DB[o + 4] != 0.0 || DB[o + 5] != 0.0)")
        a("            n1 += sqrt(1.0 + DB[o + 3] * l2 / (l2 - DB[o + 6]) + DB[o + 4] * l2 / (l2 - DB[o + 7])")
        a("                       + DB[o + 5] * l2 / (l2 - DB[o + 8]));")
        a("        float n2 = DA[o] + (DA[o + 1] + DA[o + 2] * ul) * ul;")
        a("        if (DA[o + 3] != 0.0 || DA[o + 4] != 0.0 || DA[o + 5] != 0.0)")
        a("            n2 += sqrt(1.0 + DA[o + 3] * l2 / (l2 - DA[o + 6]) + DA[o + 4] * l2 / (l2 - DA[o + 7])")
        a("                       + DA[o + 5] * l2 / (l2 - DA[o + 8]));")
    else:
        a("        float n1 = N1[s];")
        a("        float n2 = N2[s];")
    a("        if (n1 == n2) continue;")
    a("        float eta = n1 / n2;")
    a("        vector g;")
    a("        if (kd == 0) g = vector(0, 0, -1);")
    a("        else if (kd == 2) g = vector(AX[s] * px, AY[s] * py, AZ[s] * (pz - VZ[s]) - 1.0);")
    a("        else g = vector(dsr * px, dsr * py, -1.0);")
    a("        g = normalize(g);")
    a("        vector dv = vector(dx, dy, dz);")
    a("        float ci = dot(dv, g);")
    a("        if (ci < 0.0) { g = -g; ci = -ci; }  // normal on the side the ray travels to")
    a("        float kk = 1.0 - eta * eta * (1.0 - ci * ci);")
    a("        if (!(kk >= 0.0)) return;  // total internal reflection")
    a("        vector nd = refract(dv, -g, eta);  // Snell: eta d + (cos t - eta cos i) g")
    a("        if (nd == vector(0)) return;")
    if fresnel:
        a("        float ct = sqrt(kk);")
        a("        float ec = eta * ci; float et = eta * ct;")
        a("        float sm = (ec - ct) * (ci + et);")
        a("        float pm = (ci - et) * (ec + ct);")
        a("        float sp = (ec + ct) * (ci + et);")
        a("        float qf = RSC[s] / (sp * sp);")
        a("        Ts *= 1.0 - min(sm * sm * qf, 1.0);")
        a("        Tp *= 1.0 - min(pm * pm * qf, 1.0);")
    a("        dx = nd[0]; dy = nd[1]; dz = nd[2];")
    a("    }")
    if fresnel:
        a("    w *= 0.5 * (Ts + Tp);")
    a("    if (!(w > 0.0) || !(w < 1e30)) return;")
    a("    // lens space (mm, +z toward the film) -> OSL camera space (m, +Z toward the scene)")
    a("    position = point(px * 0.001, py * 0.001, (FILM_Z - pz) * 0.001);")
    a("    direction = vector(dx, dy, -dz);")
    if dispersion:
        a("    // three tents (450, 550, 650 nm) summing to 1 at each wavelength; x3 keeps white white")
        a("    float cb = clamp((550.0 - lam) / 100.0, 0.0, 1.0);")
        a("    float cr = clamp((lam - 550.0) / 100.0, 0.0, 1.0);")
        a("    float cg = 1.0 - cb - cr;")
        a("    throughput = color(3.0 * w * cr, 3.0 * w * cg, 3.0 * w * cb);")
    else:
        a("    throughput = color(w);")
    a("}")
    return "\n".join(L) + "\n"


def _resolution(resolution, sw, sh):
    if resolution is None:
        w = 1920
        return w, max(1, int(round(w * sh / sw)))
    try:
        w, h = (int(v) for v in resolution)
    except (TypeError, ValueError):
        raise InputError("resolution must be two integers (width, height) in pixels") from None
    if not (1 <= w <= 65536 and 1 <= h <= 65536):
        raise InputError(f"resolution must lie in 1..65536 pixels a side, got {w} x {h}")
    if abs((w / h) / (sw / sh) - 1.0) > 0.01:
        raise InputError(f"resolution {w} x {h} has aspect {w / h:.4f}, the sensor {sw:g} x {sh:g} mm "
                         f"{sw / sh:.4f}: the shader maps the whole sensor to the frame, so they must match")
    return w, h


_SETUP = '''"""Blender set-up for a physcam real-lens camera{title}.

Run it as ``blender --python {script}`` (or ``blender file.blend --python ...``), or import it
and call ``apply(scene)``: the scene camera (created when the scene has none) becomes a Cycles
custom OSL camera with the shader below, the sensor and resolution are set, OSL shading is
switched on and the device set to the CPU (Cycles runs OSL cameras on the CPU and OptiX only).
Generated by physcam.export.blender.blender_setup_script.
"""

import os

import bpy

SENSOR_WIDTH_MM = {sw!r}
SENSOR_HEIGHT_MM = {sh!r}
RESOLUTION = {res!r}
TEXT_NAME = {text_name!r}
SHADER_PATH = {path!r}  # read at run time when set (relative to this script)
SHADER_SOURCE = {source!r}


def _source():
    if SHADER_PATH is None:
        return SHADER_SOURCE
    p = SHADER_PATH
    if not os.path.isabs(p):
        here = os.path.dirname(os.path.abspath(globals().get("__file__", "") or "."))
        p = os.path.join(here, p)
    with open(p, encoding="utf-8") as fh:
        return fh.read()


def apply(scene=None):
    """Make ``scene``'s camera (default: the current scene's) the physcam OSL camera; returns it."""
    scene = scene or bpy.context.scene
    cam_obj = scene.camera
    if cam_obj is None:
        cam_obj = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        scene.collection.objects.link(cam_obj)
        scene.camera = cam_obj
    # Cycles with OSL first: Blender compiles a custom camera shader when it is assigned, and only
    # when the scene already renders with Cycles and OSL (else the camera stays uncompiled and black)
    r = scene.render
    r.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.shading_system = True
    r.resolution_x, r.resolution_y = RESOLUTION
    r.resolution_percentage = 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    text = bpy.data.texts.get(TEXT_NAME) or bpy.data.texts.new(TEXT_NAME)
    text.clear()
    text.write(_source())
    cam = cam_obj.data
    cam.type = "CUSTOM"
    cam.custom_mode = "INTERNAL"
    cam.custom_shader = text
    cam.sensor_fit = "HORIZONTAL"
    cam.sensor_width = SENSOR_WIDTH_MM
    cam.sensor_height = SENSOR_HEIGHT_MM
    if not cam.custom_bytecode:
        raise RuntimeError("Blender did not compile the physcam OSL camera shader: is this Blender built with "
                           "OSL, and is its oslquery module importable?")
    return cam_obj


if __name__ == "__main__":
    apply()
'''


def blender_setup_script(shader, *, sensor_width_mm, sensor_height_mm, resolution=None,
                         text_name: str = "physcam_lens.osl") -> str:
    """Python source of a Blender script (``blender --python setup.py``; importable, ``apply(scene=None)``)
    that makes the scene camera the custom OSL camera.

    ``shader``: the OSL source (a ``str`` holding a ``shader`` declaration) embedded in the script,
    or a path (``pathlib.Path``, or a one-line ``str`` without a shader declaration) read when the script runs, relative to
    the script. ``resolution`` (w, h) px must have the sensor's aspect (1 %); default 1920 wide.
    """
    sw = require_positive("sensor width", sensor_width_mm)
    sh = require_positive("sensor height", sensor_height_mm)
    res = _resolution(resolution, sw, sh)
    if isinstance(shader, Path):
        path, source = str(shader), None
    elif isinstance(shader, str) and re.search(r"\bshader\s+\w+\s*\(", shader):
        path, source = None, shader
    elif isinstance(shader, str) and shader.strip() and "\n" not in shader.strip():
        path, source = shader.strip(), None
    else:
        raise InputError("shader must be OSL source text (with a `shader` declaration) or a path to an .osl file")
    if not isinstance(text_name, str) or not text_name.strip():
        raise InputError("text_name must be a non-empty string")
    title = f" ({Path(path).name})" if path else ""
    return _SETUP.format(title=title, script="setup.py", sw=float(sw), sh=float(sh), res=res, text_name=text_name,
                         path=path, source=source)


def write_blender_camera(out_dir, lens: Prescription, *, focus_mm, fstop=None, sensor_width_mm, sensor_height_mm,
                         aperture=None, dispersion: bool = False, fresnel: bool = False, resolution=None,
                         name: str | None = None, force: bool = False) -> tuple[Path, Path]:
    """Write ``<name>.osl`` (:func:`osl_camera_shader`) and ``setup_<name>.py``
    (:func:`blender_setup_script`, with the shader embedded) into ``out_dir`` through
    :func:`physcam.io.atomic_write` (no overwrite without ``force``). ``name`` defaults to the
    lens name made an identifier. Returns the two paths."""
    from ..io import atomic_write, check_writable
    from ..lens.prescription import require_prescription

    require_prescription(lens)
    stem = _ident(name if name is not None else lens.name)
    out = Path(out_dir)
    osl_path = out / f"{stem}.osl"
    setup_path = out / f"setup_{stem}.py"
    check_writable(osl_path, force=force)
    check_writable(setup_path, force=force)
    src = osl_camera_shader(lens, focus_mm=focus_mm, fstop=fstop, sensor_width_mm=sensor_width_mm,
                            sensor_height_mm=sensor_height_mm, aperture=aperture, dispersion=dispersion,
                            fresnel=fresnel)
    setup = blender_setup_script(src, sensor_width_mm=sensor_width_mm, sensor_height_mm=sensor_height_mm,
                                 resolution=resolution, text_name=f"{stem}.osl")
    atomic_write(osl_path, src, force=force)
    atomic_write(setup_path, setup, force=force)
    return osl_path, setup_path
