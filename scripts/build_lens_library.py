#!/usr/bin/env python
"""Convert every reference lens file into drafts of physcam's bundled library (physcam TOML).

    .venv/bin/python scripts/build_lens_library.py --out DRAFTS/ [--reference DIR] [--force]

The bundled files (``src/physcam/data/lenses``) were made by this script and are since kept by
hand: each carries a provenance record (issue 44, docs/lens-library.md) and catalogue glasses that
the drafts do not have, so the script writes drafts to compare with them, never over them.

Reads ../shared/reference/lenses/ (or tests/data/reference_lenses/){pbrt-dat,iset-json,physical-camera-toml} with
physcam's own readers (without validation), adds curated metadata and provenance, applies the
documented corrections, decided and made by ``physcam.lens.repair.propose`` -- the code behind
``physcam lens fix`` -- (only where the original file does not describe a buildable lens or
contradicts its own engraved f-number), validates, and writes
``src/physcam/data/lenses/<slug>.toml``. Every correction is recorded in the lens's
``[provenance] corrections`` and in docs/lens-formats.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from physcam.lens.check import read_raw  # noqa: E402
from physcam.lens.formats import write_lens  # noqa: E402
from physcam.lens.formats._common import json_text  # noqa: E402
from physcam.lens.prescription import Prescription  # noqa: E402
from physcam.lens.repair import propose  # noqa: E402

# Curated metadata for the formats that carry none (from SOURCES.md and the files' comments).
PBRT_ISET_META = {
    "dgauss.50mm.dat": dict(
        name="Double Gauss 50mm f/2 (pbrt dgauss.50mm)", patent="US 2,673,491 (Tronnier)", focal_length=50.0,
        max_fstop=2.0, source="pbrt-v4-scenes lenses/dgauss.50mm.dat; W. J. Smith, Modern Lens Design, p. 312, "
        "scaled to 50 mm from 100 mm"),
    "fisheye.10mm.dat": dict(
        name="Fisheye 10mm f/4 (pbrt fisheye.10mm)", patent="Muller 16mm f/4 fisheye", focal_length=10.0,
        max_fstop=4.0, source="pbrt-v4-scenes lenses/fisheye.10mm.dat; Smith, Modern Lens Design, p. 164, "
        "scaled to 10 mm from 100 mm"),
    "telephoto.250mm.dat": dict(
        name="Telephoto 250mm f/5.6 (pbrt telephoto.250mm)", patent="Sigler super-achromatic telephoto",
        focal_length=250.0, max_fstop=5.6, source="pbrt-v4-scenes lenses/telephoto.250mm.dat; Smith, Modern "
        "Lens Design, p. 175, scaled to 250 mm from 100 mm"),
    "dgauss.77deg.3.5201mm.json": dict(
        name="Double Gauss 3.52mm (isetlens dgauss.77deg.3.5201mm)", focal_length=3.5201, max_fstop=None,
        source="isetlens data/lens/dgauss.77deg.3.5201mm.json (pbrt's dgauss.50mm scaled by 0.0699)"),
}


# ---- corrections: physcam.lens.repair.propose decides and makes them (also `physcam lens fix`) ----
def corrected(path: Path, fmt: str):
    """The file read without validation and repaired by :func:`physcam.lens.repair.propose`:
    ``(prescription, [messages])``; a file that needs nothing comes back as read."""
    raw = read_raw(path, fmt)
    q, repairs = propose(raw.prescription)
    return q, [r.message for r in repairs]


def convert(path: Path, fmt: str, folder: str) -> tuple[str, Prescription]:
    original_file = f"{folder}/{path.name}"
    corrections: list[str] = []
    p, corrections = corrected(path, fmt)
    if fmt == "seed-toml":
        slug = path.stem
        meta = dataclasses.replace(
            p.metadata, source=f"Blender 'Physical Camera' extension addon/lenses/{path.name}")
        aliases = [path.name]
    else:
        slug = path.name.rsplit(".", 1)[0].replace(".", "_").lower()
        cur = PBRT_ISET_META[path.name]
        notes = p.metadata.notes
        meta = dataclasses.replace(p.metadata, **cur, notes=notes)
        aliases = [path.name, path.name.rsplit(".", 1)[0]]
        if p.metadata.name not in aliases and fmt == "iset":
            aliases.append(p.metadata.name)  # the file's own 'name' field
            corrections.append(
                f"name: the file's 'name' field says {p.metadata.name!r} but the lens has EFL 3.52 mm as its file "
                "name says (the shape is pbrt's dgauss.50mm scaled by 0.0699); the file name is used, the field "
                "kept as an alias")
    extras = dict(p.extras)
    extras["provenance.original_file"] = json_text(original_file)
    extras["provenance.original_format"] = json_text(fmt)
    extras["provenance.aliases"] = json_text(aliases)
    if corrections:
        extras["provenance.corrections"] = json_text(corrections)
    p = dataclasses.replace(p, metadata=meta, extras=tuple(sorted(extras.items())))
    p.validate()
    return slug, p


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--reference", default=str(Path(__file__).resolve().parents[1] / "tests" / "data" / "reference_lenses"))
    ap.add_argument("--out", required=True, help="folder for the drafts (not the bundled library: it is kept by hand)")
    ap.add_argument("--force", action="store_true", help="overwrite existing library files")
    args = ap.parse_args(argv)
    if Path(args.out).resolve() == (ROOT / "src/physcam/data/lenses").resolve():
        ap.error("the bundled library is kept by hand (provenance records): write the drafts elsewhere and compare")
    ref = Path(args.reference)
    jobs = [(f, "pbrt", "pbrt-dat") for f in sorted((ref / "pbrt-dat").glob("*.dat"))]
    jobs += [(f, "iset", "iset-json") for f in sorted((ref / "iset-json").glob("*.json"))]
    jobs += [(f, "seed-toml", "physical-camera-toml") for f in sorted((ref / "physical-camera-toml").glob("*.toml"))]
    for path, fmt, folder in jobs:
        slug, p = convert(path, fmt, folder)
        out = Path(args.out) / f"{slug}.toml"
        write_lens(p, out, "physcam", force=args.force)
        fixes = json.loads(dict(p.extras).get("provenance.corrections", "[]"))
        print(f"{slug:32s} {len(p.surfaces):3d} surfaces  {'corrected: ' + str(len(fixes)) if fixes else ''}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
