"""The kernel cache of ``physcam defocus`` on disk: stack files, written whole, checked when read.

A folder per camera (:meth:`~physcam.analysis.defocus.kernels.DefocusCamera.key`) holds
``stack-*.npz`` files. A run that traces kernels writes the ones it traced as **one** new file
(:func:`physcam.io.atomic_write`: one sync per stack, not per kernel, issue 47; a killed writer
leaves no file, never part of one), so the frames of a shot and the Dask workers that render them
share what any of them traced. A file holds: its format and camera key; the field grid's fractions
(:func:`physcam.analysis.defocus.field.field_fractions`); the kernels, each (field column, row,
depth node) with its image (unit sum per channel); the kernels traced at tile corners themselves
(small blurs: :data:`~physcam.analysis.defocus.kernels.DIRECT_BLUR_PX`), each (x, y in thousandths
of a display pixel, depth node) with its image; and the transmission table's rows
(:class:`physcam.analysis.defocus.field.FieldTable`).

Every file is **checked when read** (issue 42): a file that is not a readable archive of these
arrays (truncated, damaged), whose key or format is not this camera's, or whose numbers are not
finite, negative, or not summing to one, is set aside with a :class:`~physcam.errors.PhysCamWarning`
naming it, and its kernels are traced again: a damaged cache never gives NaN pixels.
"""

from __future__ import annotations

import io
import os
import secrets
import warnings
import zipfile
from pathlib import Path

import numpy as np

from ...errors import PhysCamWarning


STACK_GLOB = "stack-*.npz"
#: a kernel's channel sums may differ from 1 by this much in a file
_SUM_TOL = 1e-3


class _Damaged(Exception):
    """A stack file that does not hold what it should (the reason)."""


def _kernel_arrays(kernels: dict, prefix: str, scale: float = 1.0) -> dict:
    """A kernel dict ({(a, b, node): image}) as the file's three arrays (keys' a, b times ``scale``)."""
    keys = sorted(kernels)
    imgs = [np.ascontiguousarray(kernels[k], dtype=np.float32) for k in keys]
    nodes = np.array([(round(a * scale), round(b * scale), n) for a, b, n in keys], dtype=np.int64).reshape(-1, 3)
    return {prefix + "nodes": nodes, prefix + "sizes": np.array([i.shape[0] for i in imgs], np.int64),
            prefix + "data": np.concatenate([i.ravel() for i in imgs]) if imgs else np.zeros(0, np.float32)}


def write_stack(folder: Path, key: str, fmt: str, fractions, kernels: dict, table, direct=None) -> Path | None:
    """Write ``kernels`` ({(column, row, node): image}), ``direct`` ({(x, y, node): image}, kernels
    traced at tile corners) and ``table`` (radial, positions, {node: T}) as one new stack file in
    ``folder``; returns its path (None when there is nothing to write)."""
    from ...io import atomic_write

    radial, positions, trans = table
    direct = direct or {}
    if not kernels and not trans and not direct:
        return None
    tnodes = sorted(trans)
    buf = io.BytesIO()
    np.savez(buf, format=np.array(fmt), key=np.array(key), fractions=np.asarray(fractions, dtype=np.float64),
             **_kernel_arrays(kernels, ""), **_kernel_arrays(direct, "direct_", 1000.0),
             table_radial=np.array(bool(radial)), table_nodes=np.array(tnodes, dtype=np.int64),
             table_t=np.array([trans[n] for n in tnodes], dtype=np.float64).reshape(len(tnodes), int(positions), -1))
    path = folder / f"stack-{os.getpid()}-{secrets.token_hex(6)}.npz"
    return atomic_write(path, buf.getvalue(), force=False)


def read_stacks(folder: Path, key: str, fmt: str, channels: int):
    """Every sound stack file of ``folder``: (fractions or None, {(column, row, node): image},
    (radial, positions, {node: T}) or None, {(x, y, node): image}). Damaged files are set aside with a
    warning (module notes)."""
    fractions, kernels, table, direct = None, {}, None, {}
    for path in sorted(folder.glob(STACK_GLOB)) if folder.is_dir() else []:
        try:
            got = _read_one(path, key, fmt, channels)
        except _Damaged as exc:
            warnings.warn(f"the kernel cache file {path} is damaged ({exc}): its kernels are traced again",
                          PhysCamWarning, stacklevel=3)
            continue
        f, k, t, d = got
        if fractions is not None and not np.array_equal(f, fractions):
            continue  # another field grid (the first file's rules): its kernels do not fit
        fractions = f
        kernels.update(k)
        direct.update(d)
        if table is None:
            table = t
        elif t[:2] == table[:2]:
            table[2].update(t[2])
    return fractions, kernels, table, direct


def _read_one(path: Path, key: str, fmt: str, channels: int):
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {name: z[name] for name in z.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, RuntimeError) as exc:
        raise _Damaged(f"not a readable stack: {str(exc).splitlines()[0][:80] if str(exc) else type(exc).__name__}") from None
    need = ("format", "key", "fractions", "nodes", "sizes", "data", "direct_nodes", "direct_sizes", "direct_data",
            "table_radial", "table_nodes", "table_t")
    missing = [n for n in need if n not in arrays]
    if missing:
        raise _Damaged(f"no {missing[0]} array")
    if str(arrays["format"]) != fmt or str(arrays["key"]) != key:
        raise _Damaged("written for another camera or by another version")
    fractions = _finite(arrays["fractions"], "field grid")
    kernels = _kernel_list(arrays, "", channels, 1.0)
    direct = _kernel_list(arrays, "direct_", channels, 1e-3)
    tn, tt = arrays["table_nodes"], arrays["table_t"]
    if tn.ndim != 1 or tt.ndim != 3 or tt.shape[0] != len(tn) or tt.shape[2] != channels:
        raise _Damaged("its transmission table is malformed")
    if not np.isfinite(tt).all() or (tt < 0).any() or (tt > 4).any():
        raise _Damaged("its transmission table has NaN or impossible values")
    table = (bool(arrays["table_radial"]), int(tt.shape[1]), {int(n): tt[i] for i, n in enumerate(tn.tolist())})
    return fractions, kernels, table, direct


def _kernel_list(arrays: dict, prefix: str, channels: int, scale: float) -> dict:
    """The kernels of the file's arrays ``prefix`` + nodes, sizes, data, checked (keys' first two
    numbers times ``scale``)."""
    nodes, sizes, data = arrays[prefix + "nodes"], arrays[prefix + "sizes"], arrays[prefix + "data"]
    if nodes.ndim != 2 or nodes.shape[1] != 3 or sizes.shape != (len(nodes),) or (sizes % 2 != 1).any() or (sizes < 1).any():
        raise _Damaged("its kernel list is malformed")
    ends = np.cumsum(sizes.astype(np.int64) ** 2 * channels)
    if data.dtype != np.float32 or data.ndim != 1 or (len(ends) and ends[-1] != len(data)) or (not len(ends) and len(data)):
        raise _Damaged("its kernel data is not as long as its list says")
    kernels = {}
    for (a, b, n), s, end in zip(nodes.tolist(), sizes.tolist(), ends.tolist()):
        img = data[end - s * s * channels: end].reshape(s, s, channels)
        sums = img.sum(axis=(0, 1), dtype=np.float64)
        if not np.isfinite(img).all() or (img < 0).any() or (np.abs(sums - 1.0) > _SUM_TOL).any():
            raise _Damaged(f"kernel ({a}, {b}, {n}) has NaN, negative or misnormalised values")
        kernels[(a, b, n) if scale == 1.0 else (round(a * scale, 3), round(b * scale, 3), n)] = img
    return kernels


def _finite(a, what):
    if a.ndim != 1 or not np.isfinite(a).all():
        raise _Damaged(f"its {what} has NaN")
    return a
