"""Write physcam's glass catalogues (src/physcam/data/glass/*.json) from the makers' own spreadsheets.

The spreadsheets are the ones redistributed inside the PyPI wheel ``opticalglass`` 1.1.1 (its
``opticalglass/data`` folder: SCHOTT.xls, OHARA.xlsx, HOYA.xlsx, CDGM.xls, HIKARI.xlsx, SUMITA.xlsx
and the ``*_prev`` previous editions). The wheel is only unzipped, never installed or imported::

    pip download opticalglass==1.1.1 --no-deps -d /tmp/og && (cd /tmp/og && unzip -o *.whl -d whl)
    python -m venv /tmp/gvenv && /tmp/gvenv/bin/pip install xlrd openpyxl
    /tmp/gvenv/bin/python scripts/build_glass_catalogs.py /tmp/og/whl/opticalglass/data

Per glass the JSON keeps: the name, the maker's dispersion formula as a Zemax formula number
(1 Schott, 2 Sellmeier 1, 13 Extended 3) with its coefficients (lambda in um), nd and Vd as printed,
the maker's printed indices at C, d, F, g, the span of wavelengths the maker tabulates indices for
(nm; the formula's stated range), the 10 mm internal transmission table (nm, tau) where given, and
``previous`` for a glass found only in the previous edition. Columns are fixed per maker and checked
against the header text, so a changed spreadsheet fails loudly instead of filling wrong columns.
"""

from __future__ import annotations

import datetime
import json
import re
import sys
from pathlib import Path

OUT = Path(__file__).resolve().parents[1] / "src" / "physcam" / "data" / "glass"
LINE_NM = {"t": 1013.98, "s": 852.11, "r": 706.52, "C": 656.27, "C'": 643.85, "D": 589.29, "d": 587.56,
           "e": 546.07, "F": 486.13, "F'": 479.99, "g": 435.83, "h": 404.66, "i": 365.01}


def rows(path: Path):
    if path.suffix == ".xls":
        import xlrd
        sh = xlrd.open_workbook(str(path)).sheet_by_index(0)
        return [sh.row_values(i) for i in range(sh.nrows)]
    import openpyxl
    wb = openpyxl.load_workbook(str(path), read_only=True, data_only=True)
    return [list(r) for r in wb.worksheets[0].iter_rows(values_only=True)]


def num(v):
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return float(v)
    try:
        return float(str(v).strip())
    except ValueError:
        return None


def header(R, k, nhead):
    return " ".join(" ".join(str(R[i][k]).split()) for i in range(nhead) if k < len(R[i]) and R[i][k] not in (None, ""))


def last_number(text):
    """The wavelength of a transmission column: the header's last number ('TAUI10/2500', '280nm')."""
    found = re.findall(r"(\d+(?:\.\d+)?)", text)
    return float(found[-1]) if found else None


# Per maker: header rows, name column, nd, vd, coefficient columns, C d F g columns, index columns for
# the span, 10 mm transmission columns, formula, expected header words (checked).
MAKERS = {
    "SCHOTT": dict(file="SCHOTT.xls", prev="SCHOTT_prev.xls", nhead=4, name=0, nd=1, vd=3, coef=range(6, 12),
                   lines=(123, 127, 129, 131), span=range(116, 139), tau=range(67, 97), formula=2,
                   check={0: "Glass", 6: "B1", 11: "C3", 123: "nC", 131: "ng", 67: "TAUI10"}),
    "OHARA": dict(file="OHARA.xlsx", prev="OHARA_prev.xlsx", nhead=2, name=1, nd=16, vd=26, coef=range(60, 66),
                  lines=(12, 16, 18, 21), span=range(4, 24), tau=range(80, 112), formula=2,
                  check={1: "Glass", 60: "A1", 65: "B3", 12: "nC", 21: "ng", 80: "TRANSMISSION"}),
    "HOYA": dict(file="HOYA.xlsx", prev="HOYA_prev.xlsx", nhead=4, name=2, nd=4, vd=5, coef=range(28, 40),
                 lines=(16, 20, 22, 24), span=range(10, 27), tau=range(463, 507), formula=1,
                 check={2: "Glass", 28: "A0", 39: "A5pow", 16: "nC", 24: "ng", 463: "10mmt"}),
    "CDGM": dict(file="CDGM.xls", prev=None, nhead=2, name=0, nd=9, vd=17, coef=range(21, 27),
                 lines=(5, 9, 11, 13), span=range(2, 16), tau=range(106, 141), formula=1,
                 check={0: "Glass", 21: "A0", 26: "A5", 5: "nc", 13: "ng", 106: "10mm"}),
    "HIKARI": dict(file="HIKARI.xlsx", prev=None, nhead=3, name=0, nd=16, vd=24, coef=range(55, 64),
                   lines=(12, 16, 18, 20), span=range(3, 24), tau=range(102, 134), formula=13,
                   check={55: "nine", 63: "A8", 12: "C 0.656273", 20: "g 0.435835", 102: "280nm"}),
    "SUMITA": dict(file="SUMITA.xlsx", prev=None, nhead=2, name=2, nd=15, vd=3, coef=range(47, 53),
                   lines=(12, 15, 17, 19), span=range(7, 22), tau=range(105, 132), formula=1,
                   check={2: "GNAME", 47: "A0", 52: "A5", 12: "nC", 19: "ng", 105: "T2_270", 104: "T2_thick"}),
}


def span_nm(head: str) -> float | None:
    """Wavelength of an index column from its header: '1529.6', 'n2325.4', 'nC', 'C 0.656273'."""
    for tok in head.replace("|", " ").split():
        t = tok[1:] if tok[:1] == "n" and len(tok) > 1 else tok
        if t in LINE_NM:
            return LINE_NM[t]
        v = num(t)
        if v is not None and v > 0:
            return v * 1000.0 if v < 3.0 else v
    return None


def coefficients(R, r, cfg):
    vals = [num(R[r][k]) for k in cfg["coef"]]
    if any(v is None for v in vals):
        return None
    if cfg is MAKERS["HOYA"]:
        vals = [float(f"{m * 10.0 ** e:.10g}") for m, e in zip(vals[::2], vals[1::2])]
    if cfg["formula"] == 2:  # sheet order B1 B2 B3 C1 C2 C3 -> Zemax Sellmeier 1 order K1 L1 K2 L2 K3 L3
        b, c = vals[:3], vals[3:]
        vals = [b[0], c[0], b[1], c[1], b[2], c[2]]
    return vals


def read(path: Path, cfg, previous: bool):
    R = rows(path)
    nhead = cfg["nhead"]
    if not previous:
        for k, word in cfg["check"].items():
            assert word.lower() in header(R, k, nhead).lower(), (path.name, k, header(R, k, nhead))
    spans = {k: span_nm(header(R, k, nhead)) for k in cfg["span"]} if not previous else {}
    taus = {k: last_number(header(R, k, nhead)) for k in cfg["tau"]} if not previous else {}
    out = []
    for r in range(nhead, len(R)):
        row = R[r]
        if len(row) <= max(cfg["coef"]):
            continue
        name = str(row[cfg["name"]] or "").strip()
        nd, vd = num(row[cfg["nd"]]), num(row[cfg["vd"]])
        coefs = coefficients(R, r, cfg)
        if not name or nd is None or vd is None or coefs is None or not 1.2 < nd < 2.6:
            continue
        g = {"name": name, "formula": cfg["formula"], "coefficients": coefs, "nd": nd, "vd": vd}
        lines = [num(row[k]) for k in cfg["lines"]]
        if not previous and all(v is not None for v in lines):
            g["published"] = dict(zip("CdFg", lines))
        have = [spans[k] for k in cfg["span"] if spans.get(k) and num(row[k]) is not None]
        if have:
            g["range_nm"] = [min(have), max(have)]
        if cfg is MAKERS["SUMITA"] and num(row[104]) != 10.0:
            taus = {}
        tau = sorted((taus[k], round(num(row[k]), 4)) for k in cfg["tau"] if taus.get(k) and num(row[k]) is not None)
        if tau:
            g["transmission_10mm"] = tau
        if previous:
            g["previous"] = True
        out.append(g)
    return out


def build(src: Path) -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for maker, cfg in MAKERS.items():
        glasses = read(src / cfg["file"], cfg, False)
        names = {g["name"].upper() for g in glasses}
        n_prev = 0
        if cfg["prev"] and (src / cfg["prev"]).exists():
            try:
                old = [g for g in read(src / cfg["prev"], cfg, True) if g["name"].upper() not in names]
            except (IndexError, AssertionError):
                old = []
            glasses += old
            n_prev = len(old)
        doc = {"catalog": maker, "source": f"{cfg['file']} (opticalglass 1.1.1 wheel, data/)",
               "previous_edition": cfg["prev"] if n_prev else None,
               "built": datetime.date.today().isoformat(), "glasses": glasses}
        text = json.dumps(doc, separators=(",", ":"), ensure_ascii=False)
        (OUT / f"{maker}.json").write_text(text + "\n", encoding="utf-8")
        print(f"{maker}: {len(glasses)} glasses ({n_prev} from the previous edition), {len(text) // 1024} kB")


if __name__ == "__main__":
    build(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("/tmp/og/whl/opticalglass/data"))
