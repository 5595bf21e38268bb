#!/usr/bin/env python
"""Convert every reference lens file into physcam's bundled library (physcam TOML).

    .venv/bin/python scripts/build_lens_library.py [--reference DIR] [--out DIR] [--force]

Reads ../shared/reference/lenses/ (or tests/data/reference_lenses/){pbrt-dat,iset-json,physical-camera-toml} with
physcam's own readers, adds curated metadata and provenance, applies the documented
corrections below (only where the original file does not describe a buildable lens or
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

from physcam.lens.formats import read_lens, seedtoml, write_lens  # noqa: E402
from physcam.lens.formats._common import json_text, parse_toml, read_text  # noqa: E402
from physcam.lens.geometry import sag  # noqa: E402
from physcam.lens.prescription import Medium, Prescription, Surface  # noqa: E402

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


# ---- a minimal paraxial (y, nu) trace in the Y meridian, only to size stops -----------
def _trace_y(surfaces, y, u, upto):
    n = 1.0
    for s in surfaces[:upto]:
        n2 = s.medium.nd
        u = (n * u - y * s.curvature_y * (n2 - n)) / n2
        n = n2
        y += s.thickness * u
    return y, u


def _efl(surfaces):
    y, u = 1.0, 0.0
    n = 1.0
    for i, s in enumerate(surfaces):
        n2 = s.medium.nd
        u = (n * u - y * s.curvature_y * (n2 - n)) / n2
        n = n2
        if i < len(surfaces) - 1:
            y += s.thickness * u
    return -1.0 / u


def _surfaces(doc):
    rows = doc["surface"]
    out = []
    for r in rows:
        kind = r.get("type") or ("flat" if r["radius"] == 0 else "spherical")
        out.append(Surface(r["radius"], r["thickness"], Medium(r["ior"], r.get("abbe_v", 0.0)), r["aperture"] / 2,
                           kind, r.get("conic", 0.0), tuple(r.get("aspheric_coeffs", ()))))
    return out


def f_number(doc):
    """Paraxial f/# = EFL / entrance-pupil diameter with the file's stop (infinity focus)."""
    s = _surfaces(doc)
    k = next(i for i, x in enumerate(s) if x.kind == "stop")
    y_stop, _ = _trace_y(s, 1.0, 0.0, k)  # marginal ray of unit height on the first surface
    epd = 2.0 * s[k].semi_diameter / abs(y_stop)
    return _efl(s) / epd


# ---- corrections ---------------------------------------------------------------------
def halve_apertures(doc):
    before = f_number(doc)
    for r in doc["surface"]:
        r["aperture"] = r["aperture"] / 2.0
    return (f"all 'aperture' values halved: the file's values are twice the clear diameters (with them the "
            f"paraxial f-number is f/{before:.2f} against the engraved f/{doc['lens']['max_fstop']:g}, and some "
            f"semi-diameters exceed their surface radius); halved, f/{f_number(doc):.2f}")


def stop_from_fnumber(doc):
    """Stop diameter such that the entrance pupil gives the engraved f-number (pupil magnification)."""
    k = next(i for i, r in enumerate(doc["surface"]) if r.get("type") == "stop")
    old = doc["surface"][k]["aperture"]
    old_z = doc["surface"][k - 1]["thickness"]
    gap = old_z + doc["surface"][k]["thickness"]
    n_max = doc["lens"]["max_fstop"]
    for _ in range(20):  # stop size and position interact slightly: iterate to convergence
        doc["surface"][k]["aperture"] *= f_number(doc) / n_max
        move_stop_clear(doc, record=False)
    new = doc["surface"][k]["aperture"] = round(doc["surface"][k]["aperture"], 3)
    return (f"stop diameter {old:g} mm equals the entrance-pupil diameter EFL/N, but the front group magnifies "
            f"the stop; set to {new:g} mm so the paraxial f-number is the engraved f/{n_max:g} "
            f"(now f/{f_number(doc):.3f}); and the stop moved within its air gap from {old_z:g} mm to "
            f"{doc['surface'][k - 1]['thickness']:g} mm behind surface {k - 1} (gap {gap:g} mm and all glass "
            "unchanged) because at the file's position the stop plane lies inside the neighbouring curved "
            "surface's sag")


def move_stop_clear(doc, record=True, clearance=0.05):
    """Move the stop inside its air gap (glass unchanged) so its plane clears both neighbours."""
    s = _surfaces(doc)
    k = next(i for i, x in enumerate(s) if x.kind == "stop")
    prev, stop, nxt = s[k - 1], s[k], s[k + 1]
    gap = prev.thickness + stop.thickness
    lower = max(0.0, max(sag(prev, min(prev.semi_diameter, stop.semi_diameter), a) for a in "xy")) + clearance
    upper = gap + min(0.0, min(sag(nxt, min(nxt.semi_diameter, stop.semi_diameter), a) for a in "xy")) - clearance
    if lower > upper:
        raise SystemExit(f"{doc['lens']['name']}: no room for the stop in its air gap")
    z = round(min(max(prev.thickness, lower), upper), 3)
    old = prev.thickness
    doc["surface"][k - 1]["thickness"] = z
    doc["surface"][k]["thickness"] = round(gap - z, 6)
    if record:
        return (f"stop moved within its air gap from {old:g} mm to {z:g} mm behind surface {k - 1} (gap "
                f"{gap:g} mm kept) so the stop plane clears the curved neighbours at the stop's semi-diameter")
    return None


def clip_pair(doc, i, clearance=0.05):
    """Reduce the semi-diameters of surfaces i, i+1 to where their edges clear each other."""
    s = _surfaces(doc)
    a, b = s[i], s[i + 1]

    def overlap(h):
        return max(sag(a, h, ax) - (a.thickness + sag(b, h, ax)) for ax in "xy") + clearance

    lo, hi = 0.0, min(a.semi_diameter, b.semi_diameter)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if overlap(mid) < 0 else (lo, mid)
    h = int(lo * 100) / 100.0
    old = (doc["surface"][i]["aperture"], doc["surface"][i + 1]["aperture"])
    for j in (i, i + 1):
        doc["surface"][j]["aperture"] = min(doc["surface"][j]["aperture"], 2 * h)
    return (f"clear diameters of surfaces {i} and {i + 1} reduced from {old[0]:g}/{old[1]:g} mm to "
            f"{2 * h:g} mm: at the file's values the two surfaces cross inside the aperture")


CORRECTIONS = {
    "canon_rf_85mm_f1_2.toml": [halve_apertures],
    "zuiko_18mm_f3_5.toml": [halve_apertures],
    "nikkor_fisheye_16mm_f2_8.toml": [halve_apertures, lambda d: clip_pair(d, 1)],
    "cooke_triplet_50mm_f4_5.toml": [stop_from_fnumber],
    "tessar_50mm_f2_8.toml": [stop_from_fnumber],
    "neil_front_anamorphic_2x.toml": [lambda d: clip_pair(d, 5)],
}


def convert(path: Path, fmt: str, folder: str) -> tuple[str, Prescription]:
    original_file = f"{folder}/{path.name}"
    corrections: list[str] = []
    if fmt == "seed-toml":
        text = read_text(path)
        doc = parse_toml(text, path)
        for fix in CORRECTIONS.get(path.name, []):
            note = fix(doc)
            if note:
                corrections.append(note)
        p = seedtoml.loads_document(doc, text, str(path))
        slug = path.stem
        meta = dataclasses.replace(
            p.metadata, source=f"Blender 'Physical Camera' extension addon/lenses/{path.name}")
        aliases = [path.name]
    else:
        p = read_lens(path, fmt)
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
    ap.add_argument("--out", default=str(ROOT / "src/physcam/data/lenses"))
    ap.add_argument("--force", action="store_true", help="overwrite existing library files")
    args = ap.parse_args(argv)
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
