"""Paraxial EFL, BFL, f-number and entrance pupil of every bundled zoom lens at each tabulated position, by optiland.

Writes tests/data/optiland_zoom.json, the independent oracle of tests/optics/test_zoom_optics.py. Run
with optiland 0.6.3 in a throwaway venv (not a physcam dependency)::

    python -m venv /tmp/olvenv && /tmp/olvenv/bin/pip install optiland==0.6.3
    /tmp/olvenv/bin/python scripts/optiland_zoom_oracle.py

Nothing of physcam is imported: each zoom file (``src/physcam/data/lenses/*.toml`` with a ``[zoom]``
table) is parsed with ``tomllib``, and each tabulated position is built as one optiland system with
the gaps of that position (``[[zoom.gap]] thickness[k]``), the stop of that position (``[zoom]
stop_semi_diameter[k]`` where tabulated, else the surface's), each medium an ``IdealMaterial`` of the
file's nd, at the d line with the object at infinity and the aperture "float by stop size": single
configurations built from the same data, as issue 45 asks.
"""

import json
import tomllib
from pathlib import Path

from optiland.materials import IdealMaterial
from optiland.optic import Optic

ROOT = Path(__file__).resolve().parents[1]
LENSES = ROOT / "src" / "physcam" / "data" / "lenses"
OUT = ROOT / "tests" / "data" / "optiland_zoom.json"
LINE_D_UM = 0.5875618


def build(doc, k):
    zoom = doc["zoom"]
    gaps = {g["surface"]: g["thickness"][k] for g in zoom["gap"]}
    o = Optic()
    o.add_surface(index=0, radius=float("inf"), thickness=float("inf"))
    stop_d = None
    for i, s in enumerate(doc["surface"]):
        med = s["medium"]
        n = 1.0 if med == "air" else float(med["nd"])
        flat = s["kind"] in ("flat", "stop") or s["radius"] == 0
        o.add_surface(index=i + 1, radius=float("inf") if flat else float(s["radius"]),
                      thickness=float(gaps.get(i, s["thickness"])), material="air" if n == 1.0 else IdealMaterial(n=n),
                      is_stop=s["kind"] == "stop")
        if s["kind"] == "stop":
            semi = zoom["stop_semi_diameter"][k] if "stop_semi_diameter" in zoom else s["semi_diameter"]
            stop_d = 2.0 * float(semi)
    o.add_surface(index=len(doc["surface"]) + 1)
    o.set_aperture(aperture_type="float_by_stop_size", value=stop_d)
    o.set_field_type(field_type="angle")
    o.add_field(y=0)
    o.add_wavelength(value=LINE_D_UM, is_primary=True)
    return o, float(gaps.get(len(doc["surface"]) - 1, doc["surface"][-1]["thickness"]))


def _f(v) -> float:
    import numpy as np

    return float(np.asarray(v).ravel()[0])


def main():
    from importlib.metadata import version

    out = {"tool": f"optiland {version('optiland')}", "wavelength_um": LINE_D_UM, "lenses": {}}
    for path in sorted(LENSES.glob("*.toml")):
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
        if "zoom" not in doc:
            continue
        rows = []
        for k in range(len(doc["zoom"]["gap"][0]["thickness"])):
            o, last_t = build(doc, k)
            p = o.paraxial
            rows.append({"efl_mm": _f(p.f2()), "f_number": _f(p.FNO()), "epd_mm": _f(p.EPD()),
                         "bfl_mm": _f(p.F2()) + last_t, "ep_from_front_vertex_mm": _f(p.EPL())})
        out["lenses"][path.stem] = rows
        print(path.stem, rows)
    OUT.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
