"""Write (or check) src/physcam/data/glass/fits/<CATALOGUE>.json: each bundled catalogue's glasses whose
formula is refitted into the tracer's dispersion form (physcam.optics.glassfit.tracer_form), fitted once
here so that a lens of such glass loads without fitting (issue 43: 50 ms of numpy per glass).

    python scripts/glass_fits.py            # rewrite every table (about a minute of CPU)
    python scripts/glass_fits.py --check    # refit and compare with the stored tables (exit 1 on a difference)
    python scripts/glass_fits.py HOYA CDGM  # only these catalogues

A glass whose formula, coefficients or band differ from its stored entry is fitted at run time as before
(physcam.optics.glassfit.stored_form checks all three), so a stale table costs time, never a wrong index.
"""

from __future__ import annotations

import json
import sys

from physcam.lens.catalog import BUILTIN_CATALOGS, catalog
from physcam.optics.glass import _traced_band
from physcam.optics.glassfit import STORED_DIR, fit_table


def refitted(name: str) -> list:
    seen, out = set(), []
    for g in catalog(name).values():
        if g.formula is not None and g.sellmeier is None and g.name.upper() not in seen:
            seen.add(g.name.upper())
            out.append(g)
    return out


def main() -> int:
    check = "--check" in sys.argv[1:]
    only = [a.upper() for a in sys.argv[1:] if not a.startswith("--")]
    bad = 0
    for name in only or BUILTIN_CATALOGS:
        glasses = refitted(name)
        if not glasses:
            continue
        table = fit_table(glasses, _traced_band)
        path = STORED_DIR / f"{name}.json"
        if check:
            stored = json.loads(path.read_text(encoding="utf-8"))["glasses"] if path.is_file() else {}
            diff = [k for k in table if stored.get(k) != table[k]]
            bad += len(diff)
            print(f"{name}: {len(table)} glasses, {len(diff)} differ{': ' + ', '.join(diff[:5]) if diff else ''}")
            continue
        STORED_DIR.mkdir(parents=True, exist_ok=True)
        lines = ",\n".join(f"  {json.dumps(k)}: {json.dumps(v)}" for k, v in table.items())
        path.write_text('{"catalogue": ' + json.dumps(name) + ', "written_by": "scripts/glass_fits.py", '
                        '"glasses": {\n' + lines + "\n}}\n", encoding="utf-8")
        print(f"{name}: {len(table)} glasses -> {path}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
