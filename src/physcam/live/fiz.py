"""Encoder-to-lens calibration tables (FIZ): normalised focus, iris and zoom encoders to focus
distance, f-stop and focal length.

A tracking stream may carry only ``lens.encoders`` (OpenTrackIO 1.0.1: normalised 0-1, focus 0 at
infinity and 1 at the closest mark, iris 0 open, zoom 0 wide). Turning those into physical values is
the job of a lens calibration, the encoder mappings an Unreal Lens File holds for focus, iris and
zoom (Epic, "Camera Lens Calibration Overview": the Lens File converts raw focus and iris values
to physical units). physcam reads such a mapping as a CSV file, one calibration point a row::

    axis,encoder,value
    focus,0.0,inf        # metres from the film plane (the lens's focus marks); inf allowed
    focus,0.5,2.0
    focus,1.0,0.45
    iris,0.0,2.0         # f-stop
    iris,1.0,22
    zoom,0.0,24          # focal length, mm
    zoom,1.0,70

Between points a value is interpolated linearly in the encoder, focus in **dioptres** (1 / distance,
0 at infinity): a focus scale's marks are close to evenly spaced in 1 / distance, so two points a
turn apart interpolate far better there than in metres; iris in stops (log2 of the f-number), the
unit an iris ring is marked in. An encoder outside the calibrated range is refused, never
extrapolated. Lines starting with ``#`` and blank lines are skipped; a value may carry a comment
after ``#``.
"""

from __future__ import annotations

import bisect
import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError

__all__ = ["FizTable", "read_fiz_table", "FIZ_AXES"]

#: the axes a table may calibrate and what their values are
FIZ_AXES = {"focus": "metres from the film plane (inf allowed)", "iris": "f-stop", "zoom": "focal length, mm"}
#: the most rows one table holds
MAX_ROWS = 100_000


@dataclass(frozen=True)
class FizTable:
    """Calibration points per axis: ``points[axis]`` = ((encoder, value), ...) sorted by encoder."""

    points: dict

    def _interp(self, axis: str, encoder: float, to, back) -> float:
        pts = self.points.get(axis)
        if not pts:
            raise InputError(f"the FIZ table has no {axis} calibration")
        e = float(encoder)
        if not math.isfinite(e):
            raise InputError(f"the {axis} encoder {encoder!r} is not a number")
        xs = [p[0] for p in pts]
        if not xs[0] <= e <= xs[-1]:
            raise InputError(f"the {axis} encoder {e:g} is outside the calibrated range {xs[0]:g} to {xs[-1]:g}")
        if len(pts) == 1:
            return pts[0][1]
        i = min(max(bisect.bisect_right(xs, e) - 1, 0), len(xs) - 2)
        (x0, v0), (x1, v1) = pts[i], pts[i + 1]
        u = (e - x0) / (x1 - x0)
        return back(to(v0) + (to(v1) - to(v0)) * u)

    def focus_mm(self, encoder: float) -> float:
        """The focus mark (mm from the film plane; inf at infinity), interpolated in dioptres."""
        d = self._interp("focus", encoder, lambda m: 0.0 if math.isinf(m) else 1.0 / m,
                         lambda dpt: math.inf if dpt <= 0 else 1.0 / dpt)
        return d * 1000.0

    def fstop(self, encoder: float) -> float:
        """The f-stop, interpolated in stops."""
        return self._interp("iris", encoder, math.log2, lambda s: 2.0 ** s)

    def focal_length_mm(self, encoder: float) -> float:
        """The focal length (mm), interpolated linearly."""
        return self._interp("zoom", encoder, float, float)

    def has(self, axis: str) -> bool:
        return bool(self.points.get(axis))


def _value(axis: str, text: str, where: str) -> float:
    t = text.split("#", 1)[0].strip().lower()
    if axis == "focus" and t in ("inf", "infinity"):
        return math.inf
    try:
        v = float(t)
    except ValueError:
        raise InputError(f"{where}: {text.strip()!r} is not a number") from None
    if not math.isfinite(v) or v <= 0:
        raise InputError(f"{where}: a {axis} value must be a positive number ({FIZ_AXES[axis]}), got {text.strip()!r}")
    if axis == "iris" and not 0.5 <= v <= 256:
        raise InputError(f"{where}: an f-stop must lie between 0.5 and 256, got {v:g}")
    if axis != "iris" and v > 1e6:
        raise InputError(f"{where}: {v:g} is beyond {'1000 km' if axis == 'focus' else '1 km'}")
    return v


def read_fiz_table(file) -> FizTable:
    """Read a FIZ calibration CSV (module notes); errors name the file and line."""
    p = Path(file) if isinstance(file, (str, Path)) else None
    if p is None:
        raise InputError(f"a FIZ table is a file name, got {file!r}")
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the FIZ table {p}: {getattr(exc, 'strerror', None) or exc}") from None
    lines = [(n, line) for n, line in enumerate(text.splitlines(), start=1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines or [c.strip().lower() for c in lines[0][1].split(",")] != ["axis", "encoder", "value"]:
        raise InputError(f"{p}:{lines[0][0] if lines else 1}: a FIZ table starts with the header axis,encoder,value")
    if len(lines) > MAX_ROWS:
        raise InputError(f"{p}: more than {MAX_ROWS} rows")
    points: dict = {}
    for n, line in lines[1:]:
        where = f"{p}:{n}"
        row = next(csv.reader(io.StringIO(line)))
        if len(row) != 3:
            raise InputError(f"{where}: a row is axis,encoder,value, got {line.strip()!r:.60}")
        axis = row[0].strip().lower()
        if axis not in FIZ_AXES:
            raise InputError(f"{where}: the axis is focus, iris or zoom, got {row[0].strip()!r:.20}")
        try:
            e = float(row[1])
        except ValueError:
            raise InputError(f"{where}: the encoder {row[1].strip()!r:.20} is not a number") from None
        if not 0.0 <= e <= 1.0:
            raise InputError(f"{where}: an encoder is normalised, 0 to 1 (OpenTrackIO lens.encoders), got {row[1].strip()}")
        points.setdefault(axis, []).append((e, _value(axis, row[2], where)))
    for axis, pts in points.items():
        pts.sort()
        if any(a[0] == b[0] for a, b in zip(pts, pts[1:])):
            raise InputError(f"{p}: two {axis} rows have the same encoder value")
    if not points:
        raise InputError(f"{p}: the FIZ table has no rows")
    return FizTable({k: tuple(v) for k, v in points.items()})
