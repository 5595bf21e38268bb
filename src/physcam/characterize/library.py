"""A lens's USD file in the library: one ``characterization`` variant per run that recorded new values.

After a lens's grid is complete, :func:`lens_usd_update` gathers the measured data from the cells'
result files and adds them to ``LIBRARY/LENS/LENS.usda`` as a variant named by the run id, through
:func:`physcam.usd.kit.add_characterization` (which makes ``current`` a copy of it, as the
proposal's "Interesting Looking Models" use case asks). The variant holds, on ``/Lens``:

* the lens as a PhysicalCamera lens (the best-match pinhole of :func:`physcam.usd.kit.best_match_pinhole`
  at the farthest finite focus mark of the grid, 1 km when the grid has only infinity, at the
  widest f-stop of the grid);
* ``physcam:characterization:*`` arrays, one value per focus mark in the grid's order:
  ``focusDioptres`` (1000 / mark in mm, 0 = infinity: no infinite value is written) and
  ``focusLabels`` (``0.5m``, ``infinity``); from the ``lens`` cell: ``effectiveFocalLengths``, ``pinholeFocalLengths``,
  ``entrancePupilDistances``, ``exitPupilDistances`` (mm in front of the film plane),
  ``hfovRealDeg``, ``hfovParaxialDeg``, ``hfovChangeRealPct`` (breathing); from the ``distortion``
  cells at the wavelength nearest the lens's design wavelength: ``distortionK1``, ``distortionK2``
  (Hydra lensDistortion "standard", docs/distortion.md), ``distortionFitMaxResidualPx``,
  ``distortionMaxPx``, and ``stmapDistortionFiles``, ``stmapUndistortionFiles`` (relative to the
  lens file); ``run``, ``date``, ``gridHash``, ``physcamVersion``, ``indexFolder``.

A variant whose ``gridHash`` (SHA-256 of the sorted input hashes of the lens's cells) equals this
grid's is "nothing new recorded": no second variant is added for the same measurements.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from pathlib import Path

from .cells import cell_lock
from .grid import PSF_INFINITY_STANDIN_MM, focus_label

__all__ = ["lens_usd_update", "lens_usd_path", "grid_hash"]


def lens_usd_path(output, slug: str) -> Path:
    """Where a lens's USD file lives in the library folder ``output``."""
    from ..errors import require_type

    require_type("output", output, (str, Path), "the library folder")
    require_type("lens slug", slug, str, "the lens's folder name")
    return Path(output) / slug / f"{slug}.usda"


def grid_hash(cells) -> str:
    """SHA-256 of the sorted input hashes of ``cells`` (one lens's grid)."""
    from ..errors import require_type

    from .grid import Cell

    require_type("cells", cells, (list, tuple), "the lens's cells")
    for c in cells:
        require_type("cell", c, Cell, "physcam.characterize.build_cells")
    return hashlib.sha256("\n".join(sorted(c.input_hash for c in cells)).encode()).hexdigest()


def _measured(rx, slug, cells, grid, out: Path, run_id: str, version: str, usd_file: Path) -> dict:
    by_kind = {}
    for c in cells:
        by_kind.setdefault(c.kind, []).append(c)
    marks = list(grid.focus_mm)
    m = {"focusDioptres": [0.0 if math.isinf(f) else 1000.0 / f for f in marks],
         "focusLabels": [focus_label(f) for f in marks],
         "run": run_id, "date": time.strftime("%Y-%m-%d", time.gmtime()), "gridHash": grid_hash(cells),
         "physcamVersion": version, "indexFolder": os.path.relpath(out / "index", usd_file.parent),
         "sensorMm": list(grid.sensor_mm)}
    if "lens" in by_kind:
        doc = json.loads((out / by_kind["lens"][0].result_name).read_text())
        rows = doc["rows"]
        for key, name in (("efl_mm", "effectiveFocalLengths"), ("pinhole_focal_length_mm", "pinholeFocalLengths"),
                          ("entrance_pupil_from_film_mm", "entrancePupilDistances"),
                          ("exit_pupil_from_film_mm", "exitPupilDistances"), ("hfov_real_deg", "hfovRealDeg"),
                          ("hfov_paraxial_deg", "hfovParaxialDeg"), ("hfov_change_real_pct", "hfovChangeRealPct")):
            vals = [r.get(key) for r in rows]
            if all(isinstance(v, (int, float)) and math.isfinite(v) for v in vals):
                m[name] = vals
    if "distortion" in by_kind:
        wls = sorted({c.wavelength_nm for c in by_kind["distortion"]}, key=lambda w: abs(w - rx.wavelength_nm))
        chosen = {c.focus_mm: c for c in by_kind["distortion"] if c.wavelength_nm == wls[0]}
        k1, k2, res, dmax, dfiles, ufiles = [], [], [], [], [], []
        for f in marks:
            c = chosen[f]
            doc = json.loads((out / c.result_name / "fits.json").read_text())
            usd = next(x for x in doc["fits"] if x["model"].startswith("USD"))
            k1.append(usd["coefficients"]["k1"])
            k2.append(usd["coefficients"]["k2"])
            res.append(usd["residual_px"]["max"])
            dmax.append(doc["field"]["max_distortion_px"])
            folder = os.path.relpath(out / c.result_name, usd_file.parent)
            dfiles.append(f"{folder}/distortion.exr")
            ufiles.append(f"{folder}/undistortion.exr")
        m.update(distortionK1=k1, distortionK2=k2, distortionFitMaxResidualPx=res, distortionMaxPx=dmax,
                 distortionWavelengthNm=str(wls[0]), stmapDistortionFiles=dfiles, stmapUndistortionFiles=ufiles)
    return m


def lens_usd_update(rx, slug: str, cells, grid, output, run_id: str) -> dict | None:
    """Add this run's variant to the lens's USD file (module notes); None when a variant of the same grid exists.

    Runs under a file lock on the lens file, so two runs finishing together both land (one after
    the other) instead of one overwriting the other's variant. Returns ``{"lens", "file",
    "variant", "variants"}``.
    """
    from .. import __version__
    from ..errors import require_type
    from ..lens.prescription import Prescription
    from ..usd.kit import add_characterization, best_match_pinhole, read_characterizations

    require_type("lens", rx, Prescription, "the lens's Prescription")
    require_type("run id", run_id, str, "run_YYYYmmddTHHMMSSZ_xxxxxx")
    out = Path(output)
    usd_file = lens_usd_path(out, slug)
    gh = grid_hash(cells)
    with cell_lock(out / ".locks" / slug / "usd.lock"):
        if usd_file.is_file():
            known = read_characterizations(usd_file)["variants"]
            if any(v.get("gridHash") == gh for name, v in known.items() if name != "current"):
                return None
        finite = [f for f in grid.focus_mm if math.isfinite(f)]
        spec, _ = best_match_pinhole(rx, focus_mm=max(finite) if finite else PSF_INFINITY_STANDIN_MM,
                                     fstop=min(grid.fstops), sensor_width_mm=grid.sensor_mm[0],
                                     sensor_height_mm=grid.sensor_mm[1])
        measured = _measured(rx, slug, cells, grid, out, run_id, __version__, usd_file)
        add_characterization(usd_file, run_id, spec, measured)
        names = [n for n in read_characterizations(usd_file)["variants"] if n != "current"]
    return {"lens": slug, "file": str(usd_file), "variant": run_id, "variants": names}
