"""Paraxial data of every bundled anamorphic lens, per meridian, by optiland, as a test oracle (issue 49).

Writes tests/data/optiland_anamorphic.json: for each lens with cylinders and each meridian, the EFL,
f-number, entrance-pupil diameter and the **entrance-pupil position** (optiland's ``EPL``: from the
first surface, + toward the image), at the d line with the object at infinity. Built exactly as
scripts/optiland_library_oracle.py builds a lens (the meridian's curvatures, ``IdealMaterial`` of the
file's nd, "float by stop size"); run it the same way, in a throwaway venv with optiland 0.6.3::

    python -m venv /tmp/olvenv && /tmp/olvenv/bin/pip install optiland==0.6.3
    /tmp/olvenv/bin/python scripts/optiland_anamorphic_oracle.py

Nothing of physcam is imported.
"""

import json
import sys
import tomllib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from optiland_library_oracle import LENSES, LINE_D_UM, _f, build  # noqa: E402

OUT = Path(__file__).resolve().parents[1] / "tests" / "data" / "optiland_anamorphic.json"


def main():
    from importlib.metadata import version

    out = {"tool": f"optiland {version('optiland')}", "wavelength_um": LINE_D_UM,
           "epl": "entrance pupil from the first surface, mm, + toward the image", "lenses": {}}
    for path in sorted(LENSES.glob("*.toml")):
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
        if not any(s["kind"].startswith("cylindrical") for s in doc["surface"]):
            continue
        entry = {}
        for meridian in ("x", "y"):
            p = build(doc, meridian).paraxial
            entry[meridian] = {"efl_mm": _f(p.f2()), "f_number": _f(p.FNO()), "epd_mm": _f(p.EPD()),
                               "epl_mm": _f(p.EPL())}
        out["lenses"][path.stem] = entry
        print(path.stem, entry)
    OUT.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
