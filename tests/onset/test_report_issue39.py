"""The lens report says what its numbers are (issue 39 items 2 and 3).

Item 2: "FOV h / v / d (infinity)" was computed with the EFL at the mark. Numbers from the issue's
review (the Navarro 2x at infinity: 8.30 deg vertical on Super 35) and a property: the field at
infinity of a report focused anywhere equals the field at focus of the same lens focused at infinity.

Item 3: a split focus (near and far asked, the focus solved) with a stop given solved the CoC
(0.049 mm, 2.4 x d/1500) and showed the asked limits as if f/4 held them. Now the CoC stays the chosen
one, the limits shown are the given stop's, and the stop the asked limits need is said beside them.
The numbers are worked here by hand from the thin lens (tests/_thin_lens.py's relations).
"""

from __future__ import annotations

import json
import math
import re

import pytest
from _thin_lens import image_distance_at_mark  # noqa: F401  (the same oracle module as the other tests)

from physcam.cli import main
from physcam.lens.library import list_lenses, load_lens
from physcam.onset.report import solve_lens_report
from physcam.optics.sensors import find_sensor
from physcam.optics.focusing import closest_focus

S35 = find_sensor("S35")
pytestmark = pytest.mark.filterwarnings("ignore::physcam.errors.PhysCamWarning")


def test_navarro_fov_at_infinity_is_the_lens_at_infinity():
    r = solve_lens_report(lens=load_lens("navarro_anamorphic_2x"), sensor=S35, fstop=4.0, focus_mm=1250.0)
    assert r.vfov_inf_deg == pytest.approx(8.30, abs=0.005)  # the review's number; 9.15 before (EFL at 1.25 m)


@pytest.mark.parametrize("slug", [r.slug for r in list_lenses()])
def test_fov_at_infinity_does_not_depend_on_the_mark(slug):
    lens = load_lens(slug)
    mark = max(2000.0, 1.2 * closest_focus(lens))
    near = solve_lens_report(lens=lens, sensor=S35, focus_mm=mark)
    far = solve_lens_report(lens=lens, sensor=S35, focus_mm=math.inf)
    assert near.vfov_inf_deg == pytest.approx(far.vfov_focus_deg, rel=1e-9)
    if not lens.is_anamorphic:  # an anamorphic's X pinhole at infinity is not its X EFL (docs/distortion.md)
        assert near.hfov_inf_deg == pytest.approx(far.hfov_focus_deg, rel=1e-9)
        assert near.dfov_inf_deg == pytest.approx(far.dfov_focus_deg, rel=1e-9)


def _split_by_hand(f, near_film, far_film, c):
    """Thin lens, practical model (H1 = H2 = s' in front of the film): the focus s about H1 between the
    limits (1/n + 1/F = 2/s, n and F from H1) and the f-number whose exact limits are n and F:
    near = s f^2 / (f^2 + N c (s - f)), so N = (1/n - 1/F) s f^2 / (2 c (s - f)). H1 moves with s:
    iterate."""
    sp = f
    for _ in range(200):
        n, F = near_film - sp, far_film - sp
        s = 2 * n * F / (n + F)
        sp = 1.0 / (1.0 / f - 1.0 / s)
    N = (1 / n - 1 / F) * s * f * f / (2 * c * (s - f))
    return s, sp, N


def _limits_by_hand(f, N, c, s, sp):
    k = N * c * (s - f)
    return s * f * f / (f * f + k) + sp, s * f * f / (f * f - k) + sp


def test_split_focus_keeps_the_stop_and_says_the_stop_needed(capsys):
    c = math.hypot(S35.width_mm, S35.height_mm) / 1500.0
    s, sp, need = _split_by_hand(50.0, 2500.0, 4000.0, c)
    assert need == pytest.approx(9.5, abs=0.05)  # the f/9.5
    assert main(["report", "--focal", "50", "--near", "2.5m", "--far", "4m", "--fstop", "4", "--sensor", "S35",
                 "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["coc_mm"] == pytest.approx(c, rel=1e-12) and d["coc_convention"] == "d/1500"  # not 0.049 solved
    assert "coc_mm" not in d["solved"]
    assert d["fstop"] == 4.0
    sf = d["split_focus"]
    assert sf["fstop_needed"] == pytest.approx(need, rel=1e-6)
    assert sf["holds"] is False
    near, far = _limits_by_hand(50.0, 4.0, c, s, sp)
    assert d["dof"]["near_from_film_mm"] == pytest.approx(near, rel=1e-6)  # the given stop's limits, not 2.5 / 4 m
    assert d["dof"]["far_from_film_mm"] == pytest.approx(far, rel=1e-6)
    assert main(["report", "--focal", "50", "--near", "2.5m", "--far", "4m", "--fstop", "4", "--sensor", "S35"]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.startswith("stop needed"))
    assert "f/9.5 for 2.500 m – 4.000 m" in row and "f/4 holds only" in row
    assert "solved consistency" not in out and not re.search(r"\de-\d", out)  # no debug figures


def test_split_focus_with_a_stop_that_holds():
    r = solve_lens_report(focal_length_mm=50.0, sensor=S35, near_mm=2500.0, far_mm=4000.0, fstop=11.0)
    assert r.split_focus["holds"] is True
    assert r.dof.near_from_film_mm < 2500.0 < 4000.0 < r.dof.far_from_film_mm


def test_effective_stop_inversion_is_unchanged():
    """Focus known, limits measured, no stop: the stop is solved (matchmove forensics), as before."""
    r = solve_lens_report(focal_length_mm=35.0, sensor=S35, focus_mm=3048.0, near_mm=2438.4, coc="cine")
    assert "fstop" in r.solved and r.split_focus is None
