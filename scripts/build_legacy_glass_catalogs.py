"""Write physcam's legacy glass catalogues (src/physcam/data/glass/SCHOTT_LEGACY.json, OHARA_LEGACY.json,
HIKARI_LEGACY.json, HOYA_LEGACY.json) from the public Zemax .agf files that carry the makers' obsolete glasses.

The sources (data/glass/SOURCES.md): Zemax OpticStudio's SCHOTT.AGF whose header reads "SCHOTT
Preferred optical glasses. 26th February 2008 plus B270 and obsolete glasses", and OHARA's own
catalogue "Updated 18.10.19" (standard, special-order and obsolete glasses), and HIKARI's catalogue
as Zemax distributed it ("Hikari Glass Co. Catalog", with its E- glasses), and HOYA's own
"20220711 HOYA Optical Glass Catalog" with its obsolete glasses, all as published in
the KrakenOS repository (GPL-3.0; the files are the makers' data, read here, never copied
whole)::

    BASE=https://raw.githubusercontent.com/Garchupiter/Kraken-Optical-Simulator/d86353370de44a01cb9fe14d871bc3fb46e472f2/KrakenOS/Cat
    for f in SCHOTT.AGF ohara.agf hikari.agf HOYA20220711_include_obsolete.agf; do curl -sLo /tmp/$f $BASE/$f; done
    .venv/bin/python scripts/build_legacy_glass_catalogs.py /tmp/SCHOTT.AGF /tmp/ohara.agf /tmp/hikari.agf \
        /tmp/HOYA20220711_include_obsolete.agf

Each file is read by physcam's own .agf reader (physcam.lens.agf, which checks every number), and
a glass is kept when physcam's current catalogue of that maker (SCHOTT.json, OHARA.json, from the
makers' spreadsheets) does not hold its name (spaces aside: OHARA's sheet writes "S-TIL 2"): SCHOTT's lead glasses (SK16, F15, SK1, SSK4A...),
BK7, B270; OHARA's names before the S- prefix (LAH64, FPL51...) and its withdrawn S- glasses;
HIKARI's E- glasses (E-BAF11, in Thorlabs' achromats) and other withdrawn ones; HOYA's obsolete
glasses (FD10, in Thorlabs' achromats). Per
glass: name, Zemax formula and coefficients (lambda in um), nd and Vd as on the NM line, the LD
range (nm), the 10 mm internal transmission rows, and the catalogue's status (Zemax's code:
0 standard, 1 preferred, 2 obsolete, 3 special, 4 melt).
"""

from __future__ import annotations

import datetime
import hashlib
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "src" / "physcam" / "data" / "glass"
STATUS = {0: "standard", 1: "preferred", 2: "obsolete", 3: "special", 4: "melt"}
SOURCE = {"SCHOTT": "Zemax SCHOTT.AGF, 'SCHOTT Preferred optical glasses. 26th February 2008 plus B270 and obsolete glasses'",
          "OHARA": "OHARA .agf catalogue, 'Updated 18.10.19'",
          "HIKARI": "Zemax HIKARI.AGF, 'Hikari Glass Co. Catalog (subsidiary of Nikon)'",
          "HOYA": "HOYA .agf catalogue, '20220711 HOYA Optical Glass Catalog' (obsolete glasses included)"}
MAKERS = ("SCHOTT", "OHARA", "HIKARI", "HOYA")


def _statuses(text: str) -> dict[str, int]:
    """Upper-case name -> the NM line's status field (its 8th token)."""
    out = {}
    for line in text.replace("\r", "\n").split("\n"):
        tok = line.split()
        if len(tok) >= 8 and tok[0] == "NM":
            out.setdefault(tok[1].upper(), int(float(tok[7])))
    return out


def build(maker: str, agf: Path) -> dict:
    sys.path.insert(0, str(ROOT / "src"))
    from physcam.lens.agf import _decode, _read_bytes, loads_agf

    data = _read_bytes(agf)
    text = _decode(data, str(agf))
    glasses = loads_agf(text, f"{maker}_LEGACY", str(agf))
    sheet = json.loads((OUT / f"{maker}.json").read_text(encoding="utf-8"))["glasses"]
    current = {g["name"].upper().replace(" ", "") for g in sheet}  # OHARA's sheet writes "S-TIL 2", its .agf "S-TIL2"
    status = _statuses(text)
    rows = []
    for key, g in glasses.items():
        if key.replace(" ", "") in current:
            continue
        row = {"name": g.name, "formula": g.formula, "coefficients": list(g.coefficients), "nd": g.nd, "vd": g.vd,
               "status": STATUS.get(status.get(key), "unknown")}
        if g.range_nm:
            row["range_nm"] = [round(v, 6) for v in g.range_nm]
        if g.transmission_10mm:
            row["transmission_10mm"] = [[round(lam, 6), tau] for lam, tau in g.transmission_10mm]
        if g.dpgf:
            row["dpgf"] = g.dpgf
        rows.append(row)
    return {"catalog": f"{maker}_LEGACY", "source": SOURCE[maker], "source_sha256": hashlib.sha256(data).hexdigest(),
            "built": datetime.date.today().isoformat(), "glasses": rows}


def main(argv: list[str]) -> None:
    if len(argv) != len(MAKERS):
        raise SystemExit("usage: build_legacy_glass_catalogs.py SCHOTT.AGF ohara.agf hikari.agf HOYA.agf "
                         "(module notes say where)")
    for maker, path in zip(MAKERS, argv):
        doc = build(maker, Path(path))
        text = json.dumps(doc, separators=(",", ":"), ensure_ascii=False)
        (OUT / f"{maker}_LEGACY.json").write_text(text + "\n", encoding="utf-8")
        print(f"{maker}_LEGACY: {len(doc['glasses'])} glasses")


if __name__ == "__main__":
    main(sys.argv[1:])
