"""pbrt's lens ``.dat`` format (pbrt-v3/v4 ``realistic`` camera, ISET3D).

One surface a row, front (scene side) to back: ``radius thickness index aperture``,
millimetres, whitespace separated, ``#`` starts a comment. Source: pbrt-v4
``RealisticCamera::Create`` (src/pbrt/cameras.cpp) and the ISET3D wiki (seed 004).

- ``radius``: signed radius of curvature, positive when the centre lies toward the
  film; **0 marks the aperture stop** (so pbrt cannot hold a flat refracting surface).
- ``thickness``: axial distance to the next vertex ("axpos" in some headers); on the
  last row the distance to the film, 0 when not given.
- ``index``: refractive index after the surface; 0 means air (pbrt treats 0 as 1; the
  stop row carries 0). pbrt has no dispersion, so every medium reads with Vd = 0.
- ``aperture``: the clear **diameter** (pbrt halves it to get the element radius). The
  ISET wiki calls it a semi-diameter; the files' own geometry says otherwise: in
  dgauss.50mm, radius 12.75 with aperture 18 fits only as a diameter (9 < 12.75).

Comment lines before the first row become ``metadata.notes`` (a comment whose first
word is ``radius`` is taken as the column header and skipped). A lone number before
the rows (pbrt-v2 files) is the nominal focal length. The lens name is the file name
without ``.dat``.
"""

from __future__ import annotations

import warnings
from pathlib import Path

from ...errors import ExportError, LensFileError, PhysCamWarning
from ..prescription import AIR, LensMetadata, Medium, Prescription, Surface, takes_prescription
from ._common import check_count, fmt, number, one_line, validated, takes_text

__all__ = ["loads", "dumps", "HEADER"]

HEADER = "radius thickness index aperture-diameter (mm; radius 0 = aperture stop, index 0 = air)"


@takes_text
def loads(text: str, path=None, name: str | None = None) -> Prescription:
    """Parse pbrt ``.dat`` text into a validated :class:`Prescription`."""
    if name is None:
        name = Path(path).name.removesuffix(".dat") if path is not None else "unnamed lens"
    notes: list[str] = []
    rows: list[tuple[int, list[str]]] = []
    focal = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        body, hash_, comment = raw.partition("#")
        fields = body.split()
        if not fields:
            if hash_ and not rows:
                c = comment.strip()
                if c and c.split()[0].lower() != "radius":
                    notes.append(c)
            continue
        if len(fields) == 1 and not rows and focal is None:
            focal = number(fields[0], "focal length (pbrt-v2 header)", path, lineno)
            continue
        if len(fields) != 4:
            raise LensFileError(
                f"expected 4 numbers (radius thickness index aperture-diameter), found {len(fields)}", path, lineno
            )
        rows.append((lineno, fields))
        check_count(len(rows), path, lineno)
    check_count(len(rows), path)
    surfaces, lines = [], []
    for lineno, (r, t, n, d) in rows:
        radius = number(r, "radius", path, lineno)
        thickness = number(t, "thickness", path, lineno)
        index = number(n, "index", path, lineno, length=False)
        diameter = number(d, "aperture diameter", path, lineno)
        if index == 0.0:
            medium = AIR
        elif index == 1.0:
            medium = AIR
        else:
            medium = Medium(index, 0.0)
        kind = "stop" if radius == 0.0 else "spherical"
        surfaces.append(Surface(radius, thickness, medium, diameter / 2.0, kind))
        lines.append(lineno)
    meta = LensMetadata(name=name, focal_length=focal, notes="\n".join(notes) or None)
    return validated(Prescription(tuple(surfaces), meta), path, lines)


@takes_prescription
def dumps(p: Prescription) -> str:
    """pbrt ``.dat`` text for ``p``; :class:`ExportError` for what pbrt cannot hold.

    Refused: flat refracting surfaces, aspheres, cylinders (pbrt reads radius 0 as the
    stop and knows only spheres). Dropped with a :class:`PhysCamWarning`: Abbe numbers,
    focus groups, the anamorphic squeeze and metadata other than the notes.
    """
    for i, s in enumerate(p.surfaces):
        if s.kind not in ("spherical", "stop"):
            raise ExportError(
                f"lens {p.name!r}: surface {i} is {s.kind}; pbrt .dat holds only spheres and the stop "
                "(radius 0 is read as the stop). Write physcam TOML or Zemax instead"
            )
    dropped = []
    if any(s.medium.vd for s in p.surfaces):
        dropped.append("Abbe numbers (pbrt has no dispersion)")
    if p.focus is not None:
        dropped.append("focus groups")
    if p.squeeze != 1.0:
        dropped.append("anamorphic squeeze")
    if dropped:
        warnings.warn(f"pbrt .dat drops {', '.join(dropped)} of lens {p.name!r}", PhysCamWarning, stacklevel=3)
    out = []
    if p.metadata.notes:
        out += [one_line(f"# {line}").rstrip() for line in p.metadata.notes.splitlines()]
    out.append(f"# {HEADER}")
    for s in p.surfaces:
        if s.medium.is_air or (s.medium.nd == 1.0 and s.medium.vd == 0.0):
            index = 0.0 if s.is_stop else 1.0
        else:
            index = s.medium.nd
        radius = 0.0 if s.is_stop else s.radius
        out.append("\t".join(fmt(v) for v in (radius, s.thickness, index, 2.0 * s.semi_diameter)))
    return "\n".join(out) + "\n"
