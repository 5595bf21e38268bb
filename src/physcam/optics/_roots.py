"""A root inside a bracket, for the optics' one-dimensional solves (internal focus, a zoom's focal length)."""

from __future__ import annotations


def bracketed_root(f, a: float, fa: float, b: float, fb: float, tol: float) -> float:
    """A root of ``f`` in [a, b] (``fa`` = f(a) <= 0 <= ``fb`` = f(b)) to within ``tol``: regula falsi, Illinois
    variant (M. Dowell and P. Jarratt, "A modified regula falsi method for computing the root of an equation",
    BIT 11, 1971: an end kept twice in a row has its value halved, so both ends close in; superlinear, and
    never leaving the bracket). The internal-focus residual is smooth and nearly linear in the subject distance
    (its slope about 1), a zoom's EFL smooth and monotone in the encoder: a handful of evaluations where
    bisection took 35-45. The answer: a point whose
    residual is below ``tol`` / 10, or the middle of the last bracket, narrower than ``tol`` (bisection's answer)."""
    side = 0
    for _ in range(200):
        if b - a < tol:
            break
        c = (a * fb - b * fa) / (fb - fa) if fb != fa else 0.5 * (a + b)
        if not a < c < b:  # rounding at a narrow bracket
            c = 0.5 * (a + b)
        fc = f(c)
        if abs(fc) < 0.1 * tol:
            return c
        if fc > 0:
            b, fb = c, fc
            if side == 1:
                fa *= 0.5
            side = 1
        else:
            a, fa = c, fc
            if side == -1:
                fb *= 0.5
            side = -1
    return 0.5 * (a + b)
