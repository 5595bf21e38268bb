"""Bundled lenses re-entered from their patents' own printed pages (issue 44): every number of the
file against the patent's table as typed in primary_stated.py, and the first-order data the patent states against
physcam's paraxial values and optiland's.

The tables there were typed from the patents' scanned pages (a reading independent of the lens
file's, done a second time for this test), not from physcam's files or output.
"""

import dataclasses
import json
from pathlib import Path

import pytest

from physcam.lens.library import find_lens, load_lens
from physcam.lens.provenance import primary_source_claim_gaps, provenance_of
from physcam.optics.paraxial import gaussian, media_indices, paraxial_trace, system_matrix

from primary_stated import (PRIMARY, US_3583791_EX2_R13_COLUMN3, US_3841736_EX2_STATED, US_3841736_R14_PRINTED,
                             US_4310222_COLUMNS, US_4310222_EX2_R16_PRINTED, US_4310222_EX8_N7_PRINTED,
                             US_4310222_R6_PRINTED)

ORACLE = json.loads((Path(__file__).resolve().parents[1] / "data" / "optiland_library.json").read_text())["lenses"]


def _rows(slug):
    """The file's (radius, gap to the next glass surface, nd, vd) rows, a stop's gaps merged into the air space it splits."""
    rows = []
    for s in load_lens(slug).surfaces:
        if s.kind == "stop":
            r, t, nd, vd = rows.pop()
            rows.append((r, t + s.thickness, nd, vd))
            continue
        glass = s.medium.nd not in (None, 1.0)
        rows.append((s.radius, s.thickness, s.medium.nd if glass else None, s.medium.vd if glass else None))
    return rows


@pytest.mark.parametrize("slug", sorted(PRIMARY))
def test_every_number_is_the_patents(slug):
    table, _ = PRIMARY[slug]
    rows = _rows(slug)
    assert len(rows) == len(table)
    for (r, t, nd, vd), (pr, pt, pnd, pvd) in zip(rows, table):
        assert r == pytest.approx(pr, abs=1e-9)
        if pt is not None:  # the last gap is the back focus, checked below
            assert t == pytest.approx(pt, abs=1e-9)
        assert (nd, vd) == (pytest.approx(pnd), pytest.approx(pvd)) if pnd else (nd, vd) == (None, None)


@pytest.mark.parametrize("slug", sorted(PRIMARY))
def test_first_order_data_match_the_patent_and_optiland(slug):
    _, want = PRIMARY[slug]
    g = gaussian(load_lens(slug))
    assert g.efl == pytest.approx(want["efl"], rel=want.get("efl_rel", 5e-3))
    assert g.f_number == pytest.approx(want["fno"], rel=5e-3)
    if want["bf"] is not None:
        assert g.bfl == pytest.approx(want["bf"], abs=want["bf_tol"])
    oracle = ORACLE[slug]["y"]  # optiland 0.6.3, scripts/optiland_library_oracle.py
    assert g.efl == pytest.approx(oracle["efl_mm"], rel=1e-3)
    assert g.f_number == pytest.approx(oracle["f_number"], rel=1e-3)


@pytest.mark.parametrize("slug", sorted(PRIMARY))
def test_provenance_is_the_patent_itself_and_checked(slug, capsys):
    from physcam.cli import main

    prov = provenance_of(load_lens(slug))
    assert prov.primary_source_checked is True and primary_source_claim_gaps(prov) == []
    assert prov.licence == "Apache-2.0" and "facts" in prov.notes and "Apache-2.0" in prov.notes
    assert prov.transcribed_from.startswith("the patent itself") and "not that project's lens files" in prov.transcribed_from
    assert prov.checked and prov.checked_by and prov.source_url
    kinds = {a.split(":")[0] for a in prov.assumptions}
    assert {"stop", "semi-diameters", "glass"} <= kinds
    # what a user sees: the list and the lens's own page name the source and the licence
    assert main(["lenses", "--json"]) == 0
    (rec,) = [r for r in json.loads(capsys.readouterr().out)["lenses"] if r["slug"] == slug]
    assert rec["licence"] == "Apache-2.0" and load_lens(slug).metadata.patent in rec["source"]
    assert main(["lens", "show", "--lens", slug]) == 0
    out = capsys.readouterr().out
    assert "licence: Apache-2.0" in out and "every number checked against it" in out
    assert find_lens(slug).slug == slug
    # and the lens card's key numbers, which its footer prints (physcam.analysis.lens_cards)
    from physcam.analysis.lens_cards.card import key_numbers

    key = key_numbers(load_lens(slug), 3000.0, 21.63)
    assert key["licence"] == "Apache-2.0" and key["source"] == prov.source


def test_a_misprinted_radius_is_corrected_by_the_patents_own_stated_values():
    """US 3,841,736 prints r14 = -52.41 twice; its stated F, F_B and the focal lengths F7 = 102.06 and
    F8 = -69.76 of the cemented lenses 7 and 8 (Table I) are those of r14 = -62.41, which the file uses."""
    p = load_lens("asahi_wide_angle_us3841736_100mm_f3_5")
    s = [x for x in p.surfaces if x.kind != "stop"]
    assert s[13].radius == pytest.approx(-62.41) and "-52.41" in provenance_of(p).corrections[0]

    def thick_lens_f(n, r1, r2, t):  # Smith, Modern Optical Engineering, eq. 2.48
        return 1.0 / ((n - 1.0) * (1.0 / r1 - 1.0 / r2 + (n - 1.0) * t / (n * r1 * r2)))

    r13, r15 = s[12].radius, s[14].radius
    assert thick_lens_f(1.51823, r13, -62.41, 18.11) == pytest.approx(102.06, abs=0.01)
    assert thick_lens_f(1.83400, -62.41, r15, 5.76) == pytest.approx(-69.76, abs=0.01)
    assert thick_lens_f(1.51823, r13, US_3841736_R14_PRINTED, 18.11) == pytest.approx(88.10, abs=0.01)
    i = p.surfaces.index(s[13])  # the printed r14 in the lens: F 117.5, not the stated 100
    printed = p.with_surfaces(dataclasses.replace(x, radius=US_3841736_R14_PRINTED) if k == i else x
                              for k, x in enumerate(p.surfaces))
    assert gaussian(printed).efl == pytest.approx(117.51, abs=0.01)


def test_us3841736s_second_table_meets_its_printed_focal_lengths_and_table_ivs_petzval_column():
    """Column 6 prints beside Table III the focal lengths of lenses 7 and 8 and of the first four and six lenses,
    and Table IV (headed "for the lens system of Table I") the Seidel coefficients: its P column is Table III's,
    (F/r)(1/n - 1/n') with F = 100, every radius and index of the file to the printed digits (Table I's first
    row would be 0.23, not 0.17)."""
    p, want = load_lens("asahi_wide_angle_us3841736_100mm_f3_5_ex2"), US_3841736_EX2_STATED
    st, n = p.stop_index, media_indices(p)
    pt = [(100.0 / s.radius if s.radius else 0.0) * (1.0 / n[i] - 1.0 / n[i + 1])  # r3 is flat: 0
          for i, s in enumerate(p.surfaces) if i != st]
    assert pt == pytest.approx(want["pt"], abs=0.0051) and sum(pt) == pytest.approx(want["pt_sum"], abs=0.005)
    assert (100.0 / 196.25) * (1.0 - 1.0 / 1.80610) == pytest.approx(0.23, abs=0.005)  # Table I's r1, n1

    def group_f(first, last):  # the file's surface indices (the stop is index 12, after r12), last one into air
        return -1.0 / system_matrix(p, first=first, last=last)[2]

    def thick_lens_f(k):  # lens k in air (Smith, Modern Optical Engineering, eq. 2.48); its surfaces k, k + 1
        r1, r2, t, nk = p.surfaces[k].radius, p.surfaces[k + 1].radius, p.surfaces[k].thickness, n[k + 1]
        return 1.0 / ((nk - 1.0) * (1.0 / r1 - 1.0 / r2 + (nk - 1.0) * t / (nk * r1 * r2)))

    assert thick_lens_f(13) == pytest.approx(want["f7"], rel=5e-4)  # 100.729: 0.03 % from the printed 100.70
    assert thick_lens_f(14) == pytest.approx(want["f8"], abs=0.005)
    assert group_f(0, 7) == pytest.approx(want["f1234"], abs=0.005)
    assert group_f(0, 11) == pytest.approx(want["f123456"], abs=0.015)


def test_a_sign_lost_in_us3583791s_second_example_is_restored_by_its_stated_values():
    """Example II's R13 is printed 3,921.60 in column 3 and -3921.60 in claim 3: only the minus sign gives the
    stated f = 100 and Bf = 137.24 (95.79 and 131.29 with the plus), and makes L7 the positive meniscus convex
    to the image that claim 1 ends the lens with."""
    p = load_lens("nikon_retrofocus_us3583791_100mm_f2_8_ex2")
    s = [x for x in p.surfaces if x.kind != "stop"]
    assert s[13].radius == pytest.approx(-3921.60) and "3,921.60" in provenance_of(p).corrections[0]
    assert s[13].radius < 0 and s[14].radius < 0 and abs(s[14].radius) < abs(s[13].radius)  # concave to the object
    i = p.surfaces.index(s[13])
    printed = p.with_surfaces(dataclasses.replace(x, radius=US_3583791_EX2_R13_COLUMN3) if k == i else x
                              for k, x in enumerate(p.surfaces))
    g = gaussian(printed)
    assert g.efl == pytest.approx(95.79, abs=0.01) and g.bfl == pytest.approx(131.29, abs=0.01)


@pytest.mark.parametrize("slug", sorted(US_4310222_COLUMNS))
class TestCanonUS4310222:
    """US 4,310,222 prints, beside each table, the Petzval term of every surface, computed with the design's f
    (each term is (f/r)(1/n - 1/n')) and its lens groups' focal lengths, and (but for the seventh and eighth) what its own
    paraxial trace gave (the h and h-bar columns, below): numbers computed from every radius, gap and index at
    once, held here against physcam's paraxial trace of the file."""

    def test_the_asphere_is_the_patents(self, slug):
        p = load_lens(slug)
        (r3,) = [s for s in p.surfaces if s.kind == "aspheric"]
        assert r3 is p.surfaces[2] and r3.conic == 0.0
        assert tuple(r3.aspheric) == pytest.approx(US_4310222_COLUMNS[slug]["asphere"], rel=1e-12)

    def test_the_patents_petzval_terms_and_group_focal_lengths(self, slug):
        p, col = load_lens(slug), US_4310222_COLUMNS[slug]
        st, f, n = p.stop_index, gaussian(p).efl, media_indices(p)
        pt = [(f / s.radius if s.radius else 0.0) * (1.0 / n[i] - 1.0 / n[i + 1])  # a flat (the filter): 0
              for i, s in enumerate(p.surfaces) if i != st]
        printed = list(col["pt"])
        if slug.endswith("14mm_f2_8"):  # row 20 is printed -0.6776; the printed total is the sum with -0.0676
            assert pt[19] == pytest.approx(-0.0676, abs=1e-4) and sum(printed) == pytest.approx(-0.4967, abs=1e-4)
            printed[19] = -0.0676
        if slug.endswith("_ex2"):  # row 23 is printed 0.3023; the printed total 0.1172 is the lens's sum (0.11725)
            assert pt[22] == pytest.approx(0.3026, abs=1e-4) and sum(pt) == pytest.approx(col["pt_total"], abs=1e-4)
            printed[22] = 0.3026
        assert pt == pytest.approx(printed, abs=2e-4)
        assert sum(printed) == pytest.approx(col["pt_total"], abs=1e-3)

        def index(k):  # the patent's surface number -> the file's (the stop comes after the surface before it)
            return k - 1 if k - 1 < st else k

        for first, last, in_f in col["groups"]:  # stated in units of the stated f
            m = system_matrix(p, first=index(first), last=index(last))
            # to the printed digits, or 0.1 % of a long one (the sixth embodiment's 7.343f is the lens's 7.336f)
            assert -1.0 / m[2] / col["f"] == pytest.approx(in_f, abs=0.005, rel=1.1e-3)


@pytest.mark.parametrize("slug", sorted(s for s, col in US_4310222_COLUMNS.items() if "h" in col))
def test_the_patents_paraxial_columns_of_us4310222(slug):
    """The h and h-bar columns the patent prints beside each table but the last two: its own paraxial trace."""
    p, col = load_lens(slug), US_4310222_COLUMNS[slug]
    st, f = p.stop_index, gaussian(p).efl
    h, _ = paraxial_trace(p, 1.0, 0.0)  # the axial ray, incident height 1
    a, _ = paraxial_trace(p, 0.0, 1.0)  # principal ray of f = 1: nu = 1, aimed at the stop's centre
    b, _ = paraxial_trace(p, 1.0, 1.0)
    y0 = -a[st] / (b[st] - a[st])
    hbar, _ = paraxial_trace(p, y0, 1.0)
    assert [y for i, y in enumerate(h) if i != st] == pytest.approx(col["h"], abs=5.1e-4)
    assert [y / f for i, y in enumerate(hbar) if i != st] == pytest.approx(col["hbar"], abs=1e-3)
    # the h column ends at bf/f (f = 1): the first embodiment's design f is 14.28, not the stated 14.2;
    # the fifth's bf is 17.40, not the 17.2 printed with it
    assert col["bf"] / col["h"][-1] == pytest.approx(f, rel=1e-3)


def test_a_misprinted_radius_of_us4310222_is_corrected_by_its_own_columns():
    """The fifth embodiment's R6 prints as 3.3649; its h column, its Petzval term for R6 and its f = 5.52
    are those of 8.3649, which the file uses."""
    p = load_lens("canon_wide_angle_us4310222_5_5mm_f1_6")
    i = 5  # R6, before the stop
    assert p.surfaces[i].radius == pytest.approx(8.3649) and "3.3649" in provenance_of(p).corrections[0]
    printed = p.with_surfaces(dataclasses.replace(x, radius=US_4310222_R6_PRINTED) if k == i else x
                              for k, x in enumerate(p.surfaces))
    h, _ = paraxial_trace(printed, 1.0, 0.0)
    assert h[6] == pytest.approx(2.547, abs=1e-3)  # the patent's h column: 1.710
    assert gaussian(printed).efl == pytest.approx(2.927, abs=1e-3)  # the patent's f: 5.52


def test_a_sign_lost_in_us4310222s_second_table_is_restored_by_its_own_columns():
    """The second embodiment's R16 prints as 12.614; its Petzval term (-0.4933), its h column and the lens's
    shape are those of -12.614, which the file uses: with +12.614 the convex R15 and R16, 0.94 mm apart, meet
    inside the f/2.8 beam and the h column from R17 on is not the patent's."""
    from physcam.errors import PhysCamError

    p = load_lens("canon_wide_angle_us4310222_14mm_f2_8_ex2")
    i = 15  # R16, before the stop
    assert p.surfaces[i].radius == pytest.approx(-12.614) and "12.614" in provenance_of(p).corrections[0]
    f, n = gaussian(p).efl, media_indices(p)
    assert (f / US_4310222_EX2_R16_PRINTED) * (1.0 / n[i] - 1.0 / n[i + 1]) == pytest.approx(0.4934, abs=1e-4)
    with pytest.raises(PhysCamError, match="crosses surface 16"):  # the printed sign: two faces crossing
        p.with_surfaces(dataclasses.replace(x, radius=US_4310222_EX2_R16_PRINTED) if k == i else x
                        for k, x in enumerate(p.surfaces)).validate()


def test_the_seventh_embodiments_petzval_column_is_computed_with_its_tables_f():
    """US 4,310,222's seventh embodiment prints no h columns; its Petzval terms, (f/r)(1/n - 1/n') each, are
    the file's with the table's own f (14.290, held above) and not with the stated 14.2. Its stated focal
    distance of the plastic lens R3-R4, -265 f, is not the table's (-245 f): recorded in the file as not met."""
    slug = "canon_wide_angle_us4310222_14mm_f2_8_ex7"
    p, col = load_lens(slug), US_4310222_COLUMNS[slug]
    st, n = p.stop_index, media_indices(p)
    at_stated = [(14.2 / s.radius if s.radius else 0.0) * (1.0 / n[i] - 1.0 / n[i + 1])
                 for i, s in enumerate(p.surfaces) if i != st]
    assert max(abs(a - b) for a, b in zip(at_stated, col["pt"])) > 2e-3  # R16: 0.3998 against the printed 0.4022

    def thick_lens_f(n, r1, r2, t):  # Smith, Modern Optical Engineering, eq. 2.48
        return 1.0 / ((n - 1.0) * (1.0 / r1 - 1.0 / r2 + (n - 1.0) * t / (n * r1 * r2)))

    r3, r4 = p.surfaces[2], p.surfaces[3]
    f_plastic = thick_lens_f(r3.medium.nd, r3.radius, r4.radius, r3.thickness)
    assert f_plastic / 14.2 == pytest.approx(-245.2, abs=0.1)
    assert "-265 f" in " ".join(provenance_of(p).checks)


def test_a_misprinted_index_of_us4310222s_eighth_table_is_corrected_by_its_petzval_column():
    """The eighth embodiment prints N7 = 1.6968 with v 30.1 (1.6968 goes with v 55.5 everywhere else in the patent,
    1.69895 with 30.1); its own Petzval column, each term (f/r)(1/n - 1/n') with the lens's f, is the file's only
    with 1.69895, and so are the stated f = 17.3 and bf = 36.2 most nearly."""
    slug = "canon_wide_angle_us4310222_17mm_f2_8_ex8"
    p, col = load_lens(slug), US_4310222_COLUMNS[slug]
    i = next(k for k, s in enumerate(p.surfaces) if s.radius == pytest.approx(67.788))  # R13, N7 behind it
    assert p.surfaces[i].medium.nd == pytest.approx(1.69895) and "1.6968" in provenance_of(p).corrections[0]
    printed = p.with_surfaces(dataclasses.replace(x, medium=dataclasses.replace(x.medium, nd=US_4310222_EX8_N7_PRINTED))
                              if k == i else x for k, x in enumerate(p.surfaces))

    def petzval(q):
        st, f, n = q.stop_index, gaussian(q).efl, media_indices(q)
        return [(f / s.radius) * (1.0 / n[j] - 1.0 / n[j + 1]) for j, s in enumerate(q.surfaces) if j != st]

    assert petzval(p) == pytest.approx(col["pt"], abs=2e-4)
    misses = [abs(a - b) for a, b in zip(petzval(printed), col["pt"])]
    assert sum(m > 2.5e-4 for m in misses) == 9 and max(misses) > 6e-4
    g, g_printed = gaussian(p), gaussian(printed)
    assert abs(g.efl - 17.3) < abs(g_printed.efl - 17.3) and abs(g.bfl - 36.2) < abs(g_printed.bfl - 36.2)
    assert g_printed.efl == pytest.approx(17.357, abs=1e-3) and g_printed.bfl == pytest.approx(36.229, abs=1e-3)
