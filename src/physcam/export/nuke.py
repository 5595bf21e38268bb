"""A Nuke script that applies physcam's ST-maps to a plate, and redistorts CG (docs/distortion.md).

Two branches, each a ``Read`` of the map (raw, so no colour transform touches the numbers), a
``Read`` of the image and an ``STMap`` (``uv rgb``): *undistort* turns the plate into the
undistorted, overscanned picture; *redistort* turns a render of that picture back into the plate.
The maps carry their own frames (:func:`physcam.analysis.distortion.stmap.write_stmaps`): the undistorted
picture's format is the plate's (or, desqueezed, the wider frame the map's display window says) and
its bounding box the overscan (EXR display and data windows),
so the render to redistort is an EXR of that frame too (display window = the plate, data window =
the overscan, as renderers write overscan).
In a ``.nk`` file a node with ``inputs 2`` takes its inputs from the node stack, the top of the
stack as input 0: the image is written last, so it is the STMap's ``src`` (input 0) and the map
its ``stmap`` input (input 1). No Nuke was run to check the script; the maps themselves are
checked end to end by :func:`physcam.analysis.distortion.stmap.apply_stmap`.
"""

from __future__ import annotations

from ..errors import InputError
from ._codetext import hash_comment, nuke_file_path

__all__ = ["nuke_stmap_script"]


def _path(p) -> str:
    return nuke_file_path(p)


def nuke_stmap_script(undistortion_map, distortion_map, *, plate="plate.####.exr", render="render.####.exr",
                      plate_size=(2048, 1080), undistorted_size=(2048, 1080), undistorted_frame=None,
                      version: str = "") -> str:
    """The ``.nk`` text (module notes); sizes in pixels (width, height). ``undistorted_frame``: the
    undistorted picture's frame without its overscan when it is not the plate's (desqueezed)."""
    frame = plate_size if undistorted_frame is None else undistorted_frame
    for n, s in (("plate", plate_size), ("undistorted", undistorted_size), ("undistorted frame", frame)):
        if len(s) != 2 or not all(isinstance(v, int) and v > 0 for v in s):
            raise InputError(f"the {n} size must be two whole numbers of pixels, got {s!r}")
    (w, h), (W, H), (fw, fh) = plate_size, undistorted_size, frame
    said = (f"the plate's format {w} x {h}" if (fw, fh) == (w, h) else
            f"desqueezed from the plate's {w} x {h} to {fw} x {fh} square pixels")

    def node(kind, **knobs):
        body = "".join(f" {k} {v}\n" for k, v in knobs.items())
        return f"{kind} {{\n{body}}}\n"

    parts = [
        f"# physcam {hash_comment(version)}: apply the undistortion and distortion ST-maps (R = u, G = v, origin bottom left)\n"
        f"# the undistorted picture: {said}, bounding box {W} x {H} "
        f"({(W - fw) // 2}, {(H - fh) // 2} px of overscan each side; the maps' EXR windows say so)\n",
        node("Root", inputs=0, format=f'"{w} {h} 0 0 {w} {h} 1 physcam_plate"'),
        node("Read", inputs=0, file=f'"{_path(undistortion_map)}"', raw="true", name="physcam_undistortion_map"),
        node("Read", inputs=0, file=f'"{_path(plate)}"', name="physcam_plate"),
        node("STMap", inputs=2, channels="rgba", uv="rgb", name="physcam_undistort"),
        node("Read", inputs=0, file=f'"{_path(distortion_map)}"', raw="true", name="physcam_distortion_map"),
        node("Read", inputs=0, file=f'"{_path(render)}"', name="physcam_undistorted_render"),
        node("STMap", inputs=2, channels="rgba", uv="rgb", name="physcam_redistort"),
    ]
    return "".join(parts)
