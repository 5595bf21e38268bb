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
"""

import json
from pathlib import Path

from optiland.materials import AbbeMaterial, Material
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
            "relay_obna": (relay, 0.6328, ("objectNA", 0.02), 1.0, 150.0)}


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
    OUT.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
