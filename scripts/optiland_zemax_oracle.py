"""Paraxial EFL, BFL and f-number of the hand-written Zemax test lenses by optiland, as a test oracle.

Writes tests/data/optiland_zemax.json. Run with optiland 0.6.3 in a throwaway venv (it is not a
physcam dependency)::

    python -m venv /tmp/olvenv && /tmp/olvenv/bin/pip install optiland==0.6.3
    /tmp/olvenv/bin/python scripts/optiland_zemax_oracle.py

The lenses are built here from the same numbers as tests/data/zemax/*.zmx (radii = 1/CURV,
thicknesses, semi-diameters, the stop surface), with optiland's own glass data
(refractiveindex.info, SCHOTT and OHARA pages) for the catalogue glasses and its Abbe
model for the model glasses, so nothing of physcam's glass data or Zemax reader is shared.
The stop on a lens face is optiland's stop on that same face. The aperture is each file's own
(ENPD -> optiland "EPD", FNUM n 0 -> "imageFNO", OBNA na 0 -> "objectNA"), with the object
at the file's distance (the object surface's DISZ), so optiland sizes the pupil itself; "epd_mm"
is optiland's entrance-pupil diameter. optiland's F2 is the rear focal point from the image surface, divided
by the image-space index (a reduced distance); it is multiplied back and the last thickness
added: the BFL from the last lens vertex that physcam reports.

Issue 40 item 15 adds Thorlabs' negative lenses (a stop on a concave first face, a virtual image
behind the lens: LC1120-A, LD1170-B, ACN254-050-A) and the B270 condenser ACL3026U, built from
the numbers of Thorlabs' published .zmx with optiland's own glasses (B270: SCHOTT's 1993 data
sheet, a source independent of the Zemax catalogue physcam reads), and a double Gauss in SCHOTT's
legacy glasses (SK16, SK1, F15, SSK4A). optiland's own lookup has no such glasses and takes
others of similar name (F15 -> SF15, SK1 -> HIKARI SK16: it says so in a warning), so the legacy
lens is built twice: with the legacy glasses' Sellmeier coefficients as printed in Zemax's
SCHOTT.AGF (2008; the CD lines, written here as refractiveindex.info "formula 2" files that
optiland evaluates itself), and with optiland's lookup, whose EFL is kept as
"efl_mm_optiland_lookup" to show the substitution physcam does not make.
"""

import json
import tempfile
from pathlib import Path

from optiland.materials import AbbeMaterial, Material, MaterialFile
from optiland.optic import Optic

OUT = Path(__file__).resolve().parents[1] / "tests" / "data" / "optiland_zemax.json"


def build(surfaces, wavelength_um, aperture, object_distance=float("inf")):
    o = Optic()
    o.add_surface(index=0, radius=float("inf"), thickness=object_distance)
    for i, s in enumerate(surfaces, start=1):
        kw = dict(index=i, radius=s["r"], thickness=s.get("t", 0.0), material=s.get("m", "air"),
                  is_stop=s.get("stop", False))
        if "k" in s:
            kw.update(surface_type="even_asphere", conic=s["k"], coefficients=[0.0] + s["a"])
        o.add_surface(**kw)
    o.add_surface(index=len(surfaces) + 1)
    o.set_aperture(aperture_type=aperture[0], value=aperture[1])
    o.set_field_type(field_type="angle")
    o.add_field(y=0)
    o.add_wavelength(value=wavelength_um, is_primary=True)
    return o


def lenses():
    sk16, f2 = Material("N-SK16", reference="SCHOTT"), Material("F2", reference="SCHOTT")
    inf = float("inf")
    cooke = [dict(r=1 / 4.542681e-2, t=3.25896, m=sk16), dict(r=1 / -2.294840e-3, t=6.007573),
             dict(r=1 / -4.501812e-2, t=0.99997, m=f2), dict(r=1 / 4.928050e-2, t=4.750409, stop=True),
             dict(r=1 / 1.254963e-2, t=2.952076, m=sk16), dict(r=1 / -5.436166e-2, t=42.20778)]
    lah64 = Material("S-LAH64", reference="OHARA")
    asphere = [dict(r=1 / 0.1085776, t=4.2, m=lah64, stop=True, k=-0.6478, a=[3.6e-5, 1.2e-7]),
               dict(r=1 / -0.0125, t=12.5)]
    water = AbbeMaterial(1.333, 55.8)
    doublet = [dict(r=inf, t=2.0, stop=True), dict(r=1 / 0.0325, t=4.0, m=AbbeMaterial(1.62, 60.3)),
               dict(r=1 / -0.0410, t=2.0, m=AbbeMaterial(1.72, 29.5)), dict(r=1 / -0.0080, t=38.0, m=water)]
    bk7 = Material("N-BK7", reference="SCHOTT")
    relay = [dict(r=60.0, t=5.0, m=bk7), dict(r=-45.0, t=2.0, m=AbbeMaterial(1.6, 50.0)), dict(r=-200.0, t=5.0),
             dict(r=inf, t=318.0, stop=True)]
    return {"cooke_triplet": (cooke, 0.5875618, ("EPD", 10.0), 1.0, inf),
            "asphere_780nm": (asphere, 0.78, ("imageFNO", 2.5), 1.0, inf),
            "water_doublet": (doublet, 0.5875618, ("EPD", 8.0), 1.333, inf),
            "relay_obna": (relay, 0.6328, ("objectNA", 0.02), 1.0, 150.0),
            **thorlabs(), **legacy_double_gauss(LEGACY)}


def thorlabs():
    """Thorlabs' lenses as in tests/data/zemax/thorlabs_*.zmx (the numbers of Thorlabs' .zmx)."""
    inf = float("inf")
    bk7 = Material("N-BK7", reference="SCHOTT")
    lc1120 = [dict(r=1 / -1.943256898561989900e-002, t=4.0, m=bk7, stop=True), dict(r=inf, t=-1.010940419263e2)]
    ld1170 = [dict(r=1 / -1.284521515735390100e-002, t=3.5, m=bk7, stop=True),
              dict(r=1 / 1.284521515735390100e-002, t=-7.384151953028e1)]
    acn = [dict(r=1 / -2.944640753828030000e-002, t=2.0, m=Material("N-BAF10", reference="SCHOTT"), stop=True),
           dict(r=1 / 3.075976622577670000e-002, t=4.5, m=Material("N-SF6HT", reference="SCHOTT")),
           dict(r=1 / 5.284574327537899800e-003, t=-5.288445773232e1)]
    acl = [dict(r=inf, t=5.0), dict(r=1 / 7.379474728988791300e-002, t=11.9, m=Material("B270"), stop=True,
                                    k=-0.6301, a=[5.513e-6]), dict(r=inf, t=1.809209481007e1)]
    return {"thorlabs_LC1120-A": (lc1120, 0.5876, ("EPD", 2.208581163847e1), 1.0, inf),
            "thorlabs_LD1170-B": (ld1170, 0.5876, ("EPD", 2.235211691777e1), 1.0, inf),
            "thorlabs_ACN254-050-A": (acn, 0.5876, ("EPD", 2.090499755177e1), 1.0, inf),
            "thorlabs_ACL3026U": (acl, 0.587, ("EPD", 27.0), 1.0, inf)}


#: SCHOTT's legacy glasses as Zemax's SCHOTT.AGF (2008) prints them: CD line (B1 C1 B2 C2 B3 C3), LD (um).
LEGACY = {"SK16": ((1.34317774, 7.04687339e-3, 0.241144399, 2.29005e-2, 0.994317969, 92.7508526), (0.31, 2.5)),
          "SK1": ((1.23997939, 6.76460788e-3, 0.308829519, 2.33830716e-2, 1.03366266, 114.585882), (0.334, 2.325)),
          "F15": ((1.31031527, 9.5403489e-3, 0.202636884, 4.55807051e-2, 0.920049222, 109.864711), (0.334, 2.325)),
          "SSK4A": ((1.38336169, 7.87154985e-3, 0.187125107, 2.89352221e-2, 0.944170902, 105.742424), (0.334, 2.325))}


def _rii_file(folder: Path, name: str, coefficients, span) -> MaterialFile:
    """A refractiveindex.info "formula 2" file (n^2 - 1 = sum B l^2 / (l^2 - C)) of one glass."""
    f = folder / f"{name}.yml"
    f.write_text("DATA:\n  - type: formula 2\n    wavelength_range: " + " ".join(map(repr, span)) +
                 "\n    coefficients: 0 " + " ".join(map(repr, coefficients)) + "\n", encoding="utf-8")
    return MaterialFile(str(f))


def legacy_double_gauss(glasses):
    """tests/data/zemax/double_gauss_legacy.zmx: US 2,673,491's geometry with SCHOTT legacy glasses."""
    folder = Path(tempfile.mkdtemp())
    real = {n: _rii_file(folder, n, c, span) for n, (c, span) in glasses.items()}
    R = [29.475, 84.83, 19.275, 40.77, 12.75, float("inf"), -14.495, 40.77, -20.385, 437.065, -39.73]
    T = [3.76, 0.12, 4.025, 3.275, 5.705, 4.5, 1.18, 6.065, 0.19, 3.22, 45.4756]
    G = ["SK16", None, "SK1", "F15", None, None, "F15", "SSK4A", None, "SK16", None]
    surfaces = [dict(r=r, t=t, m=real[g] if g else "air", stop=(k == 5)) for k, (r, t, g) in enumerate(zip(R, T, G))]
    return {"double_gauss_legacy": (surfaces, 0.5875618, ("EPD", 20.0), 1.0, float("inf"))}


def optiland_lookup_efl() -> float:
    """EFL of the legacy double Gauss with optiland's own lookup of the glass names (it substitutes;
    SSK4A it does not find at all, so that one keeps the real glass)."""
    surfaces = legacy_double_gauss(LEGACY)["double_gauss_legacy"][0]
    names = iter(["SK16", "SK1", "F15", "F15", "SSK4A", "SK16"])
    for s in surfaces:
        if s["m"] != "air":
            try:
                s["m"] = Material(next(names))
            except ValueError:
                pass
    return _f(build(surfaces, 0.5875618, ("EPD", 20.0)).paraxial.f2())


def _f(v) -> float:
    import numpy as np

    return float(np.asarray(v).ravel()[0])


def main():
    from importlib.metadata import version

    out = {"tool": f"optiland {version('optiland')}", "lenses": {}}
    for name, (surfaces, wl, aperture, n_image, distance) in lenses().items():
        o = build(surfaces, wl, aperture, distance)
        p = o.paraxial
        out["lenses"][name] = {"wavelength_um": wl, "efl_mm": _f(p.f2()), "bfl_mm": _f(p.F2()) * n_image + surfaces[-1]["t"],
                               "f_number": _f(p.FNO()), "epd_mm": _f(p.EPD()), "image_index": n_image,
                               "aperture": list(aperture), "object_distance_mm": None if distance == float("inf") else distance}
        print(name, out["lenses"][name])
    out["lenses"]["double_gauss_legacy"]["efl_mm_optiland_lookup"] = optiland_lookup_efl()
    OUT.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
