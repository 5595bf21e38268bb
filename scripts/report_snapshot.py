"""Write (or check) tests/data/house_snapshot.json: the on-set report of every bundled lens in a few
settings, made by the code before issue 43 rebuilt the house around one camera object, so that the
rebuilt house can be compared with it number by number (tests/onset/test_house_snapshot.py).

    python scripts/report_snapshot.py           # rewrite the snapshot (the tree's own code)
    python scripts/report_snapshot.py --check   # compare the tree's reports with the snapshot

Each lens is keyed by the SHA-256 of its file's data less its [provenance] table, so a lens whose data
changed later (another issue's correction) is skipped, not reported as a regression, while a lens whose
provenance record alone grew (a check, a maker's figure quoted) is still compared. Cases: wide open at 2 m, f/4 at infinity, f/5.6
at the hyperfocal mark, and f/4 at 3 m with a measured near limit of 2.5 m (the f-stop solved).
"""

from __future__ import annotations

import hashlib
import json
import math
import sys
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SNAPSHOT = ROOT / "tests" / "data" / "house_snapshot.json"
SENSOR = "S35"
#: (name, inputs): the ReportRequest fields of each case besides the lens and the sensor
CASES = (("open_2m", {"focus_mm": 2000.0}), ("f4_inf", {"fstop": 4.0, "focus_mm": math.inf}),
         ("f5.6_hyperfocal", {"fstop": 5.6, "focus_mm": "hyperfocal"}),
         ("near_2.5m_at_3m", {"focus_mm": 3000.0, "near_mm": 2500.0, "coc": 0.025}))


def lens_files():
    from physcam.lens.library import list_lenses

    return [(r.slug, Path(r.path)) for r in list_lenses() if r.library == "bundled"]


def digest(path: Path) -> str:
    """SHA-256 of the lens file's TOML data without its ``[provenance]`` table (canonical JSON): what a
    report can depend on. Provenance lines (sources, checks, quoted maker figures) change no report."""
    import tomllib

    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data.pop("provenance", None)
    return hashlib.sha256(json.dumps(data, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def report_dict(lens, case: dict) -> dict:
    """The report of ``lens`` for one case, as ``to_dict()``, or its error's type and message."""
    from physcam.errors import PhysCamError
    from physcam.onset.report import solve_lens_report

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return solve_lens_report(lens=lens, sensor=SENSOR, **case).to_dict()
    except PhysCamError as exc:
        return {"error": type(exc).__name__, "message": str(exc)}


def snapshot() -> dict:
    from physcam.lens.library import load_lens

    out = {}
    for slug, path in lens_files():
        lens = load_lens(slug)
        out[slug] = {"sha256": digest(path), "reports": {name: report_dict(lens, case) for name, case in CASES}}
    return out


def differences(old, new, path="", rel=1e-12) -> list[str]:
    """Where two report documents differ: numbers by more than ``rel`` relative, anything else at all."""
    if isinstance(old, dict) and isinstance(new, dict):
        out = [f"{path}.{k}: only in one" for k in set(old) ^ set(new)]
        for k in sorted(set(old) & set(new)):
            out += differences(old[k], new[k], f"{path}.{k}", rel)
        return out
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        return [d for i, (a, b) in enumerate(zip(old, new)) for d in differences(a, b, f"{path}[{i}]", rel)]
    if isinstance(old, (int, float)) and isinstance(new, (int, float)) and not isinstance(old, bool):
        if old == new or abs(old - new) <= rel * max(abs(old), abs(new)):
            return []
        return [f"{path}: {old!r} -> {new!r}"]
    return [] if old == new else [f"{path}: {old!r} -> {new!r}"]


def main(argv) -> int:
    if "--check" not in argv:
        doc = snapshot()  # one lens a line: a later change of one lens is one line of a diff
        lines = [f"{json.dumps(k)}: {json.dumps(v, sort_keys=True, separators=(',', ':'))}" for k, v in sorted(doc.items())]
        SNAPSHOT.write_text("{\n" + ",\n".join(lines) + "\n}\n", encoding="utf-8")
        return 0
    old = json.loads(SNAPSHOT.read_text(encoding="utf-8"))
    bad = []
    for slug, doc in snapshot().items():
        if slug in old and old[slug]["sha256"] == doc["sha256"]:
            bad += [f"{slug}{d}" for d in differences(old[slug]["reports"], doc["reports"])]
    print("\n".join(bad) or "the reports agree with the snapshot")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
