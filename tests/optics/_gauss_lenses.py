"""Hand-made prescriptions for the Gaussian-optics tests (not collected by pytest)."""

from __future__ import annotations

from dataclasses import replace

from physcam.lens.prescription import AIR, Focus, Medium, Prescription, Surface, VariableGap

# pbrt-v4-scenes lenses/dgauss.50mm.dat: radius, thickness, index (0 = air), aperture diameter.
DGAUSS_ROWS = """29.475 3.76 1.67 25.2
84.83 0.12 1 25.2
19.275 4.025 1.67 23
40.77 3.275 1.699 23
12.75 5.705 1 18
0 4.5 0 17.1
-14.495 1.18 1.603 17
40.77 6.065 1.658 20
-20.385 0.19 1 20
437.065 3.22 1.717 20
-39.73 0 1 20"""


def dgauss() -> Prescription:
    surfaces = []
    for row in DGAUSS_ROWS.splitlines():
        r, t, n, d = map(float, row.split())
        medium = AIR if n in (0.0, 1.0) else Medium(n, 0.0)
        surfaces.append(Surface(r, t, medium, d / 2.0, "stop" if r == 0 else "spherical"))
    return Prescription(tuple(surfaces)).validate()


def thin_lens_surfaces(f: float, n: float = 1.5, semi: float = 5.0, gap_after: float = 0.0, kind: str = "spherical"):
    """An equi-convex lens of zero thickness: focal length f (1/f = (n-1)(2/R))."""
    r = 2.0 * (n - 1.0) * f
    return [
        Surface(r, 0.0, Medium(n, 0.0), semi, kind),
        Surface(-r, gap_after, AIR, semi, kind),
    ]


def stop(gap_after: float, semi: float = 2.0) -> Surface:
    return Surface(0.0, gap_after, AIR, semi, "stop")


def thin_lens(f: float, stop_gap: float = 0.0, stop_semi: float = 2.0) -> Prescription:
    """Thin lens of focal length f; the stop ``stop_gap`` mm behind it (at the lens when 0)."""
    return Prescription(tuple(thin_lens_surfaces(f, gap_after=stop_gap) + [stop(0.0, stop_semi)]))


def thin_pair(f1: float, f2: float, d: float, *, focus: tuple[float, float] | None = None) -> Prescription:
    """Two thin lenses d apart, the stop at the first; ``focus`` = (close_distance, gap_close)."""
    s = [stop(0.0)] + thin_lens_surfaces(f1, gap_after=d) + thin_lens_surfaces(f2)
    fg = None
    if focus is not None:
        fg = Focus(close_distance=focus[0], gaps=(VariableGap(2, d, focus[1]),))
    return Prescription(tuple(s), focus=fg)


def reversed_lens(p: Prescription) -> Prescription:
    """The same glass turned around: surfaces in reverse order, radii negated, media shifted."""
    s = p.surfaces
    m = len(s)
    out = []
    for j in range(m):
        orig = s[m - 1 - j]
        if j < m - 1:
            before = s[m - 2 - j]
            out.append(replace(orig, radius=-orig.radius, thickness=before.thickness, medium=before.medium))
        else:
            out.append(replace(orig, radius=-orig.radius, thickness=0.0, medium=AIR))
    return replace(p, surfaces=tuple(out), focus=None)


def scaled_lens(p: Prescription, k: float) -> Prescription:
    return replace(
        p,
        surfaces=tuple(
            replace(x, radius=x.radius * k, thickness=x.thickness * k, semi_diameter=x.semi_diameter * k) for x in p.surfaces
        ),
        focus=None,
    )
