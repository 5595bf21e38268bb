"""EXR in and out for ``physcam defocus``: colour and depth channels by name, header kept.

Channel names: a plain EXR has ``R``, ``G``, ``B`` (``A``) and a depth ``Z``; Blender's multilayer
EXR names them ``ViewLayer.Combined.R`` ... and ``ViewLayer.Depth.Z`` (Cycles' Z pass: planar
distance from the camera, scene units); a Nuke-style depth channel is ``depth.Z`` (ScanlineRender's
default: 1 / planar distance). Pixel arrays cover the data window; the display window is the
frame the pinhole imaged (OpenEXR "Technical Introduction": data and display windows).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import InputError, require_type

__all__ = ["ExrImage", "read_exr", "write_exr", "colour_channels", "depth_channel", "defocus_file", "write_kernel_stack"]


@dataclass
class ExrImage:
    """``channels``: name -> (h, w) array over the data window; ``header``: every attribute."""

    path: str
    header: dict
    channels: dict

    @property
    def origin(self) -> tuple[int, int]:
        """The data window's corner in the display window (x, y)."""
        (dx, dy), _ = self.header["dataWindow"]
        (wx, wy), _ = self.header["displayWindow"]
        return int(dx - wx), int(dy - wy)

    @property
    def display_size(self) -> tuple[int, int]:
        (x0, y0), (x1, y1) = self.header["displayWindow"]
        return int(x1 - x0 + 1), int(y1 - y0 + 1)


def read_exr(path) -> ExrImage:
    """Read every channel of a scanline or tiled EXR (one part)."""
    from ...extras import require_extra

    require_extra("exr", "reading EXR images")
    import OpenEXR

    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such EXR file")
    try:
        with OpenEXR.File(str(p), separate_channels=True) as f:
            header = dict(f.header())
            chans = {name: np.array(c.pixels) for name, c in f.channels().items()}
    except (OSError, RuntimeError, ValueError) as e:
        raise InputError(f"{p}: not a readable EXR image ({str(e).splitlines()[0][:120]})") from None
    if not chans:
        raise InputError(f"{p}: the EXR has no channels")
    return ExrImage(str(p), header, chans)


def colour_channels(img: ExrImage) -> list[str]:
    """The colour channels (R, G, B, A in that order, with or without a layer prefix; Blender's
    ``Combined`` layer preferred); else every channel that is not a depth."""
    require_type("image", img, ExrImage, "physcam.analysis.defocus.exr.read_exr(path)")
    names = list(img.channels)
    for prefix in ("", "ViewLayer.Combined.", "RenderLayer.Combined."):
        got = [prefix + c for c in "RGBA" if prefix + c in names]
        if {prefix + "R", prefix + "G", prefix + "B"} <= set(got):
            return got
    combined = [n for n in names if ".Combined." in n]
    if combined:
        return sorted(combined, key=lambda n: "RGBA".find(n[-1]))
    rest = [n for n in names if n.split(".")[-1] != "Z" and "depth" not in n.lower()]
    if not rest:
        raise InputError(f"{img.path}: no colour channels (it has {', '.join(names)})")
    return rest


def depth_channel(img: ExrImage, name: str | None = None) -> str:
    """The named depth channel, or the one depth channel the file has (``Z``, ``*.Depth.Z``,
    ``depth.Z``, or a file's only channel)."""
    require_type("image", img, ExrImage, "physcam.analysis.defocus.exr.read_exr(path)")
    if name is not None:
        require_type("depth channel", name, str, "a channel name such as 'Z'")
    names = list(img.channels)
    if name is not None:
        if name not in img.channels:
            raise InputError(f"{img.path} has no channel {name!r} (it has {', '.join(names)})")
        return name
    found = [n for n in names if n == "Z" or n.endswith(".Z") and "depth" in n.lower()]
    if len(found) == 1:
        return found[0]
    if len(names) == 1:
        return names[0]
    if not found:
        raise InputError(f"{img.path} has no depth channel (Z, ViewLayer.Depth.Z or depth.Z; it has "
                         f"{', '.join(names)}): render a depth pass or give --depth DEPTH.exr")
    raise InputError(f"{img.path} has several depth channels ({', '.join(found)}): name one with --depth")


def write_exr(path, img: ExrImage, planes: dict, *, attributes=None, force: bool = False) -> Path:
    """Write ``planes`` (name -> (h, w) float32) with ``img``'s header (windows, every attribute,
    ``attributes`` added), ZIP-compressed, through :func:`physcam.io.atomic_write`."""
    import os
    import tempfile

    require_type("image", img, ExrImage, "physcam.analysis.defocus.exr.read_exr(path)")
    require_type("planes", planes, dict, "{channel name: (h, w) array}")
    from ...extras import require_extra

    require_extra("exr", "writing EXR images")
    import OpenEXR

    from ...io import atomic_write, check_writable

    check_writable(path, force=force)
    keep = {k: v for k, v in img.header.items() if k not in ("channels", "type", "chunkCount", "tiles")}
    header = {**keep, "compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage, **(attributes or {})}
    fd, tmp = tempfile.mkstemp(suffix=".exr")
    os.close(fd)
    try:
        with OpenEXR.File(header, {k: np.ascontiguousarray(v, dtype=np.float32) for k, v in planes.items()}) as f:
            f.write(tmp)
        data = Path(tmp).read_bytes()
    finally:
        os.unlink(tmp)
    return atomic_write(path, data, force=force)


def defocus_file(image_path, output, lens, *, focus_mm: float | None = None, fstop: float | None = None,
                 sensor_width_mm: float | None = None,
                 depth: str | None = None, depth_kind: str | None = None, depth_unit: str = "m", aperture=None,
                 dispersion: bool = False, tile: int = 64, step_px: float = 1.0, step_rel: float = 0.05, cache=None,
                 kernel_folder=None,
                 edge_px: int = 1, force: bool = False) -> dict:
    """Defocus the EXR ``image_path`` through ``lens`` (a :class:`~physcam.optics.state.CameraState`, or a
    Prescription with ``focus_mm`` and ``fstop``) into ``output`` (see
    :mod:`physcam.analysis.defocus.render`). ``depth``: a channel of the image, or a separate EXR file
    (its one depth channel) over the same data window; ``depth_kind`` defaults to ``inverse`` for a
    channel named ``depth.Z`` (Nuke) and ``planar`` otherwise (Blender's Z). ``cache``: a
    :class:`~physcam.analysis.defocus.kernels.KernelCache` to share between frames; ``edge_px``: see
    :func:`~physcam.analysis.defocus.render.defocus`. Returns a summary."""
    import time

    from .render import defocus, inverse_depth
    from .kernels import KernelCache, _as_aperture, defocus_camera

    from ...io import check_writable

    check_writable(output, force=force)
    t0 = time.perf_counter()
    img = read_exr(image_path)
    if depth is not None and (depth.lower().endswith(".exr") or Path(depth).is_file()):
        dimg = read_exr(depth)
        zname = depth_channel(dimg)
        if dimg.header["dataWindow"][0].tolist() != img.header["dataWindow"][0].tolist() or \
                dimg.channels[zname].shape != next(iter(img.channels.values())).shape:
            raise InputError(f"the depth file {depth} covers {dimg.channels[zname].shape[::-1]} pixels and the image "
                             f"{next(iter(img.channels.values())).shape[::-1]}: they must share one data window")
        z = dimg.channels[zname]
    else:
        zname = depth_channel(img, depth)
        z = img.channels[zname]
    kind = depth_kind or ("inverse" if zname.split(".")[-2:] == ["depth", "Z"] else "planar")
    w, h = img.display_size
    if cache is None:
        from ...data.default_sensor import DEFAULT_SENSOR_HEIGHT_MM
        from ...optics.state import as_camera_state

        sensor = None if sensor_width_mm is None else (sensor_width_mm, DEFAULT_SENSOR_HEIGHT_MM)
        camera = as_camera_state(lens, focus_mm=focus_mm, fstop=fstop, sensor_mm=sensor, aperture=_as_aperture(aperture))
        cam = defocus_camera(camera, width=w, height=h, dispersion=dispersion, tile=tile, step_px=step_px,
                             step_rel=step_rel)
        cache = KernelCache(cam, kernel_folder)
    cam = cache.camera
    lens, focus_mm, fstop, sensor_width_mm = cam.lens, cam.focus_mm, cam.fstop, cam.sensor_width_mm
    if (cam.width, cam.height) != (w, h):
        raise InputError(f"{image_path} is {w} x {h} pixels, the kernel cache's frame {cam.width} x {cam.height}")
    names = [n for n in colour_channels(img) if n != zname]
    rgb = np.stack([img.channels[n] for n in names], axis=2).astype(np.float32)
    u = inverse_depth(z, cam, kind=kind, unit=depth_unit, origin=img.origin)
    traced = cache.traced
    out = defocus(rgb, u, cache, origin=img.origin, edge_px=edge_px)
    attrs = {"physcam/defocus": f"{lens.name} focus {focus_mm:g} mm from the film, f/{fstop:g}, sensor "
                                f"{sensor_width_mm:g} mm wide; depth {zname} ({kind}, {depth_unit})"}
    write_exr(output, img, {n: out[..., i] for i, n in enumerate(names)}, attributes=attrs, force=force)
    return {"image": str(image_path), "output": str(output), "lens": lens.name, "focus_from_film_mm": focus_mm,
            "fstop": fstop, "sensor_width_mm": sensor_width_mm, "pixels": [w, h], "channels": names,
            "depth_channel": zname, "depth_kind": kind, "depth_unit": depth_unit,
            "pinhole_focal_length_mm": cam.pinhole_mm, "entrance_pupil_from_film_mm": cam.pupil_from_film_mm,
            "kernels_traced": cache.traced - traced, "seconds": time.perf_counter() - t0}


def write_kernel_stack(folder, camera, *, field_grid=(5, 3), depths_mm=(500.0, 1000.0, 2000.0, 4000.0, math.inf),
                       force: bool = False) -> dict:
    """The PSF stack of ``camera`` (a :class:`~physcam.analysis.defocus.kernels.DefocusCamera`):
    for each of ``field_grid`` (nx, ny) picture positions (spread corner to corner, at pixel
    centres) and each planar depth from the entrance pupil, one EXR (R, G, B: the kernel per
    channel; mono kernels repeat) and ``index.json`` describing them. Kernels are on the picture's
    pixel grid, rows down, the pinhole's image of the point at the centre pixel, each channel
    summing to the relative transmission (vignetting x cos, 1 on the axis)."""
    from ...io import atomic_write, check_writable
    from .kernels import DefocusCamera

    require_type("camera", camera, DefocusCamera, "physcam.analysis.defocus.kernels.defocus_camera(lens, ...)")
    nx, ny = (int(v) for v in field_grid)
    if not (1 <= nx <= 33 and 1 <= ny <= 33):
        raise InputError(f"the field grid must be 1 to 33 positions a side, got {nx} x {ny}")
    if not depths_mm or len(depths_mm) > 64:
        raise InputError("give 1 to 64 depths")
    folder = Path(folder)
    index_path = folder / "index.json"
    check_writable(index_path, force=force)
    entries = []
    for j in range(ny):
        for i in range(nx):
            x = 0.5 + (camera.width - 1) * (i / (nx - 1) if nx > 1 else 0.5)
            y = 0.5 + (camera.height - 1) * (j / (ny - 1) if ny > 1 else 0.5)
            for k, d in enumerate(depths_mm):
                from .kernels import FAR_MM

                kern = camera.kernel(x, y, FAR_MM if math.isinf(d) else float(d))
                img = kern.image if kern.image.shape[2] == 3 else np.repeat(kern.image, 3, axis=2)
                name = f"psf_x{i}_y{j}_d{k}.exr"
                n = img.shape[0]
                header = {
                          "physcam/kernel": f"field ({x:g}, {y:g}) px, depth {d:g} mm from the entrance pupil"}
                fake = ExrImage(name, {**header, "dataWindow": (np.array([0, 0], np.int32), np.array([n - 1, n - 1], np.int32)),
                                       "displayWindow": (np.array([0, 0], np.int32), np.array([n - 1, n - 1], np.int32))}, {})
                write_exr(folder / name, fake, {c: img[..., m] for m, c in enumerate("RGB")}, force=force)
                entries.append({"file": name, "field_px": [x, y], "field_mm": list(camera.film_point(x, y)),
                                "depth_from_pupil_mm": None if math.isinf(d) else float(d),
                                "size_px": n, "centre_px": [n // 2, n // 2], "transmission": list(kern.transmission)})
    index = {"lens": camera.lens.name, "focus_from_film_mm": camera.focus_mm, "fstop": camera.fstop,
             "sensor_width_mm": camera.sensor_width_mm, "pixels": [camera.width, camera.height],
             "pixel_pitch_mm": camera.pitch_mm, "pinhole_focal_length_mm": camera.pinhole_mm,
             "entrance_pupil_from_film_mm": camera.pupil_from_film_mm, "wavelengths_nm": list(camera.wavelengths_nm),
             "convention": "picture grid, row 0 on top, x right; the pinhole's image of the point at centre_px; "
                           "depth planar from the entrance pupil (null: infinity)",
             "kernels": entries}
    atomic_write(index_path, json.dumps(index, indent=1), force=force)
    return index
