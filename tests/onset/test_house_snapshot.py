"""The report of every bundled lens is what it was before issue 43 rebuilt the house around one camera
(tests/data/house_snapshot.json, written by scripts/report_snapshot.py from the code of main at
e8024b3, rewritten from main at cdf2d0b after its new lenses and report keys), number by number; and a report of a prescription focuses the lens at most twice.

Tolerances: 1e-12 relative. The hyperfocal mark is now solved as a fixed point in the subject's distance
(physcam.optics.focusing.hyperfocal_state) instead of one focus search per step, each stopping at 1e-9 of
the mark: values that come from it (a report focused at the hyperfocal mark, and every report's
hyperfocal distance) agree to 1e-9 relative, the old solver's own tolerance; the focus error of a
prescription at its own mark is 0 to 1e-9 mm (it was 1e-11, the old search's residue), and the
percentage differences of real and pinhole fields (differences of near-equal angles) to 1e-9.
A lens focusing internally (focus groups) is focused by a search for the subject's distance that stops at
1e-9 of the mark: bisection when the snapshot was made, regula falsi since round 15 (the same tolerance,
5-8 steps instead of about 35); the two land at different points within it, so that lens's numbers agree
to 1e-9 relative (measured: 1.4e-10 at most, 443 numbers past 1e-12, 2026-11-29), and its focus error at
its own mark to 1e-8 mm (the snapshot's holds the bisection's residue, up to 2.0e-9 mm; now 0 to 3e-14 mm).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import report_snapshot  # noqa: E402

HYPERFOCAL_RELATIVE = 1e-9
INTERNAL_FOCUS_RELATIVE = 1e-9


def _tolerance(path: str, internal: bool = False) -> tuple[float, float]:
    """(relative, absolute) tolerance of one number of the snapshot (module notes); ``internal``: of a lens
    focusing internally."""
    if path.endswith("focus_error_mm") or ".difference_pct." in path:
        return 0.0, (1e-8 if internal and path.endswith("focus_error_mm") else 1e-9)
    if "hyperfocal" in path:
        return HYPERFOCAL_RELATIVE, 0.0
    return (INTERNAL_FOCUS_RELATIVE if internal else 1e-12), 0.0


def _differences(old, new, path="", internal=False):
    if isinstance(old, dict) and isinstance(new, dict):
        out = [f"{path}.{k}: only in one" for k in set(old) ^ set(new)]
        for k in sorted(set(old) & set(new)):
            out += _differences(old[k], new[k], f"{path}.{k}", internal)
        return out
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        return [d for i, (a, b) in enumerate(zip(old, new)) for d in _differences(a, b, f"{path}[{i}]", internal)]
    if isinstance(old, (int, float)) and isinstance(new, (int, float)) and not isinstance(old, bool):
        rel, ab = _tolerance(path, internal)
        if old == new or abs(old - new) <= max(ab, rel * max(abs(old), abs(new))):
            return []
    return [] if old == new else [f"{path}: {old!r} -> {new!r}"]


@pytest.mark.slow
def test_every_bundled_lens_reports_what_it_did_before_the_house_was_rebuilt():
    old = json.loads(report_snapshot.SNAPSHOT.read_text(encoding="utf-8"))
    checked, bad = 0, []
    from physcam.lens.library import load_lens
    from physcam.optics.focusing import focus_method

    for slug, path in report_snapshot.lens_files():
        if slug not in old or old[slug]["sha256"] != report_snapshot.digest(path):
            continue  # a lens added or corrected since: nothing to compare
        lens = load_lens(slug)
        internal = focus_method(lens) == "internal"
        for name, case in report_snapshot.CASES:
            new = report_snapshot.report_dict(lens, case)
            bad += [f"{slug}{d}" for d in _differences(old[slug]["reports"][name], new, f".{name}", internal)]
            checked += 1
    assert checked >= 100, checked  # 30 bundled lenses x 4 cases when the snapshot was made
    assert not bad, "\n".join(bad[:40])


def test_the_tolerances_are_what_the_notes_say():
    assert _tolerance("zuiko.open_2m.dof.near_mm") == (1e-12, 0.0)
    assert _tolerance("zuiko.open_2m.dof.hyperfocal_mm") == (1e-9, 0.0)
    assert _tolerance("zuiko.f5.6_hyperfocal.h1_from_film_mm") == (1e-9, 0.0)
    assert _tolerance("zuiko.f5.6_hyperfocal.focus_error_mm") == (0.0, 1e-9)
    assert _differences({"a": 1.0}, {"a": 1.0 + 2e-12}) == [".a: 1.0 -> 1.000000000002"]
    assert _tolerance("sigma_50mm_f1_4_art.open_2m.dof.near_mm", internal=True) == (1e-9, 0.0)
    assert _differences({"a": 1.0}, {"a": 1.0 + 2e-10}, internal=True) == []


@pytest.mark.parametrize("name, case", [("dgauss_50mm", {"fstop": 2.8, "focus_mm": 2000.0}),
                                        ("zuiko_18mm_f3_5", {"fstop": 4.0, "focus_mm": 2000.0}),
                                        ("zuiko_18mm_f3_5", {"fstop": 4.0, "focus_mm": "hyperfocal"}),
                                        ("navarro_anamorphic_2x", {"fstop": 4.0, "focus_mm": 3000.0}),
                                        ("zuiko_18mm_f3_5", {"focus_mm": 3000.0, "near_mm": 2500.0, "coc": 0.025})])
def test_a_report_of_a_prescription_focuses_the_lens_at_most_twice(name, case):
    """Counted by profiling calls of physcam.optics.focusing.focus (its own code object), with fresh
    caches and a fresh lens: once at infinity (the iris rule) and once at the mark (before issue 43:
    15 on dgauss_50mm, 18 on zuiko_18mm_f3_5, 37 on navarro_anamorphic_2x: scripts/house_metrics.py)."""
    import cProfile
    import pstats
    import warnings

    import house_metrics

    from physcam.lens.library import load_lens
    from physcam.onset.report import solve_lens_report
    from physcam.optics import focusing

    lens = load_lens(name)
    house_metrics._clear_caches()
    pr = cProfile.Profile()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pr.enable()
        report = solve_lens_report(lens=lens, sensor="S35", **case)
        pr.disable()
    code = focusing.focus.__wrapped__.__wrapped__.__code__  # under renamed_parameter and takes_prescription
    calls = sum(v[0] for k, v in pstats.Stats(pr).stats.items() if k == (code.co_filename, code.co_firstlineno,
                                                                            code.co_name))
    assert 0 < calls <= 2 or (case["focus_mm"] == "hyperfocal" and calls <= 1), calls
    assert math.isfinite(report.dof.near_from_film_mm)
