"""Draft a physcam lens TOML from a lens transcription in Bill Claff's OpticalBench text format.

Writes a draft only (to stdout or ``-o``): its ``[provenance]`` table has the keys the bundled
library needs with the parts a person must write (source, checks) left as ``TODO``; the numbers
are then compared by hand with the other transcriptions and the patent's stated values
(docs/lens-library.md, "The provenance record")::

    python scripts/transcribe_obench.py TRANSCRIPTION.txt --name "..." --slug SLUG -o draft.toml

The format, as read here: ``[variable distances]`` rows ``name<TAB>value(s)`` (one column per focus
position: ``d0`` the object distance from the first vertex, ``dN`` the gap after surface N, ``Bf``
the back focus); ``[lens data]`` rows ``id radius thickness nd diameter vd [glass...]`` (radius
``AS`` the aperture stop, ``CG``/``Infinity`` a flat, thickness a number or a distance name, an
empty nd air, ``diameter`` the clear diameter); ``[aspherical data]`` rows ``id radius k A4 A6 ...``
(``k`` the conic constant, 0 a sphere; ``[constants] AsphericalOddCount`` or ``AsphericalA2``
files are refused, physcam's even asphere starts at A4).

Glass: a catalogue glass is named where the row's nd and Vd, to their printed digits, are one
glass type (one six-digit code) among physcam's catalogues; the first such glass in catalogue
order whose formula the tracer holds within 2e-5 is taken, and an ``assumptions`` line says so.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from physcam.lens.catalog import catalog  # noqa: E402
from physcam.optics.glass import FIT_TOLERANCE, dispersion  # noqa: E402

#: The makers' current catalogues, in physcam's order (not MISC, nor the legacy ones of discontinued glasses).
MAKERS = ["SCHOTT", "OHARA", "HOYA", "CDGM", "HIKARI", "SUMITA"]


def sections(text: str) -> dict[str, list[list[str]]]:
    out, name = {}, None
    for line in text.splitlines():
        if line.startswith("["):
            name = line.strip().strip("[]").lower()
            out[name] = []
        elif name and line.strip():
            row = line.rstrip("\n").split("\t")
            while row and not row[-1].strip():  # trailing empty columns (some files pad every row)
                row.pop()
            out[name].append(row)
    return out


def _digits(text: str) -> int:
    return len(text.split(".")[1]) if "." in text else 0


def glass_for(nd_text: str, vd_text: str):
    """(catalogue, glass, note) of the one glass type the printed nd and Vd name, or (None, None, note)."""
    nd, vd = float(nd_text), float(vd_text)
    tol_nd, tol_vd = 0.5 * 10 ** -_digits(nd_text) + 1e-9, 0.5 * 10 ** -_digits(vd_text) + 1e-9
    hits = [(cat, g) for cat in MAKERS for g in catalog(cat).values()
            if g.formula is not None and abs(g.nd - nd) <= tol_nd and abs(g.vd - vd) <= tol_vd]
    codes = {f"{round((g.nd - 1) * 1000) % 1000:03d}{round(g.vd * 10):03d}" for _, g in hits}
    if not hits:
        return None, None, f"glass: nd {nd_text}, Vd {vd_text}: no catalogue glass has it; the normal-line dispersion model of nd and Vd"
    if len(codes) > 1:
        names = ", ".join(dict.fromkeys(f"{c} {g.name}" for c, g in hits))
        return None, None, (f"glass: nd {nd_text}, Vd {vd_text} fits several glass types ({names}); "
                            "the normal-line dispersion model of nd and Vd")
    code = codes.pop()
    for cat, g in hits:
        d = dispersion(nd, vd, g.name, cat)
        if d.fit_error <= FIT_TOLERANCE:
            others = [f"{c} {h.name}" for c, h in hits if h is not g]
            tail = f"its makers' equivalents {', '.join(others)}" if others else "no other maker lists it"
            return cat, g.name, (f"glass: nd {nd_text}, Vd {vd_text} (as the transcription gives them) is glass type "
                                 f"{code}: {cat} {g.name} ({g.nd:.5f}/{g.vd:.2f}) taken, the first in physcam's catalogue "
                                 f"order that the tracer holds within 2e-5; {tail}")
    names = ", ".join(f"{c} {g.name}" for c, g in hits)
    return None, None, (f"glass: nd {nd_text}, Vd {vd_text} is glass type {code} ({names}), none of which the tracer's "
                        "dispersion form holds within 2e-5; the normal-line dispersion model of nd and Vd")


def _num(text: str) -> float:
    v = float(text)
    if not math.isfinite(v):
        raise ValueError(text)
    return v


def draft(path: Path, name: str, column_close: int | None) -> str:
    sec = sections(path.read_text(encoding="utf-8"))
    consts = {r[0] for r in sec.get("constants", [])}
    if consts & {"AsphericalOddCount", "AsphericalA2"}:
        raise SystemExit(f"{path}: {consts}: not an even asphere from A4")
    var = {r[0]: r[1:] for r in sec["variable distances"]}
    asph = {r[0]: r for r in sec.get("aspherical data", [])}
    rows = sec["lens data"]
    surfaces, assumptions, glass_notes, gaps = [], [], {}, []
    close_col = column_close if column_close is not None else len(var.get("d0", ["Infinity"])) - 1
    for i, r in enumerate(rows):  # i: 0-based, as [[focus.gap]] surface
        sid, radius, thick = r[0], r[1], r[2]
        nd = r[3] if len(r) > 3 else ""
        diam = r[4] if len(r) > 4 else ""
        vd = r[5] if len(r) > 5 else ""
        if thick in var:
            values = var[thick]
            t = _num(values[0])
            if thick != "Bf" and close_col > 0 and values[close_col] not in ("", "undefined"):
                gaps.append((i, t, _num(values[close_col]), thick))
        else:
            t = _num(thick)
        s = {"sid": sid, "thickness": t, "semi_diameter": _num(diam) / 2 if diam else None}
        if radius == "AS":
            s["kind"], s["radius"] = "stop", 0.0
        elif radius in ("CG", "Infinity", "FS"):
            s["kind"], s["radius"] = "flat", 0.0
        else:
            s["kind"], s["radius"] = "spherical", _num(radius)
        if sid in asph:
            a = asph[sid]
            s["kind"], s["conic"] = "aspheric", _num(a[2])
            s["aspheric"] = [_num(x) for x in a[3:] if x.strip()]
        if nd.strip():
            cat, glass, note = glass_for(nd.strip(), vd.strip())
            s["medium"] = (nd.strip(), vd.strip(), glass, cat)
            glass_notes.setdefault((nd.strip(), vd.strip()), note)
        else:
            s["medium"] = None
        surfaces.append(s)
    assumptions += list(glass_notes.values())
    fl = var["Focal Length"][0]
    fno = var.get("F-Number", ["?"])[0]
    out = ["# physcam lens prescription; lengths in mm, +z toward the film (docs/lens-formats.md)",
           'format = "physcam-lens/1"', "", "[lens]", f'name = "{name}"', f"focal_length = {_num(fl)!r}",
           f"max_fstop = {fno}", 'coating = "multi"', "", "[provenance]", 'source = "TODO"', 'licence = "NOASSERTION"',
           f'transcribed_from = "TODO {path.name}"', "primary_source_checked = false", "checks = [", "    \"TODO\",",
           "]", "assumptions = ["]
    out += [f"    {_q(a)}," for a in assumptions] + ["]", ""]
    for s in surfaces:
        out += ["[[surface]]", f"# {s['sid']}", f'kind = "{s["kind"]}"', f"radius = {s['radius']!r}",
                f"thickness = {s['thickness']!r}", f"semi_diameter = {s['semi_diameter']!r}"]
        if s["medium"] is None:
            out.append('medium = "air"')
        else:
            nd, vd, glass, cat = s["medium"]
            g = f', glass = "{glass}", catalog = "{cat}"' if glass else ""
            out.append(f"medium = {{ nd = {float(nd)!r}, vd = {float(vd)!r}{g} }}")
        if s["kind"] == "aspheric":
            out += [f"conic = {s['conic']!r}", f"aspheric = [{', '.join(repr(x) for x in s['aspheric'])}]"]
        out.append("")
    if gaps:
        d0 = var["d0"][close_col]
        out += ["[focus]", f"close_distance = {_num(d0)!r}", ""]
        for i, t_inf, t_close, label in gaps:
            out += ["[[focus.gap]]", f"# {label}", f"surface = {i}", f"thickness_infinity = {t_inf!r}",
                    f"thickness_close = {t_close!r}", ""]
    return "\n".join(out)


def _q(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("transcription", type=Path)
    ap.add_argument("--name", required=True)
    ap.add_argument("--close-column", type=int, default=None, help="the [variable distances] column of the close focus")
    ap.add_argument("-o", "--output", type=Path)
    a = ap.parse_args(argv)
    text = draft(a.transcription, a.name, a.close_column)
    if a.output:
        a.output.write_text(text, encoding="utf-8")
    else:
        print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
