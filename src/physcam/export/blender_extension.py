"""The physcam Blender extension (Blender 4.2+ format, id ``physcam``): a zip that artists install.

Inside Blender's own Python (numpy, no physcam) the add-on needs only numbers, so physcam computes
them here, at build time, and the zip carries **precomputed data** (docs/blender.md says why):

- per lens, one OSL camera shader source from the template with the lens's focus table
  (:func:`physcam.export.blender_focus.focus_table_shader`): focus, f-stop, sensor and iris are shader
  parameters, so a keyframed pull renders with no rebuild; dispersion and Fresnel (on/off) are
  ``#ifdef`` blocks the add-on switches with ``#define`` lines in front of it
  (:mod:`physcam.export.blender_variant`, in the zip as ``shader_variant.py``: four variants, one copy);
- per lens, a JSON table of physcam's lens report at each focus state of that table
  (:func:`physcam.onset.report.solve_lens_report` at f/``REFERENCE_FSTOP``): EFL, best-match pinhole,
  entrance pupil, H1, CoC, and the closest focus and widest f-stop the panel checks against;
- the add-on itself (``blender_addon.py.in``, written for this project), which interpolates those
  tables for the panel's numbers and Blender's built-in camera.
"""

from __future__ import annotations

import io
import json
import math
import os
import zipfile
from importlib import resources
from pathlib import Path

from ..errors import InputError
from ..progress import FORK_LOCK, others_quiet
from ..optics.thinlens import MAX_F_NUMBER

__all__ = ["build_extension", "lens_payload", "extension_manifest", "REFERENCE_FSTOP", "REPORT_SENSOR_MM"]

#: f-number the per-focus reports are solved at (the numbers stored do not depend on it).
REFERENCE_FSTOP = 8.0
#: zlib level of the zip's deflate: 1, not the default 6. The shaders' data lines are most of the 300 MB
#: the zip holds; at 6 their deflate took about 14 of the build's CPU seconds, at 1 about 2, for a zip
#: 10 % larger (docs/performance.md, round 9).
_DEFLATE_LEVEL = 1
#: Sensor (mm) of the stored reports' CoC and field of view: full frame, the pupil table's span.
REPORT_SENSOR_MM = (36.0, 24.0)


def extension_manifest(version: str) -> str:
    """``blender_manifest.toml`` (Blender's extension format 1.0.0)."""
    return f'''schema_version = "1.0.0"
id = "physcam"
version = "{version}"
name = "physcam real lenses"
tagline = "Cycles cameras traced through real lens prescriptions"
maintainer = "physcam"
type = "add-on"
tags = ["Camera", "Render"]
blender_version_min = "4.2.0"
license = ["SPDX:Apache-2.0"]
'''


def _report_rows(lens, marks_mm) -> list[dict]:
    """The on-set numbers the panel shows, per focus state: only the report's solvers it needs (the
    lens at the mark and its pinhole; no real-ray field of view, which the panel does not show)."""
    from ..onset.solvers import field_of_view
    from ..optics.coc import circle_of_confusion
    from ..optics.lens_model import lens_model_of
    from ..optics.sensors import custom_sensor
    from ..optics.state import camera_state

    sensor, model = custom_sensor(*REPORT_SENSOR_MM), lens_model_of(lens)
    coc_mm, _ = circle_of_confusion(sensor.width_mm, sensor.height_mm, None)
    rows = []
    for m in marks_mm:
        mark = 1.0e7 if math.isinf(m) else float(m)  # the report's infinity: 10 km
        camera = camera_state(model, focus_mm=mark, fstop=REFERENCE_FSTOP, sensor=sensor)
        at = camera.at_mark
        fov = field_of_view(camera, at.h2_from_film_mm)
        rows.append({"mark_mm": mark, "efl_mm": at.focal_length_mm, "pinhole_mm": fov["pinhole_focal_length_mm"],
                     "pinhole_squeeze": fov["pinhole_squeeze"], "pupil_from_film_mm": at.pupil_from_film_mm or 0.0,
                     # an anamorphic's horizontal (X, pan) entrance pupil; a spherical lens's is the one pupil
                     "pupil_x_from_film_mm": at.pupil_x_from_film_mm or at.pupil_from_film_mm or 0.0,
                     "h1_from_film_mm": at.h1_from_film_mm, "coc_mm": coc_mm,
                     # the entrance pupil at this focus times N: EFL / (N x f-number ratio) x N
                     "pupil_diameter_x_n": at.focal_length_mm / at.n_ratio})
    return rows


def lens_payload(lens, slug: str) -> tuple[dict, dict[str, str]]:
    """(the lens's JSON table, its shader source by file name, ``{"<slug>.osl": source}``) for the zip
    (:mod:`physcam.export.blender_variant` makes the four variants of the source)."""
    from ..errors import require_type

    require_type("slug", slug, str, "the lens's name in the zip, e.g. 'dgauss_50mm'")
    from .blender_focus import focus_table, focus_table_shader

    zoom = lens.zoom is not None and not lens.is_anamorphic
    if zoom:
        import numpy as np

        from ..lens.zoom import prescription_at
        from .blender_zoom import N_ZOOM_ROWS, rows_to_geometry, zoom_focus_table

        positions = {}  # the geometry's prescriptions: the rows' positions are among them, focus states kept
        ft = zoom_focus_table(lens, positions=positions)
        rows_u = np.linspace(0.0, 1.0, N_ZOOM_ROWS)
        rows = [r for u in rows_u.tolist()
                for r in _report_rows(positions.get(u) or prescription_at(lens, u), ft.marks_mm)]
        pupil = rows_to_geometry([r["pupil_from_film_mm"] for r in rows], len(ft.marks_mm))
    else:
        ft = focus_table(lens)
        rows = _report_rows(lens, ft.marks_mm)
        pupil = [r["pupil_from_film_mm"] for r in rows]  # the camera object is the entrance pupil
    shaders = {f"{slug}.osl": focus_table_shader(ft, dispersion=None, fresnel=None, pupil_mm=pupil)}
    data = {"slug": slug, "name": lens.name, "closest_m": ft.closest_mm / 1000.0, "fstop_min": ft.fstop_min,
            "fstop_open": ft.fstop_open, "fstop_max": MAX_F_NUMBER,
            # the focus axis (blender_focus.FocusAxis): the add-on finds a mark's rows as the shader does
            "focus_axis": {"closest_m": ft.axis.closest_mm / 1000.0, "s_near": ft.axis.s_near},
            "anamorphic": bool(lens.is_anamorphic),
            "report_fstop": REFERENCE_FSTOP, "report_sensor_mm": list(REPORT_SENSOR_MM),
            "focus_object": _focus_object_fits(rows[:len(ft.marks_mm)]),
            "rows": rows}
    if zoom:  # rows: one block of focus states per geometry zoom position (u major), as the shader's
        z = ft.zoom
        lo, hi = z.range_mm
        data["zoom"] = {"rows_u": rows_u.tolist(), "n_focus": len(ft.marks_mm),
                        "efl_mm": z.efl_u_mm.tolist(), "range_mm": [lo, hi],
                        "default_mm": float(z.efl_u_mm[0])}  # the first position: inside the range, exactly
    return data, shaders


def _focus_object_fits(rows) -> dict:
    """What Focus on Object's drivers evaluate (no table lookup fits in a driver's simple expression):
    with D the object's distance from the entrance pupil (m), the pupil's distance from the film
    (m) and the best-match pinhole (mm) as a + b / (D + c), fitted to the report's rows (Newton: a
    lens that focuses as a whole moves its film by f^2 / x, x the object's distance from the front
    focal point, so the form is exact for it; the internal-focus lenses bundled fit within 0.02 mm).
    ``d_min_m``: D at the closest focus."""
    import numpy as np

    mark = np.array([r["mark_mm"] for r in rows]) / 1000.0
    pupil = np.array([r["pupil_from_film_mm"] for r in rows]) / 1000.0
    d = mark - pupil
    out = {"d_min_m": float(d.min())}
    for key, y in (("pupil_m", pupil), ("pinhole_mm", np.array([r["pinhole_mm"] for r in rows]))):
        def err(cs):  # per c of cs, the worst residual of the least-squares line in w = 1 / (D + c), all at once
            w = 1.0 / (d[None, :] + cs[:, None])
            wc = w - w.mean(axis=1, keepdims=True)
            slope = (wc @ (y - y.mean())) / np.einsum("ij,ij->i", wc, wc)
            return np.abs(slope[:, None] * wc + y.mean() - y).max(axis=1)

        lo, hi = -0.99 * d.min(), 10.0 * max(d.min(), 0.1)
        for _ in range(5):  # a scan, refined about its best four times
            cs = np.linspace(lo, hi, 101)
            best = int(np.argmin(err(cs)))
            lo, hi = cs[max(best - 1, 0)], cs[min(best + 1, cs.size - 1)]
        c = float(cs[best])
        b, a = np.polyfit(1.0 / (d + c), y, 1)
        out[key] = [float(a), float(b), c]
    return out


def _sensor_presets() -> list[dict]:
    """physcam's whole sensor table (``physcam sensors``): the pupil table reaches the largest's corner."""
    from ..optics.sensors import sensors

    return [{"name": s.name, "width_mm": s.width_mm, "height_mm": s.height_mm} for s in sensors()]


def _limits() -> dict:
    """The sensor the add-on accepts at most: the pupil table's reach (physcam's largest sensor)."""
    from ..optics.sensors import sensors
    from .blender_pupil import RADIAL_MAX_MM

    largest = max(sensors(), key=lambda s: math.hypot(s.width_mm, s.height_mm))
    return {"sensor_half_diagonal_max_mm": RADIAL_MAX_MM, "sensor_largest": largest.name}


def _addon_source(name: str = "blender_addon.py.in") -> str:
    """The text of a file of this package (the add-on's template, or a module the add-on imports)."""
    return resources.files(__package__).joinpath(name).read_text(encoding="utf-8")


def _payload_job(name) -> tuple[str, str, dict, dict[str, str]]:
    """One lens's part of the zip, in a worker process: (slug, lens name, JSON table, shader source)."""
    from ..lens.library import load_lens

    lens = load_lens(name)
    slug = Path(str(name)).stem
    data, shaders = lens_payload(lens, slug)
    return slug, lens.name, data, shaders


def _worker_start(trace_threads: int) -> None:
    """A worker process's start: the compiled kernels' large batches on ``trace_threads`` threads
    (:func:`physcam.trace.kernels.set_threads`; the rays are the same on any number)."""
    from ..trace.kernels import set_threads

    set_threads(trace_threads)


def _forks() -> bool:
    """Whether the workers are forks of this process: in the ``physcam`` program (:data:`physcam._program.RUNNING`,
    never a library caller, whose threads and libraries a fork would copy mid-flight) on Linux, with no other
    thread running but quiet ones (the program's progress timer while it waits: :func:`physcam.progress.quiet_thread`;
    the caller holds :data:`physcam.progress.FORK_LOCK` until the workers have started); the modules a lens's
    tables need and the compiled C kernel (with its rim pass) are then loaded here first, once, for every worker.
    Numba is not: "auto" rents the C kernel for a lens's tables, and their rims take the C pass
    (:func:`physcam.trace.kernels.rim_pass`), as fast as numba's without its 0.35-0.45 s load (docs/performance.md,
    round 22)."""
    import sys

    from .. import _program

    if not (_program.RUNNING and sys.platform.startswith("linux") and others_quiet()):
        return False
    # what a lens's tables import (a worker's first lens imported them itself: 0.06 s each)
    from ..analysis.image_quality import ghosts  # noqa: F401
    from ..lens import library  # noqa: F401
    from ..onset import solvers  # noqa: F401
    from ..optics import coc, focusing  # noqa: F401
    from ..trace import camera_tracer, kernels, pupil_bounds, rays, trace  # noqa: F401
    from . import blender_focus, blender_pupil, blender_zoom  # noqa: F401

    kernels.c_available()  # the C kernel's module, where built
    return others_quiet()


def _payloads(names, workers: int):
    """Each lens's ``_payload_job`` in the order of ``names``, computed by ``workers`` processes.

    A lens's payload is mostly Python (the pupil tables' searches), so threads would share one core;
    processes take one lens each, as ``physcam characterize`` does with its cells: fresh ones (``spawn``: no
    JIT state or trace threads copied), or in the ``physcam`` program on Linux forks of it (:func:`_forks`),
    which start with the tables' modules loaded and end without the interpreter's teardown:
    0.6-0.8 CPU seconds less a worker (docs/performance.md, round 21). One worker computes here, in order.
    The workers share the cores: each traces its large batches on cores / workers threads (one on two
    cores with two workers), not on every core, which made two workers' four threads wait for two cores."""
    if workers <= 1 or len(names) <= 1:
        yield from map(_payload_job, names)
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    n = min(workers, len(names))
    with FORK_LOCK:  # no display thread starts drawing while the workers start (physcam.progress)
        context = multiprocessing.get_context("fork" if _forks() else "spawn")
        pool = ProcessPoolExecutor(max_workers=n, mp_context=context, initializer=_worker_start,
                                   initargs=(max(1, (os.cpu_count() or 1) // n),))
        try:
            results = pool.map(_payload_job, names)  # every lens submitted: the workers have started
        except BaseException:
            pool.shutdown(cancel_futures=True)
            raise
    with pool:
        yield from results  # in order; a lens's error is raised here, as its own class


def build_extension(out_dir, *, lenses=None, force: bool = False, progress=None, workers: int | None = 1) -> Path:
    """Write ``out_dir/physcam-<version>.zip`` (module notes) through :func:`physcam.io.atomic_write`.
    ``lenses``: bundled slugs or lens files physcam reads (default: every bundled lens). ``workers``:
    processes computing the lenses' tables at once (``None``: one per core, the CLI's default); the zip
    is the same whatever the number. More than one starts fresh Python processes that import the
    calling script: call it from a script under ``if __name__ == "__main__":``."""
    from .. import __version__
    from ..errors import require_type
    from ..io import atomic_write, check_writable
    from ..lens.library import list_lenses, load_lens

    if workers is not None:
        require_type("workers", workers, int, "a whole number of processes, e.g. 2")
        if isinstance(workers, bool) or not 1 <= workers <= 256:
            raise InputError(f"workers must be a whole number from 1 to 256, got {workers!r}")
    out = Path(out_dir) / f"physcam-{__version__}.zip"
    check_writable(out, force=force)
    names = [r.slug for r in list_lenses()] if lenses is None else list(lenses)
    if not names:
        raise InputError("the extension needs at least one lens")
    for name in names:  # every lens read before any table is computed: a bad file fails in a second
        load_lens(name)
    buf = io.BytesIO()
    index = []
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED, compresslevel=_DEFLATE_LEVEL) as z:
        z.writestr("blender_manifest.toml", extension_manifest(__version__))
        z.writestr("__init__.py", _addon_source())
        z.writestr("shader_variant.py", _addon_source("blender_variant.py"))
        for slug, lens_name, data, shaders in _payloads(names, workers or os.cpu_count() or 1):
            z.writestr(f"lenses/{slug}.json", json.dumps(data))
            for fname, text in shaders.items():
                z.writestr(f"shaders/{fname}", text)
            index.append({"slug": slug, "name": lens_name})
            if progress:
                progress(slug)
        z.writestr("lenses/index.json", json.dumps(index))
        z.writestr("sensors.json", json.dumps(_sensor_presets()))
        z.writestr("limits.json", json.dumps(_limits()))
    return atomic_write(out, buf.getvalue(), force=force)
