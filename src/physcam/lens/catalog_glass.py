"""One glass of a maker's catalogue (or of a user's Zemax ``.agf`` file): its name, nd and Vd, and
the catalogue's own dispersion formula (:mod:`physcam.lens.glassformulas`)."""

from __future__ import annotations


from .._record import field, record
from ..errors import InputError
from .glassformulas import formula_index, is_sellmeier3

__all__ = ["CatalogGlass"]


@record(slots=True)
class CatalogGlass:
    """One catalogue glass: ``nd`` at 587.5618 nm, Abbe number ``vd``, its catalogue (``maker``),
    Zemax ``formula`` number and ``coefficients`` (wavelength in um), span ``range_nm``, and in a
    legacy catalogue the maker's ``status`` ("obsolete", "standard"...)."""

    name: str
    nd: float
    vd: float
    maker: str
    formula: int | None = None
    coefficients: tuple = ()
    range_nm: tuple | None = None
    published: dict | None = field(default=None, compare=False)
    transmission_10mm: tuple = field(default=(), compare=False)
    previous: bool = False
    dpgf: float = 0.0
    status: str | None = field(default=None, compare=False)

    @property
    def sellmeier(self):
        """(B1, B2, B3, C1, C2, C3) when the formula is a 3-term Sellmeier, else None."""
        if self.formula is None or not is_sellmeier3(self.formula, self.coefficients):
            return None
        c = tuple(self.coefficients) + (0.0,) * 6
        return (c[0], c[2], c[4], c[1], c[3], c[5])

    def index(self, wavelength_nm):
        """n at ``wavelength_nm`` from the catalogue's own formula (no fit); needs a formula."""
        if self.formula is None:
            raise InputError(f"glass {self.name} has no dispersion formula in its catalogue")
        return formula_index(self.formula, self.coefficients, wavelength_nm / 1000.0)
