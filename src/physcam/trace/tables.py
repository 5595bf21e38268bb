"""Packed surface tables, built once per lens and reused by every trace call.

Flattening a prescription (:func:`~physcam.trace.surfaces.surface_table`) and packing it for the
kernels (``kernels._layout.pack``) cost about 60 us, and filling the index columns for one
wavelength 20 us more: more than tracing a few hundred rays. Analyses call the tracer many times
with the same lens (Newton iterations, bisections, refinement levels), so the packed table is
kept per (lens, direction, stop, coating, precision) and its index columns per wavelength.

Keys. A :class:`~physcam.lens.prescription.Prescription` is a frozen dataclass of frozen
dataclasses and tuples: immutable all the way down, and hashable. A lookup first tries the
lens *object* (its ``id``, checked through a weak reference, so a dead lens whose id is reused
never matches): about 0.3 us. A new object equal to a cached one (analyses rebuild the same cut
lens each call) is found by value next (hash and ``==``, 2-6 us). Equal prescriptions give
identical tables: equality compares the same floats the tables are built from, and the only
values that compare equal without being identical (0.0 and -0.0; 1 and 1.0) pack to the same
numbers (a radius of -0.0 is flat like 0.0; a conic or aspheric coefficient of -0.0 adds
nothing). The coating is resolved before keying (``None`` means the lens metadata's), and the
stop override is keyed by its float value. Caches are bounded (least recently used lenses go).

The cached arrays are shared: code that changes a table (ghost legs end on a surface) copies it
first, as :func:`physcam.trace.trace.trace_packed` does.
"""

from __future__ import annotations

import threading
import weakref
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from ..lens.prescription import Prescription
from .kernels._layout import pack, set_wavelength
from .surfaces import SurfaceTable, surface_table

__all__ = ["PackedTable", "packed_table", "clear_table_cache", "MAX_LENSES", "MAX_WAVELENGTHS"]

#: Lenses (by value) whose tables are kept; wavelengths kept per table.
MAX_LENSES = 64
MAX_WAVELENGTHS = 16
MAX_TABLES_PER_LENS = 64  # directions x stop overrides x coatings x precisions


@dataclass
class PackedTable:
    """One lens packed for the kernels: ``S`` (float64 or float32, rows in tracing order, index
    columns unset), ``kinds``, the ``SurfaceTable`` it came from and the stop's row."""

    table: SurfaceTable
    S: np.ndarray
    kinds: np.ndarray
    stop_row: int
    dtype: np.dtype
    _base64: np.ndarray = field(repr=False, default=None)
    _by_wl: OrderedDict = field(repr=False, default_factory=OrderedDict)

    def at_wavelength(self, wavelength_nm: float) -> np.ndarray:
        """``S`` with the index columns filled for one wavelength (cached; do not modify)."""
        wl = float(wavelength_nm)
        S = self._by_wl.get(wl)
        if S is None:
            S = self._base64.copy()
            set_wavelength(S, wl)  # in float64, then rounded once to the working precision
            if S.dtype != self.dtype:
                S = np.ascontiguousarray(S, dtype=self.dtype)
            self._by_wl[wl] = S
            if len(self._by_wl) > MAX_WAVELENGTHS:
                self._by_wl.popitem(last=False)
        return S


class _LensEntry:
    __slots__ = ("tables", "__weakref__")

    def __init__(self):
        self.tables: dict = {}


_lock = threading.Lock()
_by_value: OrderedDict = OrderedDict()  # Prescription -> _LensEntry (LRU)
_by_id: dict = {}  # id(lens) -> (weakref to lens, _LensEntry)


def clear_table_cache() -> None:
    """Forget every packed table (tests; after changing a lens class in place, which frozen
    prescriptions do not allow)."""
    with _lock:
        _by_value.clear()
        _by_id.clear()
        _fast.clear()


def _entry(lens: Prescription) -> _LensEntry:
    hit = _by_id.get(id(lens))
    if hit is not None and hit[0]() is lens:
        return hit[1]
    with _lock:
        e = _by_value.get(lens)
        if e is None:
            e = _LensEntry()
            _by_value[lens] = e
            while len(_by_value) > MAX_LENSES:
                old, _ = _by_value.popitem(last=False)
                _by_id.pop(id(old), None)
        else:
            _by_value.move_to_end(lens)
        key = id(lens)
        try:
            ref = weakref.ref(lens, lambda _r, key=key: _by_id.pop(key, None))
        except TypeError:  # not weak-referenceable: found by value every time
            return e
        _by_id[key] = (ref, e)
        return e


#: (id(lens), arguments as given) -> (weak reference to the lens, PackedTable): the per-call fast path
_fast: dict = {}
_FAST_MAX = 4096


def packed_table(lens: Prescription, *, reverse: bool = False, stop_semi_diameter: float | None = None,
                 coating: str | None = "none", dtype=np.float64) -> PackedTable:
    """The packed table of ``lens`` for the kernels (cached; module notes). Arguments as
    :func:`~physcam.trace.surfaces.surface_table`; ``dtype`` float64 or float32."""
    try:
        fkey = (id(lens), reverse, stop_semi_diameter, coating, dtype)
        hit = _fast.get(fkey)
    except TypeError:  # an unhashable argument: the slow path says what is wrong with it
        fkey = hit = None
    if hit is not None and hit[0]() is lens:
        return hit[1]
    p = _packed_table(lens, reverse, stop_semi_diameter, coating, dtype)
    if fkey is not None:
        try:
            ref = weakref.ref(lens)
        except TypeError:
            return p
        if len(_fast) >= _FAST_MAX:
            _fast.clear()
        _fast[fkey] = (ref, p)
    return p


def _packed_table(lens, reverse, stop_semi_diameter, coating, dtype) -> PackedTable:
    from ..errors import InputError, require_type

    require_type("lens", lens, Prescription, "load one with physcam.lens.library.load_lens(name)")
    if not isinstance(coating, (str, type(None))):
        raise InputError(f"coating must be 'none', 'single', 'multi' or None, got {coating!r}")
    if coating is None:
        mc = lens.metadata.coating
        coating = mc if mc in ("none", "single", "multi") else "none"
    dt = np.dtype(dtype)
    if dt not in (np.dtype(np.float64), np.dtype(np.float32)):
        raise InputError(f"packed tables are float64 or float32, not {dt}")
    stop = None if stop_semi_diameter is None else float(stop_semi_diameter)
    key = (bool(reverse), stop, coating, dt.char)
    e = _entry(lens)
    p = e.tables.get(key)
    if p is None:
        table = surface_table(lens, reverse=reverse, stop_semi_diameter=stop_semi_diameter, coating=coating)
        S64, kinds = pack(table)
        stops = np.flatnonzero(table.kind == 1)
        row = int(np.flatnonzero(table.index == lens.stop_index)[0]) if stops.size else -1
        S = S64 if dt == np.float64 else np.ascontiguousarray(S64, dtype=dt)
        p = PackedTable(table, S, kinds, row, dt, S64)
        if len(e.tables) >= MAX_TABLES_PER_LENS:
            e.tables.pop(next(iter(e.tables)))  # the oldest (dicts keep insertion order)
        e.tables[key] = p
    return p
