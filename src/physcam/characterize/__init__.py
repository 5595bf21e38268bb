"""Characterizing a lens library at scale on Dask (docs/characterize.md).

A declared grid (:class:`Grid`: focus marks, f-stops, field positions, wavelengths, ray counts) is
split into independent cells (:mod:`.grid`), each computed by one Dask task with physcam's
analyses (:mod:`.cells`), written atomically with a row in a Parquet index; a run skips what is
done and adds a characterization variant to each complete lens's USD file (:mod:`.run`,
:mod:`.library`). Layer: above ``usd`` (it writes the lens files through :mod:`physcam.usd.kit`),
below ``cli``; ``pxr`` is never imported here.
"""

from ..extras import require_extra

require_extra("dask", "characterizing on Dask (physcam characterize)")

from .grid import KINDS, MAX_CELLS, Cell, Grid, build_cells, parse_focus_marks, parse_numbers  # noqa: E402
from .run import CharacterizeSummary, characterize, check_scheduler_address, read_index  # noqa: E402

__all__ = ["Grid", "Cell", "KINDS", "MAX_CELLS", "parse_focus_marks", "parse_numbers", "build_cells",
           "characterize", "CharacterizeSummary", "check_scheduler_address", "read_index"]
