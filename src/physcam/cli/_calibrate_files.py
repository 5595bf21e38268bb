"""The deliverables of ``physcam calibrate`` (docs/calibrate.md): per focus mark the ST-maps, the fitted
models' files (as ``physcam distortion --fit`` writes them), an OpenTrackIO lens block (a good mark
only, with the models the run accepted), the calibration document and sheet; and the day's
characterization variant in the lens's USD file (a good calibration of that lens only).

:func:`check_outputs` checks every option, output and image header before the fit; the folder is
written as a whole (:func:`physcam.io.staged_folder`: a temporary folder, every file synced, a
manifest, one rename), so a killed run, ``--force`` or not, never leaves maps of two fits."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..analysis.distortion.stmap import DistortionField

#: Spacing (px) of the exactly computed ST-map nodes; bilinear between (the maps are smooth)
MAP_STEP_PX = 4


@dataclass
class MeasuredField(DistortionField):
    """A :class:`DistortionField` measured from a chart (its maps say so in their EXR headers): no camera
    model made it (``camera`` None), the focus mark is the one the photographs were taken at."""

    mark_mm: float = math.inf

    @property
    def focus_from_film_mm(self) -> float:
        return self.mark_mm

    @property
    def fstop(self) -> None:
        return None  # the chart's corners: no stop's centroids

    def to_dict(self) -> dict:
        d = super().to_dict()
        d["map_for"] = "a chart calibration (OpenCV Brown-Conrady, measured)"
        return d


def _coarse_then_bilinear(fn, width, height, step=MAP_STEP_PX):
    """``fn`` (n, 2) -> (n, 2) evaluated at nodes every ``step`` px of a width x height grid of pixel
    indices, then bilinear at every pixel: (height, width, 2). Separable: the node rows are interpolated
    across the frame once, then mixed down it (the same products and sums per pixel, in the same order,
    as the four-corner form; 1280 x 960: 0.16-0.37 -> 0.09 s CPU)."""
    xs = np.arange(0, width + step, step, dtype=float)
    ys = np.arange(0, height + step, step, dtype=float)
    X, Y = np.meshgrid(xs, ys)
    v = fn(np.column_stack([X.ravel(), Y.ravel()])).reshape(len(ys), len(xs), 2)
    fx, fy = np.arange(width) / step, np.arange(height) / step
    i, j = np.minimum(fx.astype(int), len(xs) - 2), np.minimum(fy.astype(int), len(ys) - 2)
    tx, ty = (fx - i)[None, :, None], (fy - j)[:, None, None]
    across = (1 - tx) * v[:, i] + tx * v[:, i + 1]  # (node rows, width, 2)
    return (1 - ty) * across[j] + ty * across[j + 1]


def measured_field(m, lens_name: str) -> MeasuredField:
    """The ST-maps of a :class:`~physcam.analysis.calibration.calibrate.MarkCalibration` (conventions of
    :mod:`physcam.analysis.distortion.stmap`: R = u, G = v from the bottom-left, rows top first)."""
    w, h = m.size_px
    edge = np.array([[x, y] for x in np.linspace(-0.5, w - 0.5, 65) for y in (-0.5, h - 0.5)]
                    + [[x, y] for y in np.linspace(-0.5, h - 0.5, 49) for x in (-0.5, w - 0.5)])
    u = m.undistort_px(edge)
    ox = max(0, (math.ceil(max(-0.5 - u[:, 0].min(), u[:, 0].max() - (w - 0.5)))))
    oy = max(0, (math.ceil(max(-0.5 - u[:, 1].min(), u[:, 1].max() - (h - 0.5)))))
    dm = _coarse_then_bilinear(m.undistort_px, w, h)  # plate pixel (col, row) -> undistorted OpenCV px
    um = _coarse_then_bilinear(lambda p: m.distort_px(p - [ox, oy]), w + 2 * ox, h + 2 * oy)
    dmap = np.dstack([(dm[..., 0] + 0.5) / w, (h - dm[..., 1] - 0.5) / h, np.zeros((h, w))]).astype(np.float32)
    umap = np.dstack([(um[..., 0] + 0.5) / w, (h - um[..., 1] - 0.5) / h,
                      np.zeros(um.shape[:2])]).astype(np.float32)
    from ..analysis.calibration.calibrate import displacement_px

    disp = np.hypot(*displacement_px(m.camera_matrix, m.distortion, m.size_px).T)
    focus = math.inf if m.mark_mm is None else float(m.mark_mm)
    return MeasuredField(lens_name, None, math.nan, tuple(m.sensor_mm), (w, h), tuple(m.focal_length_mm),
                         (math.nan, math.nan), (ox, oy), (0, 0), 0.0, math.nan, float(disp.max()),
                         (m.rms_px, max(m.view_rms_px)), dmap, umap,
                         ["measured from chart photographs; residual = the corners' reprojection residual"],
                         mark_mm=focus)


def opentrackio_lens(m) -> dict:
    """OpenTrackIO 1.0.1 ``lens`` fields of a measured mark (OpenLensIO: mm on the sensor, y down), with
    only the Brown-Conrady fits the run accepted; a mark the run calls NOT good is an OpticsError."""
    from ..analysis.distortion.models import BrownConrady
    from ..errors import OpticsError

    good, why = m.verdict
    if not good:
        raise OpticsError("the calibration is NOT good (" + "; ".join(why) + "): no OpenTrackIO lens block")
    out = {"pinholeFocalLength": float(m.focal_length_mm[1]),
           "distortion": [f.opentrackio() for f in m.fits if isinstance(f, BrownConrady) and f.acceptable],
           "projectionOffset": {"x": float(m.principal_offset_mm[0]), "y": float(-m.principal_offset_mm[1])},
           "distortionOffset": {"x": float(m.principal_offset_mm[0]), "y": float(-m.principal_offset_mm[1])}}
    if m.mark_mm is not None and math.isfinite(m.mark_mm):
        out["focusDistance"] = float(m.mark_mm) / 1000.0
    return {"lens": out}


class WritesItself:
    """A payload entry whose file is written by its own writer ``write(path, force)`` (an ST-map:
    OpenEXR writes it into the atomic write's temporary), not held as bytes."""

    def __init__(self, write):
        self.write = write


#: The units of the ``physcam calibrate --json`` document.
UNITS = {"length": "mm", "image": "pixel (OpenCV: x right, y down, pixel centres at whole numbers)",
         "focus_mark_mm": "mm from the film plane (null: not given)", "breathing": "percent",
         "uncertainty": "one standard deviation"}


def _mark_files(m, folder: Path, name: str, notes: list) -> list:
    from ..analysis.distortion.models import (
        BrownConrady,
        TDE4RadialStandard,
        USDStandard,
    )
    from ..analysis.distortion.stmap import write_map_exr, write_map_png
    from ..export.tde4 import tde4_lens_text
    from .distortion import FIT_FILES, brown_conrady_document, usd_distortion_document

    out = []
    fld = measured_field(m, name)
    said = fld.to_dict()
    attrs = {"physcamMapFor": said["map_for"], "physcamFStop": 0.0, "physcamResidualRmsPx": float(m.rms_px),
             "physcamResidualMaxPx": float(max(m.view_rms_px)), "physcamLens": name}
    for stem, rgb, over in (("distortion", fld.distortion_stmap, (0, 0)),
                            ("undistortion", fld.undistortion_stmap, fld.overscan_px)):
        # a map is written by its writer (OpenEXR into the atomic write's temporary), not held as bytes
        out += [(folder / f"{stem}.exr", WritesItself(lambda path, force, rgb=rgb, over=over:
                                                      write_map_exr(rgb, path, attrs, overscan=over, force=force))),
                (folder / f"{stem}.png", WritesItself(lambda path, force, rgb=rgb:
                                                      write_map_png(rgb, path, force=force)))]
    good = [f for f in m.fits if f.acceptable]
    notes += [f"{f.model}: not written (misses the measured field by up to {f.max_residual_px:.3g} px)"
              for f in m.fits if not f.acceptable]
    brown = [f for f in good if isinstance(f, BrownConrady)]
    if brown:
        out.append((folder / FIT_FILES["brown"], _json(brown_conrady_document(name, brown))))
    for f in good:
        if isinstance(f, TDE4RadialStandard):
            out.append((folder / FIT_FILES["3de4"], tde4_lens_text(f, name, lens_center_offset_mm=m.principal_offset_mm).encode()))
        elif isinstance(f, USDStandard):
            out.append((folder / FIT_FILES["usd"], _json(usd_distortion_document(name, f))))
    good, why = m.verdict
    if good:
        out.append((folder / "opentrackio_lens.json", _json(opentrackio_lens(m))))
    else:
        notes.append(f"{folder.name}/opentrackio_lens.json: not written (this mark's calibration is NOT good: "
                     + "; ".join(why) + ")")
    return out


def _json(doc) -> bytes:
    return (json.dumps(doc, indent=2) + "\n").encode()


def _folder(out: Path, m, several: bool) -> Path:
    if not several:
        return out
    return out / ("focus_unknown" if m.mark_mm is None else "focus_infinity" if math.isinf(m.mark_mm)
                  else f"focus_{m.mark_mm:.0f}mm")


def sensor_of(args):
    """The command line's sensor, resolved once (its note said once)."""
    from ._common import resolve_sensor

    if not hasattr(args, "_sensor_obj"):
        args._sensor_obj = resolve_sensor(args)
    return args._sensor_obj


def check_outputs(args) -> dict:
    """Every option, output and image header checked before the fit; returns the plan: the folder's
    ``force`` and the USD file's target (:func:`physcam.usd.kit.characterization_target`), or None."""
    from ..analysis.calibration.chart import check_pixels, image_files, image_size
    from ..errors import ExportError, InputError
    from ..io import MANIFEST_NAME, refuse_inputs_as_outputs

    if args.bootstrap in (1, 2) or not 0 <= args.bootstrap <= 1000:
        raise InputError(f"--bootstrap is 0 (OpenCV's covariance) or 3 to 1000 refits, got {args.bootstrap}")
    if args.variant is not None and args.usd is None:
        raise InputError("--variant names the variant added to the --usd lens file: give --usd too")
    out = Path(args.output)
    force = bool(args.force)
    refuse_inputs_as_outputs([*args.images, *(args.flat or []), args.marks, args.lens], [args.usd], folders=[out])
    if out.is_symlink() or (out.exists() and not out.is_dir()):
        raise ExportError(f"{out} exists and is not a folder: give a folder for the deliverables (-o DIR)")
    if out.is_dir():
        empty = not any(out.iterdir())
        if not empty and not force:
            raise ExportError(f"{out} exists (give --force to replace a folder physcam wrote, or a new folder)")
        if not empty and not _physcam_folder(out):
            raise ExportError(f"{out} holds files physcam did not write there; --force replaces only a folder physcam "
                              f"wrote whole (one with a {MANIFEST_NAME} listing every file) or an empty one: choose "
                              "a new output folder")
        force = True  # an empty folder, or one physcam wrote with --force: replaced whole
    first = None
    flats = [Path(f) for f in (args.flat or [])]
    for p in image_files(args.images) + flats:
        if not p.is_file():
            raise InputError(f"{p}: no such flat-field frame")
        size = image_size(p)
        check_pixels(p, *size, args.max_pixels)
        first = first or (size, p)
        if size != first[0]:
            what = "flat fields of the same camera mode" if p in flats else "images of one camera mode"
            raise InputError(f"{p}: {size[0]}x{size[1]} px, but {first[1]} is {first[0][0]}x{first[0][1]}: give {what}")
    if first is not None:  # the sensor's recorded area against the images' pixels, before the charts are looked for
        from ..analysis.calibration.calibrate import photosite_pitch

        s = sensor_of(args)
        photosite_pitch(first[0], (s.width_mm, s.height_mm))
    usd = None
    if args.usd is not None:
        import datetime as _dt

        from ..extras import require_extra

        require_extra("usd", "the lens file's characterization variant (--usd)")
        from ..usd.kit import characterization_target

        variant = args.variant or "calibration_" + _dt.datetime.now(_dt.UTC).strftime("%Y%m%d")
        usd = dict(characterization_target(args.usd, variant), file=Path(args.usd), variant=variant)
    return {"force": force, "usd": usd}


def _physcam_folder(folder: Path) -> bool:
    """Whether ``folder`` is one physcam wrote whole and nobody added to: its manifest lists every file."""
    import os

    from ..io import MANIFEST_NAME, folder_manifest

    doc = folder_manifest(folder)
    if doc is None:
        return False
    listed = {e["path"] for e in doc["files"]} | {MANIFEST_NAME}
    return all(Path(d, f).relative_to(folder).as_posix() in listed for d, _, files in os.walk(folder) for f in files)


#: a calibration goes into a lens file when its pinhole is within this factor of the file's focal length
#: (breathing: a unit-focusing lens at 1:2 is 1.5 f; internal focusing shortens it)
USD_FOCAL_FACTOR = 1.5


def _check_usd(doc: dict, usd: dict) -> None:
    """A NOT good calibration, or one of another lens, never goes into the lens file (module notes); ``doc``:
    the calibration document (``Calibration.to_dict``, as calibration.json holds it)."""
    from ..errors import ExportError

    bad = [m for m in doc["marks"] if not m["good"]]
    if bad:
        m = bad[0]
        where = "" if m["focus_mark_mm"] is None else f" at {m['focus_mark_mm']:g} mm"
        raise ExportError(f"{usd['file']}: not changed: the calibration{where} is NOT good "
                          f"({'; '.join(m['verdict_reasons'])}), and a calibration the run rejects never becomes the "
                          "lens's current one; rerun without --usd for the deliverables and the sheet")
    f_file, f = usd["focal_length_mm"], float(doc["marks"][0]["focal_length_mm"]["y"])
    if f_file is not None and not f_file / USD_FOCAL_FACTOR <= f <= f_file * USD_FOCAL_FACTOR:
        raise ExportError(f"{usd['file']}: not changed: the measured pinhole focal length {f:.4g} mm does not fit the "
                          f"file's {f_file:.4g} mm lens (a calibration of this lens is within a factor "
                          f"{USD_FOCAL_FACTOR:g} of it): check the sensor size, or give this lens's file")


def deliverables(cal, args, plan):
    """([(path in the folder, bytes or a function making them)], USD target or None), the USD checked
    against the calibration (:func:`_check_usd`)."""
    from ..analysis.calibration.sheet import calibration_sheet
    from ..figures import figure_bytes
    from ._output import document

    out = Path(args.output)
    usd = plan["usd"]
    if usd is not None:
        _check_usd(cal.to_dict(), usd)
    payload = []
    for m in cal.marks:
        payload += _mark_files(m, _folder(out, m, len(cal.marks) > 1), cal.lens_name, cal.notes)
    payload.append((out / "calibration_sheet.png", lambda: figure_bytes(calibration_sheet(cal), "png")))
    payload.append((out / "calibration.json", lambda: _json(document("calibrate", dict(cal.to_dict(), written=[]),
                                                                      units=UNITS))))
    return payload, usd


def _measured(doc: dict, out: Path, usd_file: Path) -> dict:
    """The ``physcam:characterization:*`` values of a calibration document (``Calibration.to_dict``)."""
    import os

    marks = doc["marks"]
    rel = os.path.relpath(out.resolve(), usd_file.resolve().parent)
    return {
        "source": "physcam calibrate: chart photographs",
        "focusMarksMm": [m["focus_mark_mm"] if m["focus_mark_mm"] is not None and math.isfinite(m["focus_mark_mm"])
                         else -1.0 for m in marks],
        "pinholeFocalLengthMm": [m["focal_length_mm"]["y"] for m in marks],
        "pinholeFocalLengthStdMm": [m["uncertainty"]["focal_length_mm"]["y"] for m in marks],
        "principalPointOffsetMm": [v for m in marks for v in m["principal_point_offset_mm"]],
        "opencvBrownConrady": [float(m["opencv"][k]) for m in marks for k in ("k1", "k2", "p1", "p2", "k3")],
        "residualRmsPx": [m["residual_px"]["rms"] for m in marks],
        "verdict": ["good" if m["good"] else "not good: " + "; ".join(m["verdict_reasons"]) for m in marks],
        "files": [rel],
    }


def add_calibration_variant(doc: dict, usd: dict, *, lens=None, fstop=None, output) -> Path:
    """Add the characterization variant of the calibration document ``doc`` (the payload of calibration.json,
    ``Calibration.to_dict``) to the lens file of ``usd`` (``{"file", "variant"}``): the measured pinhole (on
    ``lens``'s best-match camera at ``fstop`` when a prescription is given) and the measured numbers, the
    deliverables in the folder ``output``. ``physcam calibrate --usd`` and the farm's ``usd`` step
    (docs/farm.md) both add it so."""
    from dataclasses import replace

    from ..usd.author import CameraSpec
    from ..usd.kit import add_characterization, best_match_pinhole

    m = doc["marks"][0]
    mark = m["focus_mark_mm"]
    focus = 1.0e7 if mark is None or math.isinf(mark) else float(mark)
    f = float(m["focal_length_mm"]["y"])
    w, h = m["sensor_mm"]
    if lens is not None:
        spec, _ = best_match_pinhole(lens, focus_mm=focus, fstop=fstop, sensor_width_mm=w, sensor_height_mm=h)
        spec = replace(spec, pinhole_focal_length_mm=f)
    else:
        spec = CameraSpec.of(focal_length_mm=f, pinhole_focal_length_mm=f, focus_mm=focus, sensor_width_mm=w,
                             sensor_height_mm=h)
    return add_characterization(usd["file"], usd["variant"], spec, _measured(doc, Path(output), Path(usd["file"])))


def write_all(payload, usd, cal, args, plan) -> list:
    """Write the folder as a whole (:func:`physcam.io.staged_folder`), then the USD variant; returns the
    paths written (the files at their final places, the manifest, the lens file)."""
    from ..io import MANIFEST_NAME, atomic_write, staged_folder

    out = Path(args.output)
    written = []
    with staged_folder(out, force=plan["force"], about={"command": "physcam calibrate", "lens": cal.lens_name,
                                                        "good": cal.good}) as tmp:
        for p, data in payload:
            at = tmp / p.relative_to(out)
            if isinstance(data, WritesItself):
                data.write(at, False)
            else:
                atomic_write(at, data() if callable(data) else data)
            written.append(p)
    written.append(out / MANIFEST_NAME)
    if usd is not None:
        written.append(add_calibration_variant(cal.to_dict(), usd, lens=getattr(args, "loaded_lens", None),
                                               fstop=args.fstop, output=out))
    return written
