"""One cell of the grid: compute it with physcam's analyses, write its result and its index row.

:func:`run_cell` makes one cell; :func:`run_cells`, the Dask task, makes a few (a lens's light
cells share one task: :func:`physcam.characterize.run.task_groups`). In a worker process, for one
cell:

1. if the cell's row is in the index already (another run made it), nothing;
2. take the cell's **lock** (``fcntl.flock``, or ``msvcrt.locking`` without fcntl, on ``.locks/...``,
   released by the kernel when the process dies, so a killed worker never leaves a stale lock): a
   second run into the same
   folder waits for the cell instead of computing it twice, then finds it done;
3. compute (the analyses below; no optics is re-implemented here);
4. write the result **atomically** (:func:`physcam.io.atomic_write`: a temporary file, then a
   no-clobber link; a folder of ST-maps is written whole by :func:`physcam.io.staged_folder`, with its
   manifest, and a killed attempt's temporary folder is removed by the next attempt);
   a complete result left by a run killed before step 5 is kept and reused, since its name
   carries the cell's input hash;
5. write the cell's **row** of the Parquet index, atomically, last. A cell counts as done only
   when its row exists, so a run killed at any point loses at most the cells in flight.

What each kind computes (lengths mm from the film plane, docs/conventions.md):

* ``lens``: :func:`physcam.analysis.framing.breathing_real.real_breathing` over the focus marks and, at
  every mark and f-stop, :func:`physcam.optics.focusing.technical_planes` (EFL, principal planes,
  entrance and exit pupils in front of the film, the best-match pinhole, pupil diameter,
  working f-number).
* ``distortion``: :func:`physcam.analysis.distortion.stmap.distortion_field` at the mark and wavelength, its
  ST-maps by :func:`physcam.analysis.distortion.stmap.write_stmaps` (EXR and PNG previews), and
  :func:`physcam.analysis.distortion.models.fit_models` (Brown-Conrady D-U and U-D, 3DE4 Radial -
  Standard Degree 4, USD lensDistortion) with their residuals, in ``fits.json``.
* ``illumination``: :func:`physcam.analysis.image_quality.illumination.relative_illumination` of the lens focused
  at the mark (:func:`physcam.optics.focusing.focus`) and stopped down to the f-number
  (the iris of :func:`physcam.optics.state.camera_state`, by the one rule), fields from the axis to the
  sensor corner.
* ``psf``: :func:`physcam.analysis.defocus.bokeh.bokeh_image` of a point light at the focus distance (a
  point 1 km away stands for infinity), placed so that the best-match pinhole at that focus images
  it at the film point (k w/2, k h/2), k the field fraction (lens-space film coordinates: the upright
  picture is the film turned by 180 degrees, so this is toward the picture's bottom-left corner);
  the kernel (normalised to sum 1) with its extent on the film in an NPZ. The real image lies
  off that point by the lens's distortion: the kernel's centroid says where.
"""

from __future__ import annotations

import functools
import hashlib
import io
import json
import math
import os
import socket
import time
from pathlib import Path

from ..errors import ExportError, OpticsError, PhysCamError, require_type
from .grid import PSF_INFINITY_STANDIN_MM, Cell, Grid, focus_label

__all__ = ["run_cell", "run_cells", "compute_cell", "INDEX_SCHEMA_FIELDS", "read_row", "cell_lock"]

#: Columns of the Parquet index (one row per cell; None where a kind has no such axis). ``zoom_encoder`` and
#: ``zoom_focal_length_mm``: a zoom lens's position (``characterize --zoom``; None for a prime), its encoder
#: value 0..1 and the paraxial EFL there at infinity focus (mm).
INDEX_SCHEMA_FIELDS = (
    ("lens", "string"), ("lens_hash", "string"), ("zoom_encoder", "float64"), ("zoom_focal_length_mm", "float64"),
    ("kind", "string"),
    ("focus_mm", "float64"), ("focus_label", "string"), ("fstop", "float64"), ("field", "float64"),
    ("field_x_mm", "float64"), ("field_y_mm", "float64"), ("wavelength_nm", "float64"),
    ("settings", "string"), ("file", "string"), ("content_hash", "string"), ("input_hash", "string"),
    ("physcam_version", "string"), ("run_id", "string"), ("created_utc", "string"), ("compute_s", "float64"),
    ("worker", "string"),
)


def zoom_columns(lens) -> dict:
    """The index's zoom columns of ``lens``: the encoder value a zoom lens's position was taken at
    (:data:`physcam.lens.zoom.ZOOM_ENCODER_KEY` in its extras, kept by its TOML) and the paraxial EFL there;
    both None for a lens that is not a zoom position."""
    from ..lens.zoom import ZOOM_ENCODER_KEY

    raw = dict(lens.extras).get(ZOOM_ENCODER_KEY)
    if raw is None:
        return {"zoom_encoder": None, "zoom_focal_length_mm": None}
    from ..optics.paraxial import gaussian

    return {"zoom_encoder": float(json.loads(raw)), "zoom_focal_length_mm": gaussian(lens).efl}


def _schema():
    import pyarrow as pa

    return pa.schema([(n, getattr(pa, t)()) for n, t in INDEX_SCHEMA_FIELDS])


@functools.lru_cache(maxsize=16)
def _lens(toml_text: str):
    from ..lens.formats.physcam_toml import loads

    return loads(toml_text)


def _none_inf(v):
    return None if v is None or (isinstance(v, float) and math.isinf(v)) else v


# ------------------------------------------------------------------------------------------- kinds
def _lens_cell(lens, grid: Grid):
    from ..analysis.framing.breathing_real import real_breathing
    from ..optics.focusing import technical_planes

    w, h = grid.sensor_mm
    br = real_breathing(lens, list(grid.focus_mm), sensor_width_mm=w, sensor_height_mm=h, backend=grid.backend)
    rows = []
    for m, b in zip(grid.focus_mm, br.rows):
        tp = technical_planes(lens, m)
        row = {"focus_from_film_mm": _none_inf(m), "focus_label": focus_label(m),
               "efl_mm": tp.efl_mm, "h1_from_film_mm": tp.h1_from_film_mm, "h2_from_film_mm": tp.h2_from_film_mm,
               "entrance_pupil_from_film_mm": tp.entrance_pupil_from_film_mm,
               "exit_pupil_from_film_mm": tp.exit_pupil_from_film_mm,
               "stop_from_film_mm": tp.stop_from_film_mm, "front_vertex_from_film_mm": tp.front_vertex_from_film_mm,
               "back_focus_mm": tp.back_focus_mm, "magnification": tp.magnification,
               "pinhole_focal_length_mm": tp.pinhole_focal_length_mm,
               "hfov_paraxial_deg": b.hfov_paraxial_deg, "hfov_real_deg": b.hfov_real_deg,
               "dfov_real_deg": b.dfov_real_deg, "hfov_change_real_pct": b.change_real_pct,
               "fstops": []}
        for n in grid.fstops:
            tn = technical_planes(lens, m, fstop=n)
            row["fstops"].append({"fstop": n, "entrance_pupil_diameter_mm": tn.entrance_pupil_diameter_mm,
                                  "working_f_number": tn.working_f_number})
        rows.append(row)
    doc = {"lens": lens.name, "kind": "lens", "sensor_mm": list(grid.sensor_mm), "wavelength_nm": br.wavelength_nm,
           "focus_method": br.method, "rows": rows,
           "conventions": "distances in mm in front of the film plane (+ toward the subject); focus null = "
                          "infinity; angles in degrees; breathing change relative to the first mark"}
    return _json_bytes(doc), {}


def _distortion_cell(lens, grid: Grid, cell: Cell, dest: Path):
    from ..analysis.distortion.models import fit_models, samples_from_field
    from ..analysis.distortion.stmap import distortion_field, write_stmaps
    from ..io import atomic_write, staged_folder
    from ..optics.state import camera_state

    if dest.is_dir() and (dest / "fits.json").is_file():  # published by an earlier, killed attempt
        return (dest / "fits.json").read_bytes()
    w, h = grid.sensor_mm
    res = distortion_field(camera_state(lens, focus_mm=cell.focus_mm, sensor_mm=(w, h)),
                           width_px=grid.frame_px[0], height_px=grid.frame_px[1],
                           wavelength_nm=cell.wavelength_nm, backend=grid.backend)
    fits = fit_models(samples_from_field(res))
    try:  # the folder is published whole (a killed attempt's temporary is removed by the next one)
        with staged_folder(dest, about={"kind": "distortion", "cell": dest.name}) as tmp:
            files = write_stmaps(res, tmp)
            doc = {"lens": lens.name, "kind": "distortion", "field": res.to_dict(),
                   "fits": [f.to_dict() for f in fits],
                   "files": {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in files}}
            atomic_write(tmp / "fits.json", _json_bytes(doc))
    except ExportError:
        if not (dest / "fits.json").is_file():  # not another attempt that published first
            raise
    return (dest / "fits.json").read_bytes()


def _illumination_cell(lens, grid: Grid, cell: Cell):
    from ..analysis.image_quality.illumination import relative_illumination
    from ..optics.state import camera_state

    st = camera_state(lens, focus_mm=cell.focus_mm, fstop=cell.fstop, sensor_mm=tuple(grid.sensor_mm))
    sd = st.stop_semi_diameter
    res = relative_illumination(st, n_fields=max(grid.fields, 2), grid=grid.illumination_grid, backend=grid.backend)
    doc = res.to_dict() | {"kind": "illumination", "focus_from_film_mm": _none_inf(cell.focus_mm),
                           "fstop": cell.fstop, "stop_semi_diameter_mm": sd}
    return _json_bytes(doc), {}


def psf_light_position(lens, grid: Grid, cell: Cell):
    """(focus state, depth of the light from the film mm, light x, y mm in lens space, film target x, y mm)."""
    _check(lens, grid, cell)
    from ..optics.focusing import focus
    from ..optics.paraxial import gaussian

    st = focus(lens, cell.focus_mm)
    depth = PSF_INFINITY_STANDIN_MM if math.isinf(cell.focus_mm) else float(cell.focus_mm)
    z_obj = st.film_z - depth
    # the film target along the diagonal; the light where the best-match pinhole at this focus
    # (entrance pupil, focal length f_pin per meridian) images it: X = -x_film (z_ep - z_obj) / f_pin
    fx, fy = 0.5 * grid.sensor_mm[0] * cell.field, 0.5 * grid.sensor_mm[1] * cell.field
    pos = []
    for a, t in (("x", fx), ("y", fy)):
        g = gaussian(st.prescription, axis=a, object_z=z_obj, film_z=st.film_z)
        if g.pinhole_focal_length is None:
            raise OpticsError(f"lens {lens.name!r} has no best-match pinhole at this focus")
        pos.append(-t * (g.z_entrance_pupil - z_obj) / g.pinhole_focal_length)
    return st, depth, pos[0], pos[1], fx, fy


def _psf_cell(lens, grid: Grid, cell: Cell):
    import numpy as np

    from ..analysis.defocus.bokeh import bokeh_image
    from ..optics.state import camera_state

    st, depth, x, y, fx, fy = psf_light_position(lens, grid, cell)
    # the lens at the cell's focus (its film there), its iris at the cell's f-stop, in the cell's light
    cam = camera_state(lens, focus_mm=cell.focus_mm, fstop=cell.fstop, wavelengths_nm=[float(cell.wavelength_nm)])
    img = bokeh_image(cam, depth, x, y, rays=grid.psf_rays, pixels=grid.psf_pixels,
                      chunk=max(1000, min(grid.psf_rays, 1_000_000)), backend=grid.backend)
    e = img.image[..., 0]
    total = float(e.sum())
    if not (total > 0 and math.isfinite(total)):
        raise OpticsError(f"no light of the point at field {cell.field:g} reaches the PSF window")
    d = img.to_dict()
    meta = {"lens": lens.name, "kind": "psf", "focus_from_film_mm": _none_inf(cell.focus_mm), "fstop": cell.fstop,
            "field_fraction": cell.field, "film_target_mm": [fx, fy], "light_depth_from_film_mm": depth,
            "light_xy_mm": [x, y], "wavelength_nm": cell.wavelength_nm, "extent_mm": list(img.extent_mm),
            "centroid_mm": d["centroid_mm"], "rays_traced": img.rays_traced, "rays_passed": img.rays_passed,
            "kernel": "rows bottom to top (film y up), columns film x; sums to 1",
            "film": "lens-space film coordinates x, y (mm); the upright picture is the film turned by 180 degrees"}
    buf = io.BytesIO()
    np.savez_compressed(buf, kernel=(e / total).astype(np.float32), extent_mm=np.asarray(img.extent_mm),
                        relative_flux=np.asarray(total * (img.extent_mm[1] - img.extent_mm[0])
                                                 * (img.extent_mm[3] - img.extent_mm[2]) / e.size),
                        meta=np.asarray(json.dumps(meta)))
    return buf.getvalue(), {"field_x_mm": fx, "field_y_mm": fy}


def _json_bytes(doc) -> bytes:
    return (json.dumps(doc, indent=1, allow_nan=False) + "\n").encode()


def _check(lens, grid, cell) -> None:
    from ..lens.prescription import Prescription

    require_type("lens", lens, Prescription, "physcam.lens.library.load_lens(name)")
    require_type("grid", grid, Grid, "physcam.characterize.Grid")
    require_type("cell", cell, Cell, "physcam.characterize.build_cells")


def compute_cell(lens, grid: Grid, cell: Cell, dest: Path):
    """Compute one cell; returns (bytes of its result file, extra index columns).

    A ``distortion`` cell publishes its folder ``dest`` itself and returns its ``fits.json``."""
    _check(lens, grid, cell)
    require_type("dest", dest, Path, "the result's path")
    if cell.kind == "lens":
        return _lens_cell(lens, grid)
    if cell.kind == "distortion":
        return _distortion_cell(lens, grid, cell, dest), {}
    if cell.kind == "illumination":
        return _illumination_cell(lens, grid, cell)
    if cell.kind == "psf":
        return _psf_cell(lens, grid, cell)
    raise ExportError(f"unknown cell kind {cell.kind!r}")  # pragma: no cover - the grid checks kinds


# ---------------------------------------------------------------------------------------- the task
class cell_lock:
    """An exclusive ``flock`` on ``path`` (created if missing); the kernel drops it if the process dies."""

    def __init__(self, path: Path):
        self.path = Path(require_type("lock path", path, (str, Path)))
        self.fd = None

    def __enter__(self):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        _lock_file(self.fd, True)
        return self

    def __exit__(self, *exc):
        _lock_file(self.fd, False)
        os.close(self.fd)
        return False


def _lock_file(fd: int, lock: bool) -> None:
    """Take (or release) an exclusive lock on the open file ``fd``, waiting for it: ``fcntl.flock`` on
    POSIX, ``msvcrt.locking`` of its first byte where there is no fcntl (Windows). Either is released
    by the operating system when the process dies."""
    try:
        import fcntl
    except ImportError:  # no fcntl: Windows
        import msvcrt

        os.lseek(fd, 0, os.SEEK_SET)
        msvcrt.locking(fd, msvcrt.LK_LOCK if lock else msvcrt.LK_UNLCK, 1)
        return
    fcntl.flock(fd, fcntl.LOCK_EX if lock else fcntl.LOCK_UN)


def read_row(path) -> dict:
    """One index row file as a dict."""
    require_type("row file", path, (str, Path), "a .parquet path")
    import pyarrow.parquet as pq

    try:
        return pq.read_table(path).to_pylist()[0]
    except (OSError, IndexError) as exc:
        raise ExportError(f"cannot read the index row {path}: {exc}") from None


def _row_bytes(row: dict) -> bytes:
    import pyarrow as pa
    import pyarrow.parquet as pq

    buf = io.BytesIO()
    pq.write_table(pa.Table.from_pylist([row], schema=_schema()), buf)
    return buf.getvalue()


def run_cells(lens_toml: str, lens_digest: str, cells, grid: Grid, root: str, run_id: str, version: str) -> list[dict]:
    """The Dask task: :func:`run_cell` for each of ``cells`` (one lens's), in order. An exception other
    than a :class:`~physcam.errors.PhysCamError` ends the task, and Dask's retry then finds the cells
    done before it in the index ("present")."""
    require_type("cells", cells, (list, tuple), "physcam.characterize.run.task_groups")
    return [run_cell(lens_toml, lens_digest, c, grid, root, run_id, version) for c in cells]


def run_cell(lens_toml: str, lens_digest: str, cell: Cell, grid: Grid, root: str, run_id: str, version: str) -> dict:
    """Make ``cell`` under the library folder ``root`` (module notes).

    Returns ``{"status": "computed" | "present" | "failed", "row": {...} | None, "error": str | None,
    "cell": cell}``. A :class:`~physcam.errors.PhysCamError` (the lens does not cover the corner,
    the mark is too close...) fails the cell, not the run; any other exception is raised so Dask
    retries the task.
    """
    from ..io import atomic_write

    for name, v in (("lens TOML", lens_toml), ("lens hash", lens_digest), ("root", root), ("run id", run_id),
                    ("version", version)):
        require_type(name, v, str)
    require_type("cell", cell, Cell, "physcam.characterize.build_cells")
    require_type("grid", grid, Grid, "physcam.characterize.Grid")
    base = Path(root)
    row_path = base / cell.index_name
    if row_path.is_file():
        return {"status": "present", "row": read_row(row_path), "error": None, "cell": cell}
    with cell_lock(base / ".locks" / (cell.index_name + ".lock")):
        if row_path.is_file():
            return {"status": "present", "row": read_row(row_path), "error": None, "cell": cell}
        dest = base / cell.result_name
        t0 = time.perf_counter()
        try:
            lens = _lens(lens_toml)
            if cell.kind != "distortion" and dest.is_file():
                data, extra = dest.read_bytes(), {}  # complete (written atomically) by an attempt killed after it
                if cell.kind == "psf":
                    extra = dict(zip(("field_x_mm", "field_y_mm"),
                                     psf_light_position(lens, grid, cell)[4:]))
            else:
                data, extra = compute_cell(lens, grid, cell, dest)
                if cell.kind != "distortion":
                    try:
                        atomic_write(dest, data)
                    except ExportError:
                        if not dest.is_file():
                            raise
                        data = dest.read_bytes()
        except PhysCamError as exc:
            return {"status": "failed", "row": None, "error": str(exc).splitlines()[0] if str(exc) else
                    type(exc).__name__, "cell": cell}
        seconds = time.perf_counter() - t0
        file = cell.result_name + ("/fits.json" if cell.kind == "distortion" else "")
        row = {"lens": cell.lens, "lens_hash": lens_digest, **zoom_columns(lens), "kind": cell.kind,
               "focus_mm": _none_inf(cell.focus_mm),
               "focus_label": None if cell.focus_mm is None else focus_label(cell.focus_mm),
               "fstop": cell.fstop, "field": cell.field, "field_x_mm": extra.get("field_x_mm"),
               "field_y_mm": extra.get("field_y_mm"), "wavelength_nm": cell.wavelength_nm,
               "settings": json.dumps(cell.settings, sort_keys=True), "file": file,
               "content_hash": hashlib.sha256(data).hexdigest(), "input_hash": cell.input_hash,
               "physcam_version": version, "run_id": run_id,
               "created_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "compute_s": seconds,
               "worker": f"{socket.gethostname()}:{os.getpid()}"}
        try:
            atomic_write(row_path, _row_bytes(row))
        except ExportError:
            if not row_path.is_file():
                raise
            return {"status": "present", "row": read_row(row_path), "error": None, "cell": cell}
        return {"status": "computed", "row": row, "error": None, "cell": cell}
