"""The declared grid of a characterization job, its cells, and the hash of each cell's inputs.

A **grid** is what a show asks for, per lens (docs/characterize.md):

* focus marks in mm **from the film plane** (docs/conventions.md; infinity allowed). Written
  ``NEAR:FAR:N`` it means N marks from NEAR to FAR **spaced evenly in 1/distance** (dioptres):
  ``0.5m:inf:8`` is 1/d = 2, 12/7, 10/7, ... 2/7, 0 per metre, i.e. 0.5, 0.583, 0.7, 0.875,
  1.167, 1.75, 3.5 m and infinity. Even steps in 1/d are even steps of the focus ring's travel
  (and of depth of field) far better than even metres. A comma list (``1m,2m,inf``) is taken as is;
* f-numbers (geometric N, docs/conventions.md);
* ``fields``: the number of field positions from the frame centre (0) to its corner (1) along the
  diagonal, evenly in image height;
* wavelengths in nm (default: the lens's design wavelength);
* ray counts and resolutions: rays per PSF kernel, PSF kernel pixels, rays per side of the
  illumination grid, ST-map frame size.

The grid is split into **cells**, each one independent task with one result (:mod:`.cells`):

| kind | one per | result |
| --- | --- | --- |
| ``lens`` | lens | breathing (real and paraxial) and pupil positions at every focus and f-stop (JSON) |
| ``distortion`` | focus x wavelength | ST-maps (EXR) and fitted Brown-Conrady, 3DE4 and USD models (JSON) |
| ``illumination`` | focus x f-stop | relative illumination at the field angles (JSON) |
| ``psf`` | focus x f-stop x field x wavelength | the PSF kernel of a point at the focus distance (NPZ) |

Each cell's **input hash** (SHA-256) covers the lens prescription (its physcam TOML text), the
cell's parameters, every setting its computation reads and the physcam version; its result file
name carries the first 16 hex digits, so a changed lens or setting is a new cell and an old
result is never taken for a new one.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from dataclasses import dataclass, replace
from dataclasses import field as _dc_field

from ..data.default_sensor import DEFAULT_SENSOR_MM
from ..errors import InputError, require_positive, require_type
from ..units import parse_distance

__all__ = [
    "Grid", "Cell", "KINDS", "MAX_CELLS", "MAX_FOCUS_MARKS", "parse_focus_marks", "parse_numbers",
    "build_cells", "lens_hash", "lens_slug", "focus_label",
]

KINDS = ("lens", "distortion", "illumination", "psf")
#: Cells a run may have unless forced (``--force-large``); past :data:`HARD_MAX_CELLS` never.
MAX_CELLS = 2000
HARD_MAX_CELLS = 200_000
#: Traced rays (PSF rays x PSF cells + illumination grid^2 x fields x illumination cells) unless forced.
MAX_RAYS = 2.0e10
MAX_FOCUS_MARKS = 64
MAX_FSTOPS = 32
MAX_FIELDS = 64
MAX_WAVELENGTHS = 16
#: A point "at infinity" for the PSF of a lens focused at infinity stands this far from the film
#: (1 km): its image lies f^2 / 1e6 mm behind the focus (2.5 um for 50 mm), far below a pixel.
PSF_INFINITY_STANDIN_MM = 1.0e6


def parse_focus_marks(text) -> tuple[float, ...]:
    """``NEAR:FAR:N`` (N marks evenly in 1/distance, FAR may be ``inf``) or a comma list; mm from the film."""
    if not isinstance(text, str):
        raise InputError(f"focus marks are text such as 0.5m:inf:8 or 1m,2m,inf, got {text!r}")
    s = text.strip()
    if not s:
        raise InputError("give at least one focus mark (e.g. 0.5m:inf:8 or 1m,2m,inf): the grid is empty")
    if ":" in s:
        parts = [p.strip() for p in s.split(":")]
        if len(parts) != 3:
            raise InputError(f"a focus range is NEAR:FAR:COUNT (e.g. 0.5m:inf:8), got {text!r}")
        near = parse_distance(parts[0], name="nearest focus mark")
        far = parse_distance(parts[1], name="farthest focus mark", allow_inf=True)
        try:
            n = int(parts[2])
        except ValueError:
            raise InputError(f"the focus count in {text!r} must be a whole number, got {parts[2]!r}") from None
        if not 1 <= n <= MAX_FOCUS_MARKS:
            raise InputError(f"give 1 to {MAX_FOCUS_MARKS} focus marks, got {n}")
        if not (near > 0 and far > near):
            raise InputError(f"a focus range needs 0 < NEAR < FAR, got {text!r}")
        if n == 1:
            return (near,)
        a, b = 1.0 / near, (0.0 if math.isinf(far) else 1.0 / far)
        inv = [a + (b - a) * i / (n - 1) for i in range(n)]
        marks = tuple(math.inf if v <= 0.0 else 1.0 / v for v in inv)
        return marks[:-1] + (far,)  # the far end exactly as given
    marks = []
    for t in s.split(","):
        if t.strip():
            marks.append(parse_distance(t.strip(), name="focus mark", allow_inf=True))
    return _checked_marks(marks)


def _checked_marks(marks) -> tuple[float, ...]:
    out = []
    for m in marks:
        m = float(m)
        if math.isnan(m) or m <= 0:
            raise InputError(f"a focus mark is a positive distance from the film plane, got {m!r}")
        out.append(m)
    if not out:
        raise InputError("give at least one focus mark (e.g. 0.5m:inf:8 or 1m,2m,inf): the grid is empty")
    if len(out) > MAX_FOCUS_MARKS:
        raise InputError(f"give 1 to {MAX_FOCUS_MARKS} focus marks, got {len(out)}")
    if len(set(out)) != len(out):
        raise InputError("the focus marks repeat a distance")
    return tuple(out)


def parse_numbers(text, name: str, *, lo: float, hi: float, most: int) -> tuple[float, ...]:
    """Comma-separated numbers within [lo, hi], at most ``most``, no repeats (an empty list is refused)."""
    if not isinstance(text, str):
        raise InputError(f"{name} are comma-separated numbers, got {text!r}")
    out = []
    for t in text.split(","):
        t = t.strip()
        if not t:
            continue
        try:
            v = float(t)
        except ValueError:
            raise InputError(f"{name}: {t!r} is not a number") from None
        if not (math.isfinite(v) and lo <= v <= hi):
            raise InputError(f"{name} must lie between {lo:g} and {hi:g}, got {t!r}")
        out.append(v)
    if not out:
        raise InputError(f"give at least one of the {name}: the grid is empty")
    if len(out) > most:
        raise InputError(f"give at most {most} {name}, got {len(out)}")
    if len(set(out)) != len(out):
        raise InputError(f"the {name} repeat a value")
    return tuple(out)


def _whole(name, v, lo, hi) -> int:
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise InputError(f"{name} must be a whole number from {lo:,} to {hi:,}, got {v!r}")
    return v


#: The ST-map frame's width (pixels) when the grid gives no resolution; the height keeps pixels square.
DEFAULT_STMAP_WIDTH_PX = 2048


@dataclass(frozen=True)
class Grid:
    """What to measure on every lens (module notes). Lengths mm, wavelengths nm.

    ``sensor_mm``: default sensor Super 35 (24.89 x 18.66 mm), the CLI's
    (:data:`physcam.data.default_sensor.DEFAULT_SENSOR`); ``resolution`` None: the ST-map frame
    2048 pixels wide with square pixels on that sensor (:attr:`frame_px`)."""

    focus_mm: tuple[float, ...]
    fstops: tuple[float, ...]
    fields: int = 5
    wavelengths_nm: tuple[float, ...] | None = None  # None: each lens's design wavelength
    sensor_mm: tuple[float, float] = DEFAULT_SENSOR_MM  # Super 35 (24.89 x 18.66), as the CLI
    resolution: tuple[int, int] | None = None  # ST-map frame, pixels; None: 2048 wide, square pixels on the sensor
    psf_rays: int = 200_000
    psf_pixels: int = 64
    illumination_grid: int = 100
    kinds: tuple[str, ...] = KINDS
    backend: str = "auto"

    def checked(self) -> "Grid":
        """Self after range checks (an empty or absurd axis is an :class:`InputError` saying which)."""
        require_type("focus marks", self.focus_mm, (tuple, list), "mm from the film plane")
        require_type("f-stops", self.fstops, (tuple, list), "f-numbers")
        marks = _checked_marks(self.focus_mm)
        if not self.fstops:
            raise InputError("give at least one f-stop: the grid is empty")
        stops = parse_numbers(",".join(repr(float(v)) if isinstance(v, (int, float)) and not isinstance(v, bool)
                                       else str(v) for v in self.fstops), "f-stops", lo=0.5, hi=128.0,
                              most=MAX_FSTOPS)
        _whole("fields", self.fields, 1, MAX_FIELDS)
        wl = None
        if self.wavelengths_nm is not None:
            require_type("wavelengths", self.wavelengths_nm, (tuple, list), "nm")
            wl = parse_numbers(",".join(repr(float(v)) if isinstance(v, (int, float)) and not isinstance(v, bool)
                                        else str(v) for v in self.wavelengths_nm), "wavelengths (nm)", lo=300.0,
                               hi=1100.0, most=MAX_WAVELENGTHS)
        require_type("sensor", self.sensor_mm, (tuple, list), "(width, height) mm")
        if len(self.sensor_mm) != 2 or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                               and math.isfinite(v) and 1.0 <= v <= 100.0 for v in self.sensor_mm):
            raise InputError(f"the sensor is (width, height) between 1 and 100 mm, got {self.sensor_mm!r}")
        res = self.frame_px
        require_type("resolution", res, (tuple, list), "(width, height) pixels")
        if len(res) != 2:
            raise InputError(f"the ST-map resolution is (width, height) pixels, got {res!r}")
        _whole("ST-map width", res[0], 16, 8192)
        _whole("ST-map height", res[1], 16, 8192)
        _whole("rays per PSF", self.psf_rays, 1000, 10**9)
        _whole("PSF kernel pixels", self.psf_pixels, 8, 1024)
        _whole("illumination grid", self.illumination_grid, 16, 2000)
        require_type("kinds", self.kinds, (tuple, list), f"some of {', '.join(KINDS)}")
        kinds = tuple(dict.fromkeys(self.kinds))
        bad = [k for k in kinds if k not in KINDS]
        if bad or not kinds:
            raise InputError(f"cell kinds are some of {', '.join(KINDS)}, got {list(self.kinds)!r}"
                             + (": the grid is empty" if not kinds else ""))
        from ..trace.kernels import BACKENDS  # (the tracer's backends: auto, c, numba, numpy)

        if self.backend not in BACKENDS:
            raise InputError(f"backend is one of {', '.join(BACKENDS)}, got {self.backend!r}")
        return replace(self, focus_mm=marks, fstops=stops, wavelengths_nm=wl, kinds=kinds,
                       sensor_mm=(float(self.sensor_mm[0]), float(self.sensor_mm[1])), resolution=tuple(res))

    @property
    def frame_px(self) -> tuple[int, int]:
        """The ST-map frame (width, height) in pixels: ``resolution``, or 2048 wide with square pixels on the
        sensor (2048 x 1535 on Super 35) when it is None."""
        if self.resolution is not None:
            return self.resolution
        w, h = self.sensor_mm
        return DEFAULT_STMAP_WIDTH_PX, max(16, min(8192, round(DEFAULT_STMAP_WIDTH_PX * h / w)))

    def field_fractions(self) -> tuple[float, ...]:
        """Field positions as fractions of the half-diagonal: 0 (centre) .. 1 (corner)."""
        n = self.fields
        return (0.0,) if n == 1 else tuple(i / (n - 1) for i in range(n))

    def to_dict(self) -> dict:
        return {"focus_mm": [None if math.isinf(m) else m for m in self.focus_mm],
                "focus_labels": [focus_label(m) for m in self.focus_mm],
                "focus_spacing": "as given (NEAR:FAR:N spaces the marks evenly in 1/distance)",
                "fstops": list(self.fstops), "fields": self.fields, "field_fractions": list(self.field_fractions()),
                "wavelengths_nm": None if self.wavelengths_nm is None else list(self.wavelengths_nm),
                "sensor_mm": list(self.sensor_mm), "resolution": list(self.frame_px), "psf_rays": self.psf_rays,
                "psf_pixels": self.psf_pixels, "illumination_grid": self.illumination_grid, "kinds": list(self.kinds)}


def focus_label(focus_mm: float) -> str:
    """A focus mark as a file-name-safe label: ``infinity``, ``0.5833m``."""
    focus_mm = float(require_type("focus mark", focus_mm, (int, float), "mm from the film plane"))
    return "infinity" if math.isinf(focus_mm) else f"{focus_mm / 1000.0:.4g}m"


def lens_slug(name: str) -> str:
    """A lens name as a folder name (letters, digits, ``.``, ``_``, ``-``)."""
    require_type("lens name", name, str)
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._") or "lens"
    return s[:80]


def lens_hash(lens) -> str:
    """SHA-256 of the lens's physcam TOML text (its surfaces, focus groups, glass, metadata)."""
    from ..lens.formats.physcam_toml import dumps
    from ..lens.prescription import Prescription

    require_type("lens", lens, Prescription, "physcam.lens.library.load_lens(name)")
    return hashlib.sha256(dumps(lens).encode()).hexdigest()


def _json_num(v):
    if isinstance(v, float) and math.isinf(v):
        return "infinity"
    return v


@dataclass(frozen=True)
class Cell:
    """One task: a lens, a kind and its parameters (None where the kind has no such axis)."""

    lens: str  # the lens's slug (its folder)
    kind: str
    focus_mm: float | None = None
    fstop: float | None = None
    field: float | None = None  # fraction of the half-diagonal
    wavelength_nm: float | None = None
    input_hash: str = ""
    settings: dict = _dc_field(default_factory=dict, compare=False, hash=False)

    @property
    def stem(self) -> str:
        """The file name of the result without extension (parameters, then the input hash)."""
        parts = []
        if self.kind == "lens":
            parts.append("breathing_pupils")
        if self.focus_mm is not None:
            parts.append(f"focus_{focus_label(self.focus_mm)}")
        if self.fstop is not None:
            parts.append(f"f{self.fstop:g}")
        if self.field is not None:
            parts.append(f"field{self.field:.3f}")
        if self.wavelength_nm is not None:
            parts.append(f"{self.wavelength_nm:g}nm")
        return "_".join(parts) + "__" + self.input_hash[:16]

    @property
    def result_name(self) -> str:
        """Result path relative to the library folder."""
        ext = {"lens": ".json", "illumination": ".json", "psf": ".npz", "distortion": ""}[self.kind]
        return f"{self.lens}/{self.kind}/{self.stem}{ext}"

    @property
    def index_name(self) -> str:
        """The cell's row of the Parquet index, relative to the library folder."""
        return f"index/{self.lens}/{self.kind}/{self.stem}.parquet"


#: How a PSF cell's rays are sampled (physcam.analysis.defocus.bokeh): in every PSF cell's input hash
PSF_SAMPLING = "owen-scrambled-sobol-1"


def _settings(kind: str, grid: Grid, design_nm: float) -> dict:
    s = {"sensor_mm": list(grid.sensor_mm)}
    if kind == "lens":
        s.update(focus_mm=[_json_num(m) for m in grid.focus_mm], fstops=list(grid.fstops), design_nm=design_nm)
    elif kind == "distortion":
        s.update(resolution=list(grid.frame_px))
    elif kind == "illumination":
        s.update(grid=grid.illumination_grid, fields=max(grid.fields, 2))
    elif kind == "psf":
        # the ray sampling is part of the input: kernels made with another sampler (independent random
        # rays, before 2026-11-23) are not reused as if they were these
        s.update(rays=grid.psf_rays, pixels=grid.psf_pixels, infinity_standin_mm=PSF_INFINITY_STANDIN_MM,
                 sampling=PSF_SAMPLING)
    return s


def build_cells(lens_name: str, lens_digest: str, grid: Grid, design_wavelength_nm: float, version: str) -> list[Cell]:
    """Every cell of ``grid`` for one lens, each with its input hash (module notes)."""
    require_type("lens name", lens_name, str)
    require_type("lens hash", lens_digest, str)
    require_type("grid", grid, Grid, "physcam.characterize.Grid")
    require_type("version", version, str)
    design_wavelength_nm = require_positive("design wavelength", design_wavelength_nm, unit="nm")
    wls = grid.wavelengths_nm or (float(design_wavelength_nm),)
    axes = {
        "lens": [dict()],
        "distortion": [dict(focus_mm=m, wavelength_nm=w) for m in grid.focus_mm for w in wls],
        "illumination": [dict(focus_mm=m, fstop=n) for m in grid.focus_mm for n in grid.fstops],
        "psf": [dict(focus_mm=m, fstop=n, field=f, wavelength_nm=w) for m in grid.focus_mm for n in grid.fstops
                for f in grid.field_fractions() for w in wls],
    }
    cells = []
    for kind in KINDS:
        if kind not in grid.kinds:
            continue
        settings = _settings(kind, grid, float(design_wavelength_nm))
        for params in axes[kind]:
            doc = {"kind": kind, "lens": lens_digest, "version": version, "settings": settings,
                   "params": {k: _json_num(v) for k, v in sorted(params.items())}}
            h = hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()
            cells.append(Cell(lens_name, kind, input_hash=h, settings=settings, **params))
    return cells
