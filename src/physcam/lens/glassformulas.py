"""Zemax OpticStudio's glass dispersion formulas 1-13, as numbered in ``.agf`` catalogues.

n at a vacuum wavelength ``l`` in micrometres from a formula number and its coefficients
(the order of an ``.agf`` ``CD`` line). Source: Zemax OpticStudio user manual, "Glass
catalogs: dispersion formulas"; SCHOTT TIE-29 for Sellmeier and Schott; the HIKARI catalogue for
the 9-term series (formula 13). Plain arithmetic on floats or numpy arrays, shared by the lens
and optics layers.

=====  ==============  =======================================================================
 no.   name            formula (l in um)
=====  ==============  =======================================================================
 1     Schott          n^2 = a0 + a1 l^2 + a2 l^-2 + a3 l^-4 + a4 l^-6 + a5 l^-8
 2     Sellmeier 1     n^2 - 1 = K1 l^2/(l^2-L1) + K2 l^2/(l^2-L2) + K3 l^2/(l^2-L3)
 3     Herzberger      n = A + B L + C L^2 + D l^2 + E l^4 + F l^6,  L = 1/(l^2 - 0.028)
 4     Sellmeier 2     n^2 = 1 + A + B1 l^2/(l^2 - l1^2) + B2/(l^2 - l2^2)
 5     Conrady         n = n0 + A/l + B/l^3.5
 6     Sellmeier 3     Sellmeier 1 with four terms (K1 L1 .. K4 L4)
 7     Handbook 1      n^2 = A + B/(l^2 - C) - D l^2
 8     Handbook 2      n^2 = A + B l^2/(l^2 - C) - D l^2
 9     Sellmeier 4     n^2 = A + B l^2/(l^2 - C) + D l^2/(l^2 - E)
 10    Extended        n^2 = a0 + a1 l^2 + a2 l^-2 + ... + a7 l^-12
 11    Sellmeier 5     Sellmeier 1 with five terms
 12    Extended 2      n^2 = a0 + a1 l^2 + a2 l^-2 + a3 l^-4 + a4 l^-6 + a5 l^-8 + a6 l^4 + a7 l^6
 13    Extended 3      n^2 = a0 + a1 l^2 + a2 l^4 + a3 l^-2 + a4 l^-4 + ... + a8 l^-12
=====  ==============  =======================================================================
"""

from __future__ import annotations

__all__ = ["FORMULA_NAMES", "COEFFICIENT_COUNT", "formula_index", "is_sellmeier3"]

FORMULA_NAMES = {1: "Schott", 2: "Sellmeier 1", 3: "Herzberger", 4: "Sellmeier 2", 5: "Conrady",
                 6: "Sellmeier 3", 7: "Handbook of Optics 1", 8: "Handbook of Optics 2", 9: "Sellmeier 4",
                 10: "Extended", 11: "Sellmeier 5", 12: "Extended 2", 13: "Extended 3"}
#: Coefficients each formula uses (an .agf CD line carries 10; the rest are zero).
COEFFICIENT_COUNT = {1: 6, 2: 6, 3: 6, 4: 5, 5: 3, 6: 8, 7: 4, 8: 4, 9: 5, 10: 8, 11: 10, 12: 8, 13: 9}


def _series(l2, c, powers):
    return sum(a * l2 ** p for a, p in zip(c, powers))


def _sellmeier(l2, c, terms):
    return 1.0 + sum(c[2 * i] * l2 / (l2 - c[2 * i + 1]) for i in range(terms))


def _n_squared(formula, l2, c):
    if formula == 1:
        return _series(l2, c, (0, 1, -1, -2, -3, -4))
    if formula in (2, 6, 11):
        return _sellmeier(l2, c, {2: 3, 6: 4, 11: 5}[formula])
    if formula == 4:
        return 1.0 + c[0] + c[1] * l2 / (l2 - c[2] ** 2) + c[3] / (l2 - c[4] ** 2)
    if formula == 7:
        return c[0] + c[1] / (l2 - c[2]) - c[3] * l2
    if formula == 8:
        return c[0] + c[1] * l2 / (l2 - c[2]) - c[3] * l2
    if formula == 9:
        return c[0] + c[1] * l2 / (l2 - c[2]) + c[3] * l2 / (l2 - c[4])
    if formula == 10:
        return _series(l2, c, (0, 1, -1, -2, -3, -4, -5, -6))
    if formula == 12:
        return _series(l2, c, (0, 1, -1, -2, -3, -4, 2, 3))
    if formula == 13:
        return _series(l2, c, (0, 1, 2, -1, -2, -3, -4, -5, -6))
    raise ValueError(f"unknown dispersion formula {formula}")


def formula_index(formula: int, coefficients, wavelength_um):
    """n at ``wavelength_um`` (float or numpy array) from Zemax formula ``formula`` (module table)."""
    c = list(coefficients) + [0.0] * (10 - len(coefficients))
    lam = wavelength_um
    l2 = lam * lam
    if formula == 3:
        big_l = 1.0 / (l2 - 0.028)
        return c[0] + c[1] * big_l + c[2] * big_l * big_l + c[3] * l2 + c[4] * l2 * l2 + c[5] * l2 ** 3
    if formula == 5:
        return c[0] + c[1] / lam + c[2] / lam ** 3.5
    return _n_squared(formula, l2, c) ** 0.5


def is_sellmeier3(formula: int, coefficients) -> bool:
    """True when the formula is a 3-term Sellmeier (Zemax 2, or 6/11 with the extra terms zero)."""
    c = list(coefficients) + [0.0] * (10 - len(coefficients))
    return formula == 2 or (formula in (6, 11) and all(v == 0.0 for v in c[6:]))
