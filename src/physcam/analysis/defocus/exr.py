"""EXR in and out for ``physcam defocus``: the picture and its depth by name, everything else kept.

Channel names: a plain EXR has ``R``, ``G``, ``B`` (``A``) and a depth ``Z``; Blender's multilayer
EXR names them ``ViewLayer.Combined.R`` ... and ``ViewLayer.Depth.Z`` (Cycles' Z pass: planar
distance from the camera, scene units); a Nuke-style depth channel is ``depth.Z`` (ScanlineRender's
default: 1 / planar distance). Blender 5 writes a pass sent through the compositor as an image of
its own, ``R``, ``G``, ``B`` (``A``) all holding the pass: a depth file with those channels alone,
equal, is read from ``R``. A depth file's channel can be named (``depth_channel``). Pixel arrays
cover the data window; the display window is the frame the pinhole imaged (OpenEXR "Technical
Introduction": data and display windows).

What a compositor sends comes back whole: every part, every other layer and pass (AOVs, the depth
itself) and every header attribute is written back as read, pixel for pixel and in its own pixel
type; only the picture's colour (and its alpha, when it has one) is replaced by the defocused one.
A deep EXR (samples per pixel) is refused with one sentence: flatten it first.

An output that is one of the inputs (the picture or its depth file: the same path, through a
symbolic link, or a hard link to the same file) is refused before any work, ``--force`` or not.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import InputError, require_type

__all__ = ["ExrImage", "read_exr", "write_exr", "colour_channels", "alpha_channel", "depth_channel", "defocus_file",
           "write_kernel_stack"]


@dataclass
class ExrPart:
    """One part of an EXR file: its name, every header attribute and its channels (OpenEXR.Channel)."""

    name: str
    header: dict
    channels: dict


@dataclass
class ExrImage:
    """An EXR file: its ``parts``; ``index`` is the part holding the picture (its colour channels),
    whose ``header`` and ``channels`` (name -> (h, w) array over the data window) these properties give."""

    path: str
    parts: list
    index: int = 0

    @property
    def header(self) -> dict:
        return self.parts[self.index].header

    @property
    def channels(self) -> dict:
        return {name: c.pixels for name, c in self.parts[self.index].channels.items()}

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
    """Read every part and channel of a scanline or tiled EXR; a deep one is refused (module notes)."""
    from ...extras import require_extra

    require_extra("exr", "reading EXR images")
    import OpenEXR

    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such EXR file")
    try:
        with OpenEXR.File(str(p), header_only=True) as f:
            kinds = [(part.name(), part.type()) for part in f.parts]
    except (OSError, RuntimeError, ValueError, TypeError) as e:
        raise InputError(f"{p}: not a readable EXR image ({str(e).splitlines()[0][:120] if str(e) else type(e).__name__})") from None
    for name, kind in kinds:
        if kind in (OpenEXR.deepscanline, OpenEXR.deeptile):
            raise InputError(f"{p} is a deep EXR{f' (part {name!r})' if name else ''}: physcam defocus reads flat "
                             "images; flatten it first (Nuke: DeepToImage) or render a flat EXR with a depth pass")
    try:
        with OpenEXR.File(str(p), separate_channels=True) as f:
            parts = [ExrPart(part.name() or "", dict(part.header), dict(part.channels)) for part in f.parts]
    except (OSError, RuntimeError, ValueError, TypeError) as e:
        raise InputError(f"{p}: not a readable EXR image ({str(e).splitlines()[0][:120] if str(e) else type(e).__name__})") from None
    if not any(part.channels for part in parts):
        raise InputError(f"{p}: the EXR has no channels")
    index = next((i for i, part in enumerate(parts) if _picture(part.channels)), 0)
    return ExrImage(str(p), parts, index)


def _picture(names) -> list[str]:
    """The colour channels among ``names``: R, G, B (and A) of one layer, the unprefixed layer first,
    then Blender's Combined pass, then any; [] if there are none."""
    names = list(names)
    layers = sorted({n[:-1] for n in names if n.endswith(("R", "G", "B")) and (len(n) == 1 or n[-2] == ".")},
                    key=lambda p: (p != "", ".Combined." not in p, p))
    for prefix in layers:
        if all(prefix + c in names for c in "RGB"):
            return [prefix + c for c in "RGB"]
    return []


def colour_channels(img: ExrImage) -> list[str]:
    """The picture's colour channels (module notes): R, G, B of one layer; else every channel of the
    picture's part that is not a depth or an alpha."""
    require_type("image", img, ExrImage, "physcam.analysis.defocus.exr.read_exr(path)")
    names = list(img.channels)
    got = _picture(names)
    if got:
        return got
    rest = [n for n in names if n.split(".")[-1] not in ("Z", "A") and "depth" not in n.lower()]
    if not rest:
        raise InputError(f"{img.path}: no colour channels (it has {', '.join(names)})")
    return rest


def alpha_channel(img: ExrImage, colour: list[str]) -> str | None:
    """The alpha (coverage) channel of the picture's layer, if it has one."""
    require_type("image", img, ExrImage, "physcam.analysis.defocus.exr.read_exr(path)")
    require_type("colour channels", colour, list, "colour_channels(image)")
    prefix = colour[0][:-1] if colour and isinstance(colour[0], str) and colour[0].endswith("R") else ""
    name = prefix + "A"
    return name if name in img.channels and name not in colour else None


def depth_channel(img: ExrImage, name: str | None = None) -> str:
    """The named depth channel, or the one depth channel the file has (``Z``, ``*.Depth.Z``,
    ``depth.Z``), or a depth pass written through Blender 5's compositor (``R``, ``G``, ``B``
    (``A``) only, equal: ``R``), or a file's only channel."""
    require_type("image", img, ExrImage, "physcam.analysis.defocus.exr.read_exr(path)")
    if name is not None:
        require_type("depth channel", name, str, "a channel name such as 'Z'")
    names = list(img.channels)
    if name is not None:
        if name not in img.channels:
            raise InputError(f"{img.path} has no channel {name!r} (it has {', '.join(names)})")
        return name
    found = [n for n in names if n == "Z" or n.endswith(".Z") and ("depth" in n.lower() or n.count(".") == 1)]
    if len(found) == 1:
        return found[0]
    if len(names) == 1:
        return names[0]
    if not found and set(names) <= {"R", "G", "B", "A"} and {"R", "G", "B"} <= set(names):
        ch = img.channels
        if np.array_equal(ch["R"], ch["G"], equal_nan=True) and np.array_equal(ch["R"], ch["B"], equal_nan=True):
            return "R"  # Blender 5: a pass sent through the compositor, in every colour channel
        raise InputError(f"{img.path} holds a colour picture, not a depth pass (its R, G and B differ): name the depth "
                         "channel (--depth-channel) or give the depth pass")
    if not found:
        raise InputError(f"{img.path} has no depth channel (Z, ViewLayer.Depth.Z or depth.Z; it has "
                         f"{', '.join(names)}): render a depth pass or give --depth DEPTH.exr")
    raise InputError(f"{img.path} has several depth channels ({', '.join(found)}): name one with --depth")


def write_exr(path, img: ExrImage, planes: dict, *, attributes=None, force: bool = False) -> Path:
    """``img`` written to ``path`` with the picture part's channels in ``planes`` (name -> (h, w)
    array, in the channel's own pixel type; new names are float) replaced, everything else as read
    (module notes); ``attributes`` added to the picture part's header; through :func:`physcam.io.staged`."""
    require_type("image", img, ExrImage, "physcam.analysis.defocus.exr.read_exr(path)")
    require_type("planes", planes, dict, "{channel name: (h, w) array}")
    from ...extras import require_extra

    require_extra("exr", "writing EXR images")
    import OpenEXR

    from ...io import staged

    parts = []
    for i, part in enumerate(img.parts):
        chans = dict(part.channels)
        header = {k: v for k, v in part.header.items() if k not in ("channels", "chunkCount")}
        if i == img.index:
            for name, arr in planes.items():
                old = chans.get(name)
                dtype = old.pixels.dtype if old is not None else np.float32
                new = np.ascontiguousarray(arr, dtype=dtype)
                chans[name] = OpenEXR.Channel(name, new, old.xSampling, old.ySampling) if old is not None \
                    else OpenEXR.Channel(name, new)
            header.update(attributes or {})
        parts.append(OpenEXR.Part(header, chans, part.name) if len(img.parts) > 1 else (header, chans))
    with staged(path, force=force, suffix=".exr") as tmp:
        if len(img.parts) > 1:
            with OpenEXR.File(parts) as f:
                f.write(str(tmp))
        else:
            with OpenEXR.File(*parts[0]) as f:
                f.write(str(tmp))
    return Path(path)


def _read_depth(img: ExrImage, depth, depth_channel_name):
    """The depth array and its channel's name: a channel of the picture, or of a separate EXR file."""
    if depth is not None and (str(depth).lower().endswith(".exr") or Path(depth).is_file()):
        dimg = read_exr(depth)
        zname = depth_channel(dimg, depth_channel_name)
        z, shape = dimg.channels[zname], next(iter(img.channels.values())).shape
        if dimg.header["dataWindow"][0].tolist() != img.header["dataWindow"][0].tolist() or z.shape != shape:
            raise InputError(f"the depth file {depth} covers {z.shape[::-1]} pixels and the image {shape[::-1]}: they "
                             "must share one data window")
        return z, zname
    if depth_channel_name is not None and depth is not None:
        raise InputError("--depth-channel names a channel of a depth file; with --depth CHANNEL the channel is named already")
    zname = depth_channel(img, depth if depth is not None else depth_channel_name)
    return img.channels[zname], zname


def defocus_file(image_path, output, lens, *, focus_mm: float | None = None, fstop: float | None = None,
                 sensor_width_mm: float | None = None, depth: str | None = None, depth_channel: str | None = None,
                 depth_kind: str | None = None, depth_unit: str = "m", aperture=None, dispersion: bool = False,
                 tile: int = 64, step_px: float = 1.0, step_rel: float = 0.05, cache=None, kernel_folder=None,
                 edge_px: int = 1, force: bool = False, progress=None) -> dict:
    """Defocus the EXR ``image_path`` through ``lens`` (a :class:`~physcam.optics.state.CameraState`, or a
    Prescription with ``focus_mm`` and ``fstop``) into ``output`` (see
    :mod:`physcam.analysis.defocus.render`). ``depth``: a channel of the image, or a separate EXR file (its
    one depth channel, or ``depth_channel``) over the same data window; ``depth_kind`` defaults to
    ``inverse`` for a channel named ``depth.Z`` (Nuke) and ``planar`` otherwise (Blender's Z).
    ``cache``: a :class:`~physcam.analysis.defocus.kernels.KernelCache` to share between frames;
    ``edge_px``: see :func:`~physcam.analysis.defocus.render.defocus`. Every other channel and part is
    written back as read (module notes). Returns a summary."""
    import time

    from ...io import check_writable, refuse_inputs_as_outputs
    from .render import defocus, inverse_depth
    from .kernels import KernelCache, _as_aperture, defocus_camera

    depth_file = depth if depth is not None and (str(depth).lower().endswith(".exr") or Path(depth).is_file()) else None
    refuse_inputs_as_outputs([image_path, depth_file], [output])
    check_writable(output, force=force)
    t0 = time.perf_counter()
    img = read_exr(image_path)
    z, zname = _read_depth(img, depth, depth_channel)
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
    if (cam.width, cam.height) != (w, h):
        raise InputError(f"{image_path} is {w} x {h} pixels, the kernel cache's frame {cam.width} x {cam.height}")
    in_image = None if depth_file is not None else zname  # the depth, when it is a channel of the picture
    names = [n for n in colour_channels(img) if n != in_image]
    alpha = alpha_channel(img, names)
    alpha = None if alpha == in_image else alpha
    chans = img.channels
    stack = np.stack([chans[n] for n in names] + ([chans[alpha]] if alpha else []), axis=2).astype(np.float32)
    u = inverse_depth(z, cam, kind=kind, unit=depth_unit, origin=img.origin)
    traced, loaded = cache.traced, cache.loaded
    out = defocus(stack, u, cache, origin=img.origin, edge_px=edge_px, alpha_channel=len(names) if alpha else None,
                  progress=progress)
    if not np.isfinite(out).all():  # never written: a file reported as written is sound
        raise InputError(f"the defocused {image_path} has NaN or infinite pixels; nothing written")
    planes = {n: out[..., i] for i, n in enumerate(names)}
    if alpha:
        planes[alpha] = out[..., len(names)]
    attrs = {"physcam/defocus": f"{cam.lens.name} focus {cam.focus_mm:g} mm from the film, f/{cam.fstop:g}, sensor "
                                f"{cam.sensor_width_mm:g} mm wide; depth {zname} ({kind}, {depth_unit})"}
    write_exr(output, img, planes, attributes=attrs, force=force)
    kept = [n for part in img.parts for n in part.channels if part is not img.parts[img.index] or n not in planes]
    return {"image": str(image_path), "output": str(output), "lens": cam.lens.name, "focus_from_film_mm": cam.focus_mm,
            "fstop": cam.fstop, "sensor_width_mm": cam.sensor_width_mm, "pixels": [w, h], "channels": names,
            "alpha_channel": alpha, "kept_channels": kept, "depth_channel": zname, "depth_kind": kind,
            "depth_unit": depth_unit, "pinhole_focal_length_mm": cam.pinhole_mm,
            "pinhole_focal_length_x_mm": cam.pinhole_x_mm, "entrance_pupil_from_film_mm": cam.pupil_from_film_mm,
            "kernels_traced": cache.traced - traced, "kernels_loaded": cache.loaded - loaded,
            "seconds": time.perf_counter() - t0}


def write_kernel_stack(folder, camera, *, field_grid=(5, 3), depths_mm=(500.0, 1000.0, 2000.0, 4000.0, math.inf),
                       force: bool = False, inputs=()) -> dict:
    """The PSF stack of ``camera`` (a :class:`~physcam.analysis.defocus.kernels.DefocusCamera`):
    for each of ``field_grid`` (nx, ny) picture positions (spread corner to corner, at pixel
    centres) and each planar depth from the entrance pupil, one EXR (R, G, B: the kernel per
    channel; mono kernels repeat) and ``index.json`` describing them, written as a whole
    (:func:`physcam.io.staged_folder`: a killed or failed rerun leaves the old stack or the new one,
    never a mix). Kernels are on the picture's pixel grid, rows down, centred on their light's
    centroid (``centroid_offset_px`` from the pinhole's image of the point: the lens's distortion and
    the cat's eye's shift), each channel summing to the relative transmission (vignetting x cos, 1
    on the axis). ``inputs``: files the stack must not replace (the lens file)."""
    from ...io import refuse_inputs_as_outputs, staged_folder
    from .kernels import FAR_MM, DefocusCamera

    require_type("camera", camera, DefocusCamera, "physcam.analysis.defocus.kernels.defocus_camera(lens, ...)")
    nx, ny = (int(v) for v in field_grid)
    if not (1 <= nx <= 33 and 1 <= ny <= 33):
        raise InputError(f"the field grid must be 1 to 33 positions a side, got {nx} x {ny}")
    if not depths_mm or len(depths_mm) > 64:
        raise InputError("give 1 to 64 depths")
    folder = Path(folder)
    refuse_inputs_as_outputs(inputs, [], folders=[folder])
    points = [(0.5 + (camera.width - 1) * (i / (nx - 1) if nx > 1 else 0.5),
               0.5 + (camera.height - 1) * (j / (ny - 1) if ny > 1 else 0.5), d)
              for j in range(ny) for i in range(nx) for d in depths_mm]
    kernels = camera.kernels([(x, y, FAR_MM if math.isinf(d) else float(d)) for x, y, d in points])
    entries = []
    with staged_folder(folder, force=force, about={"what": "physcam defocus-kernels", "lens": camera.lens.name}) as tmp:
        for k, ((x, y, d), kern) in enumerate(zip(points, kernels)):
            i, j, m = k // len(depths_mm) % nx, k // (len(depths_mm) * nx), k % len(depths_mm)
            img = kern.image if kern.image.shape[2] == 3 else np.repeat(kern.image, 3, axis=2)
            name = f"psf_x{i}_y{j}_d{m}.exr"
            n = img.shape[0]
            _write_kernel(tmp / name, img, f"field ({x:g}, {y:g}) px, depth {d:g} mm from the entrance pupil")
            entries.append({"file": name, "field_px": [x, y], "field_mm": list(camera.film_point(x, y)),
                            "depth_from_pupil_mm": None if math.isinf(d) else float(d), "size_px": n,
                            "centre_px": [n // 2, n // 2], "centroid_offset_px": [float(v) for v in kern.offset_px],
                            "transmission": list(kern.transmission)})
        index = {"lens": camera.lens.name, "focus_from_film_mm": camera.focus_mm, "fstop": camera.fstop,
                 "sensor_width_mm": camera.sensor_width_mm, "pixels": [camera.width, camera.height],
                 "pixel_pitch_mm": camera.pitch_mm, "pinhole_focal_length_mm": camera.pinhole_mm,
                 "pinhole_focal_length_x_mm": camera.pinhole_x_mm,
                 "entrance_pupil_from_film_mm": camera.pupil_from_film_mm, "wavelengths_nm": list(camera.wavelengths_nm),
                 "convention": "picture grid, row 0 on top, x right; each kernel centred on its light's centroid, "
                               "centroid_offset_px from the pinhole's image of the point; depth planar from the "
                               "entrance pupil (null: infinity)",
                 "kernels": entries}
        (tmp / "index.json").write_text(json.dumps(index, indent=1, allow_nan=False), encoding="utf-8")
    return index


def _write_kernel(path: Path, img: np.ndarray, note: str) -> None:
    """One kernel as a float EXR (R, G, B) whose windows are its own size, with a note in its header."""
    import OpenEXR

    n = img.shape[0]
    win = (np.array([0, 0], np.int32), np.array([n - 1, n - 1], np.int32))
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage, "dataWindow": win,
              "displayWindow": win, "physcam/kernel": note}
    with OpenEXR.File(header, {c: np.ascontiguousarray(img[..., m], dtype=np.float32) for m, c in enumerate("RGB")}) as f:
        f.write(str(path))
