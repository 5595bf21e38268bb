"""The OSL camera template (``physcam_lens.osl.in``) and the lens-data block physcam writes into it.

The template holds the optics as OSL; physcam fills two lines: ``@PHYSCAM_DEFINES@`` (array sizes
and the feature switches) and ``@PHYSCAM_LENS_DATA@`` (the lens's arrays, inside the shader body:
OSL has no global arrays). The feature switches (:data:`FEATURES`) are resolved here, so the
written shader holds only the code it runs; every other preprocessor line is left to OSL, and so are
the switches a caller leaves (``render_template``'s ``left``: the Blender extension's one source per
lens keeps dispersion and Fresnel as ``#ifdef`` blocks: :func:`lens_data` with None).
Used by :mod:`physcam.export.blender` (one baked focus) and :mod:`physcam.export.blender_focus`
(the focus table of the Blender extension).
"""

from __future__ import annotations

import math
from importlib import resources

import numpy as np

from ...errors import InputError

__all__ = ["FEATURES", "SPHERE_KIND", "template_text", "render_template", "lens_data", "osl_number", "osl_array",
           "ray_differential_define"]

#: The template's feature switches: a data block that defines one keeps that code, else it goes.
FEATURES = ("PHYSCAM_FOCUS_TABLE", "HAS_ASPHERE", "PHYSCAM_DISPERSION", "PHYSCAM_FRESNEL", "PHYSCAM_APERTURE",
            "PHYSCAM_POLYGON", "PHYSCAM_GHOSTS", "PHYSCAM_PUPIL_ORIGIN", "PHYSCAM_RADIAL_PUPIL", "PHYSCAM_SP", "PHYSCAM_ZOOM")
#: The shader's kind of a sphere: the tracer's quadric (kind 2) with AX = AY = AZ. Its gradient at a
#: point of the surface is a unit vector and a unit direction meets it with A = AX, so the shader skips
#: a normalisation and five products per sphere (docs/performance.md, Blender render, round 10).
SPHERE_KIND = 4
#: Wavelengths sampled per ray when dispersion is on (uniform).
WAVELENGTH_RANGE_NM = (400.0, 700.0)


def template_text() -> str:
    """The template's text (package data)."""
    return resources.files(__package__).joinpath("physcam_lens.osl.in").read_text(encoding="utf-8")


def osl_number(x) -> str:
    """A finite float as an OSL literal (round-trips: ``repr``)."""
    x = float(x)
    if not math.isfinite(x):
        raise InputError(f"cannot write the non-finite number {x} into an OSL shader")
    r = repr(x)
    return r if ("." in r or "e" in r) else r + ".0"


def osl_array(name: str, values, size: str, kind: str = "float") -> str:
    """``    float NAME[SIZE] = {...};`` (one line of the data block)."""
    if kind == "int":
        vals = ", ".join(str(int(v)) for v in np.asarray(values).ravel())
    else:
        vals = ", ".join(osl_number(v) for v in np.asarray(values, dtype=float).ravel())
    return f"    {kind} {name}[{size}] = {{{vals}}};"


def ray_differential_define(efl_mm: float) -> str:
    """``#define RAY_DIFF_F_MM <mm>``: the focal length of the pinhole whose ray derivatives the shader gives
    Cycles, as Blender's perspective camera does (dP zero, dD the pinhole's through the pixel): the lens's
    paraxial EFL ``efl_mm`` (:func:`physcam.optics.paraxial.gaussian`; its size). The traced ray carries no
    derivatives: OSL would carry them through the whole trace (docs/performance.md, Blender render, round 13)."""
    f = abs(float(efl_mm))
    if not (math.isfinite(f) and f > 0.0):
        from ...errors import OpticsError

        raise OpticsError(f"a camera shader needs the lens's focal length: its paraxial EFL is {efl_mm}")
    return f"#define RAY_DIFF_F_MM {osl_number(f)}"


def _osl_kinds(table) -> np.ndarray:
    """The shader's surface kinds: physcam's tracer's (0 plane, 1 stop, 2 quadric, 3 asphere), a quadric
    whose three coefficients are equal (a sphere) marked :data:`SPHERE_KIND`."""
    kinds = np.asarray(table.kind).copy()
    kinds[(kinds == 2) & (table.ax == table.ay) & (table.ay == table.az)] = SPHERE_KIND
    return kinds


def _resolve(lines: list[str], on: set[str], left=()) -> list[str]:
    """Keep the code of the switched-on features, drop the rest (nested #ifdef/#else/#endif of
    :data:`FEATURES` not in ``left`` only; other directives are OSL's)."""
    out, stack = [], []  # stack: (is ours, keeping) per open #if
    for line in lines:
        word = line.split(None, 2)  # the first two words are all it reads (not a data line's 100,000 numbers)
        head = word[0] if word else ""
        keeping = all(k for _, k in stack)
        if head in ("#ifdef", "#ifndef") and len(word) > 1 and word[1] in FEATURES and word[1] not in left:
            want = (word[1] in on) == (head == "#ifdef")
            stack.append((True, want))
            continue
        if head in ("#if", "#ifdef", "#ifndef"):
            stack.append((False, True))
        elif head == "#else" and stack and stack[-1][0]:
            stack[-1] = (True, not stack[-1][1])
            continue
        elif head == "#endif" and stack:
            ours, _ = stack.pop()
            if ours:
                continue
        if keeping:
            out.append(line)
    if stack:
        raise InputError("the OSL template has an #ifdef without #endif")
    return out


def render_template(defines: list[str], data: list[str], left=()) -> str:
    """The shader: the template with ``defines`` and ``data`` in place and its switches resolved
    (a ``#define NAME`` line in ``defines`` switches NAME on), but those in ``left`` (names of
    :data:`FEATURES`), whose ``#ifdef`` lines are kept for OSL's preprocessor."""
    for name, lines in (("defines", defines), ("data", data)):
        if isinstance(lines, str) or not all(isinstance(ln, str) for ln in lines):
            from ...errors import WrongTypeError

            raise WrongTypeError(f"{name} must be a list of OSL lines (text), got {lines!r:.60}")
    on = {ln.split()[1] for ln in defines if ln.startswith("#define ") and ln.split()[1] in FEATURES} - set(left)
    out = []
    for line in template_text().splitlines():
        if line.strip() == "@PHYSCAM_DEFINES@":
            out.extend(defines)
        elif line.strip() == "@PHYSCAM_LENS_DATA@":
            out.extend(data)
        else:
            out.append(line)
    return "\n".join(_resolve(out, on, left)) + "\n"


def lens_data(table, aperture, wavelength_nm: float, bounds, *, dispersion: bool | None,
              fresnel: bool | None) -> tuple[list[str], list[str]]:
    """The defines and the data lines that do not change with focus: surface kinds, quadric and
    asphere coefficients, indices (or dispersion coefficients), Fresnel scales and the iris shape
    (``aperture``; in a focus-table shader the iris is the shader's parameters, pass None).
    ``dispersion`` or ``fresnel`` None: both settings' lines, chosen by ``#ifdef PHYSCAM_DISPERSION``
    (``PHYSCAM_FRESNEL``, which defines PHYSCAM_SP), which the lines do not define: leave those switches
    to OSL (``render_template``'s ``left``). ``table``: a :func:`physcam.trace.surfaces.surface_table` (film side first);
    ``bounds``: the exit-pupil rectangles' PupilBounds, or None for a radial pupil table."""
    from ...errors import require_type
    from ...trace.kernels._layout import NA, NB, SA, SB, index_rows, pack
    from ...trace.surfaces import SurfaceTable

    require_type("table", table, SurfaceTable, "physcam.trace.surfaces.surface_table(lens)")

    n = len(table)
    S, _ = pack(table)
    defines = [f"#define N_SURF {n}", f"#define STOP_ROW {int(np.flatnonzero(table.kind == 1)[0])}"]
    if bounds is not None:  # the exit-pupil rectangles' grid (a radial pupil table has none)
        nx, ny = len(bounds.xs), len(bounds.ys)
        defines += [f"#define N_BX {nx}", f"#define N_BY {ny}", f"#define N_RECT {nx * ny * 4}"]
    defines += [f"#define N_ASPH {n * 7}  // OSL array sizes must be plain integer literals", f"#define N_DISP {n * 9}"]
    data = [osl_array("KIND", _osl_kinds(table), "N_SURF", "int")]
    for name, col in (("AX", table.ax), ("AY", table.ay), ("AZ", table.az), ("CV", table.curvature),
                      ("CK", table.conic)):
        data.append(osl_array(name, col, "N_SURF"))
    if np.any(table.aspheric != 0.0):
        defines.append("#define HAS_ASPHERE 1")
        data.append(osl_array("ASPH", table.aspheric, "N_ASPH"))
    lo, hi = WAVELENGTH_RANGE_NM
    disp_defines = [f"#define WAVELENGTH_LO {osl_number(lo)}", f"#define WAVELENGTH_HI {osl_number(hi)}"]
    disp_data = [osl_array("DB", table.disp_before, "N_DISP"), osl_array("DA", table.disp_after, "N_DISP")]
    with np.errstate(all="ignore"):
        index_data = [osl_array("N1", index_rows(S, NB, SB, wavelength_nm), "N_SURF"),
                      osl_array("N2", index_rows(S, NA, SA, wavelength_nm), "N_SURF")]
    if dispersion is None:
        defines += ["#ifdef PHYSCAM_DISPERSION", *disp_defines, "#endif"]
        data += ["#ifdef PHYSCAM_DISPERSION", *disp_data, "#else", *index_data, "#endif"]
    elif dispersion:
        defines += ["#define PHYSCAM_DISPERSION 1", *disp_defines]
        data += disp_data
    else:
        data += index_data
    if fresnel is None:
        defines += ["#ifdef PHYSCAM_FRESNEL", "#define PHYSCAM_SP 1", "#endif"]
    elif fresnel:
        defines += ["#define PHYSCAM_FRESNEL 1", "#define PHYSCAM_SP 1"]
    data.append(osl_array("RSC", table.r_scale, "N_SURF"))  # Fresnel, and ghosts' reflectances
    return defines + _aperture_defines(aperture), data


def _aperture_defines(ap) -> list[str]:
    """The iris shape (physcam.trace.aperture.Aperture) as constants; none for the round stop."""
    if ap is None:
        return []
    out = ["#define PHYSCAM_APERTURE 1", f"#define AP_ROUNDNESS {osl_number(ap.roundness)}",
           f"#define AP_DENSITY {osl_number(ap.density)}"]
    if int(ap.nsides) >= 3:
        wedge = 2 * math.pi / int(ap.nsides)
        out += ["#define PHYSCAM_POLYGON 1", f"#define AP_WEDGE {osl_number(wedge)}",
                f"#define AP_ANGLE {osl_number(math.radians(ap.angle_deg))}",
                f"#define AP_COS_HALF_WEDGE {osl_number(math.cos(wedge / 2))}"]
    return out
