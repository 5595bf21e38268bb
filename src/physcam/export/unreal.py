"""An Unreal Engine Lens File (``.ulens`` JSON, Camera Calibration plugin) from a real lens.

Unreal's Camera Calibration plugin keeps a lens's calibration in a Lens File asset: tables by
focus (and zoom) of the normalised focal length (Fx, Fy), the image centre (Cx, Cy), distortion
parameters of a lens model and the nodal offset. Its importer (``LensFileImporterFactory``) reads
a JSON exchange file; docs/unreal-omniverse.md lists what each field is matched against.

Per focus mark physcam writes:

* **FocalLengthTable**: ``Fx = f_pin / sensor width``, ``Fy = f_pin_y / sensor height`` (Unreal's
  ``FFocalLengthInfo``: "If focal length is in mm, normalize using sensor dimensions"), with f_pin
  physcam's best-match pinhole at that mark (focus breathing);
* **ImageCenterTable**: ``Cx = Cy = 0.5`` (normalised; the axis meets the sensor centre);
* **DistortionTable**: ``K1, K2, K3, P1, P2`` of the spherical (Brown-Conrady, OpenCV) model, the
  fit of :func:`physcam.export.opencv_distortion.fit_opencv_pinhole` (``terms="k1k2k3"``) at that mark;
* **NodalOffsetTable**: identity rotation and the translation from the film plane (physcam's
  choice for the tracked camera point) to the entrance pupil, in OpenCV axes (z forward) and
  Unreal units (cm): ``Tz = entrance_pupil_from_film_mm / 10``, ``Tx = Ty = 0``. An anamorphic has
  two pupils (docs/anamorphic.md): Unreal's camera has one eye, so the table carries the **vertical**
  (Y) one, the tilt pivot, physcam's eye everywhere; the horizontal (X) one, the pan pivot, is in the
  ``physcam`` block (``entrance_pupil_horizontal_from_film_mm``) and the user metadata.

Focus keys (``FocusEncoder``) are the focus mark from the film plane in **cm**, with an identity
``Focus`` encoder table (encoder value = cm); infinity is written as :data:`INFINITY_FOCUS_CM`.
``ZoomEncoder`` is the lens's focal length at infinity in mm (a prime has one zoom). A zoom lens
(docs/zoom.md) gives a **focus x zoom grid**: at each zoom position (its tabulated positions unless
asked, each the prescription at that position, :func:`physcam.lens.zoom.prescription_at`) the rows
of its focus marks, keyed by that position's paraxial EFL at infinity focus (mm); each position
focuses with its own focus groups and close distance. Numbers are
written in plain decimal notation. A top-level ``physcam`` block (ignored by Unreal's importer,
which reads named fields only) carries the same numbers in mm with infinity as ``null``.
"""

from __future__ import annotations

import json
import math

from ..errors import InputError, LensFileError
from ..lens.prescription import Prescription, takes_prescription

__all__ = ["LENS_FILE_TYPE", "LENS_FILE_VERSION", "INFINITY_FOCUS_CM", "unreal_lens_file", "write_unreal_lens_file",
           "parse_parameter_table", "read_unreal_lens_file"]

LENS_FILE_TYPE = "LensFile"
LENS_FILE_VERSION = "0.0.0"
#: The focus key written for infinity focus (cm): 1 km, beyond any on-set mark.
INFINITY_FOCUS_CM = 100000.0

HEADERS = {
    "FocalLengthTable": ("FocusEncoder", "ZoomEncoder", "Fx", "Fy"),
    "ImageCenterTable": ("FocusEncoder", "ZoomEncoder", "Cx", "Cy"),
    "DistortionTable": ("FocusEncoder", "ZoomEncoder", "K1", "K2", "K3", "P1", "P2"),
    "NodalOffsetTable": ("FocusEncoder", "ZoomEncoder", "Qx", "Qy", "Qz", "Qw", "Tx", "Ty", "Tz"),
}
FOCUS_ENCODER_HEADER = ("FocusEncoder", "FocusCM")


def _num(v: float) -> str:
    """Plain decimal notation (no exponent), enough digits for Unreal's 32-bit floats."""
    s = f"{float(v):.12f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _table(name: str, header, rows) -> dict:
    return {"parameterName": name, "header": ", ".join(header),
            "data": "; ".join(", ".join(_num(v) for v in row) for row in rows)}


def parse_parameter_table(table: dict) -> tuple[list[str], list[list[float]]]:
    """Header names and rows of numbers of one exchange table (``header`` "a, b", ``data`` "1, 2; 3, 4")."""
    try:
        header = [t.strip() for t in table["header"].split(",") if t.strip()]
        rows = [[float(t) for t in r.split(",") if t.strip()] for r in table["data"].split(";") if r.strip()]
    except (KeyError, AttributeError, TypeError, ValueError) as e:
        raise LensFileError(f"not an Unreal lens file parameter table: {e}") from None
    if any(len(r) != len(header) for r in rows):
        raise LensFileError(f"table {table.get('parameterName')!r}: a row does not match its {len(header)} headers")
    return header, rows


def _marks(q: Prescription, focus_marks_mm, w: float, method: str, wl: float) -> list[float]:
    """The focus marks of one lens (or zoom position): as given, else its breathing marks."""
    from ..optics.focusing import breathing_table

    if focus_marks_mm is None:
        return [r.focus_from_film_mm for r in breathing_table(q, None, sensor_width_mm=w, method=method,
                                                              wavelength_nm=wl)]
    try:
        marks = [float(m) for m in focus_marks_mm]
    except (TypeError, ValueError):
        raise InputError(f"focus marks must be numbers (mm from the film plane), got {focus_marks_mm!r}") from None
    if not marks or len(marks) > 64:
        raise InputError("give 1 to 64 focus marks")
    if any(math.isnan(m) or m <= 0 for m in marks):
        raise InputError("focus marks must be positive distances from the film plane")
    return sorted(set(marks), reverse=True)


def _zoom_positions(lens: Prescription, zoom_positions) -> list[float | None]:
    """The zoom encoder values of the grid (the tabulated positions by default); [None] for a prime."""
    if lens.zoom is None:
        if zoom_positions is not None:
            raise InputError(f"{lens.name!r} has no zoom table: zoom positions need a zoom lens (docs/zoom.md)")
        return [None]
    from ..lens.zoom import tabulated_encoders
    from ..optics.zoom import zoom_encoder

    if zoom_positions is None:
        return list(tabulated_encoders(lens))
    us = sorted({zoom_encoder(lens, z) for z in zoom_positions})
    if not us or len(us) > 32:
        raise InputError("give 1 to 32 zoom positions")
    return us


def _grid(lens, zoom_positions, focus_marks_mm, w, h, W, H, method, wavelength_nm, backend) -> list[dict]:
    """One entry per (zoom position, focus mark): the fitted camera, planes and pupils (module notes)."""
    from ..lens.zoom import prescription_at
    from ..optics.focusing import entrance_pupils, focus_method, technical_planes
    from .opencv_distortion import fit_opencv_pinhole

    out = []
    for u in _zoom_positions(lens, zoom_positions):
        q = lens if u is None else prescription_at(lens, u)
        m_q = focus_method(q, method)
        wl = q.wavelength_nm if wavelength_nm is None else wavelength_nm
        zoom = technical_planes(q, math.inf, wavelength_nm=wl, method=m_q).efl_mm
        for m in _marks(q, focus_marks_mm, w, m_q, wl):
            cam = fit_opencv_pinhole(q, w, h, W, H, focus_mm=m, terms="k1k2k3", method=m_q, wavelength_nm=wl,
                                     backend=backend)
            out.append({"u": u, "zoom": zoom, "mark": m, "cam": cam, "method": m_q, "wl": wl,
                        "tp": technical_planes(q, m, wavelength_nm=wl, method=m_q),
                        "pupil_x": entrance_pupils(q, m, method=m_q, wavelength_nm=wl).horizontal_from_film_mm})
    return out


@takes_prescription
def unreal_lens_file(
    lens: Prescription,
    sensor_width_mm: float,
    sensor_height_mm: float,
    *,
    image_width_px: int,
    image_height_px: int,
    focus_marks_mm=None,
    method: str = "auto",
    wavelength_nm: float | None = None,
    serial_number: str = "",
    backend: str = "auto",
    zoom_positions=None,
) -> dict:
    """The ``.ulens`` exchange JSON (a dict) of ``lens`` on the sensor (module notes).

    ``focus_marks_mm``: marks in front of the film plane (inf allowed); by default the breathing
    marks of :func:`physcam.optics.focusing.breathing_table`, infinity to the closest focus (a zoom:
    at each position). ``zoom_positions``: a zoom lens's positions (focal lengths ``"135mm"`` or
    encoder values, :func:`physcam.optics.zoom.zoom_encoder`; default its tabulated positions).
    """
    from .. import __version__
    from .opencv_distortion import _pixels, _sensor

    w = _sensor("sensor width", sensor_width_mm)
    h = _sensor("sensor height", sensor_height_mm)
    W = _pixels("image width", image_width_px)
    H = _pixels("image height", image_height_px)
    if not isinstance(serial_number, str):
        raise InputError("the serial number must be text")
    grid = _grid(lens, zoom_positions, focus_marks_mm, w, h, W, H, method, wavelength_nm, backend)
    key = [(INFINITY_FOCUS_CM if math.isinf(g["mark"]) else g["mark"] / 10.0, g["zoom"]) for g in grid]
    tables = [
        _table("FocalLengthTable", HEADERS["FocalLengthTable"],
               [(*k, g["cam"].pinhole_focal_length_x_mm / w, g["cam"].pinhole_focal_length_y_mm / h)
                for k, g in zip(key, grid)]),
        _table("ImageCenterTable", HEADERS["ImageCenterTable"], [(*k, 0.5, 0.5) for k in key]),
        _table("DistortionTable", HEADERS["DistortionTable"],
               [(*k, g["cam"].k1, g["cam"].k2, g["cam"].k3, g["cam"].p1, g["cam"].p2) for k, g in zip(key, grid)]),
        _table("NodalOffsetTable", HEADERS["NodalOffsetTable"],
               [(*k, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, g["tp"].entrance_pupil_from_film_mm / 10.0)
                for k, g in zip(key, grid)]),
    ]
    user = [("physcam.version", __version__), ("physcam.lens", lens.name), ("physcam.squeeze", _num(lens.squeeze)),
            ("physcam.focusUnits", "FocusEncoder = focus mark from the film plane in cm"),
            ("physcam.nodalOffset", "film plane to entrance pupil, cm, OpenCV axes (z forward)"
             + ("; the vertical (Y, tilt) pupil of an anamorphic: the horizontal (X, pan) one is "
                "physcam.marks[].entrance_pupil_horizontal_from_film_mm" if lens.is_anamorphic else ""))]
    if lens.zoom is not None:
        user.append(("physcam.zoomUnits", "ZoomEncoder = the zoom position's paraxial EFL at infinity focus, mm"))
    focus_keys = sorted({k[0] for k in key}, reverse=True)
    return {
        "metadata": {
            "type": LENS_FILE_TYPE,
            "version": LENS_FILE_VERSION,
            "lensInfo": {"serialNumber": serial_number, "modelName": lens.name, "distortionModel": "Spherical"},
            "name": lens.name,
            "nodalOffsetCoordinateSystem": "OpenCV",
            "fxFyUnits": "Normalized",
            "cxCyUnits": "Normalized",
            "userMetadata": [{"name": n, "value": str(v)} for n, v in user],
        },
        "sensorDimensions": {"width": w, "height": h, "units": "Millimeters"},
        "imageDimensions": {"width": W, "height": H},
        "cameraParameterTables": tables,
        "encoderTables": [_table("Focus", FOCUS_ENCODER_HEADER, [(k, k) for k in focus_keys])],
        "physcam": _physcam_block(lens, grid),
    }


def _physcam_block(lens: Prescription, grid: list[dict]) -> dict:
    """The file's ``physcam`` block: the same numbers in mm, infinity as null (module notes)."""
    g0 = grid[0]
    zooms = sorted({g["zoom"] for g in grid})
    return {
        "lens": lens.name, "method": g0["method"], "wavelength_nm": float(g0["wl"]),
        "zoom_focal_length_mm": zooms[0] if len(zooms) == 1 else None,
        "zoom_focal_lengths_mm": zooms, "infinity_focus_cm": INFINITY_FOCUS_CM,
        "marks": [{
            "zoom_encoder": g["u"], "zoom_focal_length_mm": g["zoom"],
            "focus_from_film_mm": None if math.isinf(g["mark"]) else g["mark"],
            "pinhole_focal_length_x_mm": g["cam"].pinhole_focal_length_x_mm,
            "pinhole_focal_length_y_mm": g["cam"].pinhole_focal_length_y_mm,
            "entrance_pupil_from_film_mm": g["tp"].entrance_pupil_from_film_mm,
            "entrance_pupil_horizontal_from_film_mm": g["pupil_x"],
            "efl_mm": g["tp"].efl_mm,
            "k1": g["cam"].k1, "k2": g["cam"].k2, "k3": g["cam"].k3, "p1": g["cam"].p1, "p2": g["cam"].p2,
            "max_residual_px": g["cam"].max_residual_px, "notes": list(g["cam"].notes),
        } for g in grid],
    }


def write_unreal_lens_file(path, lens: Prescription, sensor_width_mm: float, sensor_height_mm: float, *,
                           force: bool = False, **kwargs) -> dict:
    """Write :func:`unreal_lens_file` as JSON to ``path`` (through ``atomic_write``; no overwrite
    without ``force``) and return the dict."""
    from ..io import atomic_write, check_writable

    check_writable(path, force=force)
    data = unreal_lens_file(lens, sensor_width_mm, sensor_height_mm, **kwargs)
    atomic_write(path, json.dumps(data, indent=2) + "\n", force=force)
    return data


def read_unreal_lens_file(path) -> dict:
    """The tables of a ``.ulens`` file: ``{parameterName: (header, rows)}`` plus ``"_json"`` (the whole file)."""
    import os
    from pathlib import Path

    from ..errors import require_type

    require_type("path", path, (str, os.PathLike))
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise LensFileError(f"cannot read Unreal lens file {str(path)!r}: {e}") from None
    if not isinstance(data, dict) or data.get("metadata", {}).get("type") != LENS_FILE_TYPE:
        raise LensFileError(f"{str(path)!r} is not an Unreal lens file (metadata.type is not {LENS_FILE_TYPE!r})")
    out = {"_json": data}
    for t in list(data.get("cameraParameterTables", [])) + list(data.get("encoderTables", [])):
        out[t.get("parameterName")] = parse_parameter_table(t)
    return out
