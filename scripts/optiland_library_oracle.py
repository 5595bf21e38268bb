"""Paraxial EFL, BFL and f-number of every bundled lens by optiland, as a test oracle.

Writes tests/data/optiland_library.json. Run with optiland 0.6.3 in a throwaway venv (it is not a
physcam dependency)::

    python -m venv /tmp/olvenv && /tmp/olvenv/bin/pip install optiland==0.6.3
    /tmp/olvenv/bin/python scripts/optiland_library_oracle.py

Nothing of physcam is imported: each ``src/physcam/data/lenses/*.toml`` is parsed with ``tomllib``
and rebuilt as an optiland system (radii, thicknesses, the stop surface and its diameter, each
medium as optiland's ``IdealMaterial`` of the file's nd), evaluated at the d line (587.5618 nm)
with the object at infinity and the aperture "float by stop size" (the file's stop diameter). An
anamorphic lens is evaluated once per meridian as the rotationally symmetric lens of that
meridian's curvatures (a cylinder is flat in the meridian along its axis: ``cylindrical_x`` is
curved in X only, ``cylindrical_y`` in Y only), which is exact for the paraxial data of a
lens of crossed cylinders. Aspheric terms do not change paraxial data; the base radius is used.
"""

import json
import tomllib
from pathlib import Path

from optiland.materials import IdealMaterial
from optiland.optic import Optic

ROOT = Path(__file__).resolve().parents[1]
LENSES = ROOT / "src" / "physcam" / "data" / "lenses"
OUT = ROOT / "tests" / "data" / "optiland_library.json"
LINE_D_UM = 0.5875618


def _radius(s, meridian):
    flat = s["kind"] in ("flat", "stop") or s["radius"] == 0 or \
        (s["kind"] == "cylindrical_x" and meridian == "y") or (s["kind"] == "cylindrical_y" and meridian == "x")
    return float("inf") if flat else float(s["radius"])


def build(doc, meridian):
    o = Optic()
    o.add_surface(index=0, radius=float("inf"), thickness=float("inf"))
    stop_d = None
    for i, s in enumerate(doc["surface"], start=1):
        med = s["medium"]
        n = 1.0 if med == "air" else float(med["nd"])
        material = "air" if n == 1.0 else IdealMaterial(n=n)
        o.add_surface(index=i, radius=_radius(s, meridian), thickness=float(s["thickness"]), material=material,
                      is_stop=s["kind"] == "stop")
        if s["kind"] == "stop":
            stop_d = 2.0 * float(s["semi_diameter"])
    o.add_surface(index=len(doc["surface"]) + 1)
    o.set_aperture(aperture_type="float_by_stop_size", value=stop_d)
    o.set_field_type(field_type="angle")
    o.add_field(y=0)
    o.add_wavelength(value=LINE_D_UM, is_primary=True)
    return o


def _f(v) -> float:
    import numpy as np

    return float(np.asarray(v).ravel()[0])


def main():
    from importlib.metadata import version

    out = {"tool": f"optiland {version('optiland')}", "wavelength_um": LINE_D_UM, "lenses": {}}
    for path in sorted(LENSES.glob("*.toml")):
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
        squeeze = float(doc["lens"].get("squeeze", 1.0))
        cylinders = any(s["kind"].startswith("cylindrical") for s in doc["surface"])
        entry = {}
        for meridian in ("x", "y") if (cylinders or squeeze != 1.0) else ("y",):
            p = build(doc, meridian).paraxial
            last_t = float(doc["surface"][-1]["thickness"])
            entry[meridian] = {"efl_mm": _f(p.f2()), "f_number": _f(p.FNO()), "epd_mm": _f(p.EPD()),
                               "bfl_mm": _f(p.F2()) + last_t}
        out["lenses"][path.stem] = entry
        print(path.stem, entry)
    OUT.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
