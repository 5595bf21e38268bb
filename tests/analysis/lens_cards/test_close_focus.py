"""Issue 39 item 6: no close focus that no real lens has; the card names its prescription's source.

Lens cards and `compare` showed "close focus 196 mm" for a 50 mm (the unit-focusing 1:1 limit,
4 f plus the hiatus: the issue's number), and breathing plots spent half their axis on 0.2-0.5 m.
Now the lens file's `[lens] minimum_object_distance` (the maker's MOD, mm from the film) is used
when given; else the 1:1 limit is labelled "unit focusing limit, not the lens's MOD" and breathing
starts at ten focal lengths (two significant figures: 500 mm for the 50.36 mm double Gauss).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from _draft_cards import draft_card
from physcam.analysis.lens_cards.card import lens_card
from physcam.cli import main
from physcam.lens.library import find_lens, load_lens
from physcam.optics.focusing import breathing_table, close_focus

pytestmark = pytest.mark.slow


def _dgauss_with(tmp_path, lens_lines="", provenance_lines="") -> Path:
    """dgauss_50mm's own file with lines added to its [lens] and [provenance] tables."""
    text = Path(find_lens("dgauss_50mm").path).read_text(encoding="utf-8")
    text = text.replace("[lens]\n", "[lens]\n" + lens_lines, 1).replace("[provenance]\n",
                                                                         "[provenance]\n" + provenance_lines, 1)
    p = tmp_path / "dgauss_mod.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_without_a_mod_the_unit_limit_is_named_and_breathing_starts_at_ten_focal_lengths():
    lens = load_lens("dgauss_50mm")
    cf = close_focus(lens)
    assert cf.source == "unit focusing limit" and cf.mark_mm == pytest.approx(196.0, abs=0.05)
    assert cf.words == "unit focusing limit, not the lens's MOD"
    assert cf.breathing_near_mm == 500.0  # 10 x 50.358 mm = 503.6, to two significant figures
    marks = [r.focus_from_film_mm for r in breathing_table(lens)]
    assert min(marks) == 500.0  # not 200 mm: the 0.2-0.5 m a real 50 mm never reaches
    card = draft_card("dgauss_50mm")
    fig = card.figure(dpi=30)
    key = next(ax for ax in fig.axes if ax.get_label() == "key numbers")
    texts = [t.get_text() for t in key.texts]
    assert "unit focusing limit, not the lens's MOD" in texts
    assert min(r.focus_from_film_mm for r in card.breathing) == 500.0


def test_the_makers_mod_is_used_when_the_file_gives_one(tmp_path, capsys):
    path = _dgauss_with(tmp_path, "minimum_object_distance = 450.0\nt_stop = 2.2\n")
    lens = load_lens(str(path))
    cf = close_focus(lens)
    assert (cf.mark_mm, cf.source, cf.breathing_near_mm) == (450.0, "maker", 450.0)
    assert min(r.focus_from_film_mm for r in breathing_table(lens)) == 450.0
    card = lens_card(lens, quality="draft")
    assert card.key["close_focus_from_film_mm"] == 450.0 and card.key["tstop"] == 2.2
    fig = card.figure(dpi=30)
    key = next(ax for ax in fig.axes if ax.get_label() == "key numbers")
    texts = [t.get_text() for t in key.texts]
    assert "close focus (MOD)" in texts and "T2.20" in texts
    foot = " ".join(" ".join(t.get_text() for t in fig.texts).split())  # the footer, wrapped for the page
    meta = lens.metadata
    assert meta.source and f"licence: {meta.licence or 'not stated'}" in foot
    assert " ".join(meta.source.split())[:60] in foot
    assert main(["compare", "lenses", "--lens", str(path), "--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "4",
                 "--sensor", "S35", "--json", "--rays", "1000"]) == 0
    rows = json.loads(capsys.readouterr().out)["lenses"]
    assert [(r["closest_focus_mm"], r["closest_focus_source"]) for r in rows] == [
        (450.0, "maker"), (pytest.approx(196.0, abs=0.05), "unit focusing limit")]


def test_compare_table_labels_the_unit_limit(capsys):
    assert main(["compare", "lenses", "--lens", "dgauss_50mm", "--lens", "zeiss_distagon_35mm_f4", "--focus", "2m",
                 "--fstop", "4", "--sensor", "S35", "--rays", "1000"]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.startswith("closest focus"))
    assert re.search(r"196\.0 mm \(unit focusing limit, not the lens's MOD\)", row)


def test_a_mod_beyond_the_focus_model_is_shown_as_the_makers_figure(tmp_path, capsys):
    """Issue 44: a MOD closer than the focus model reaches (dgauss here: 150 mm against its 196.0 mm unit
    focusing limit; the Sigma 28 Art's 0.28 m against its patent's 1.275 m) is what the card and compare
    label "close focus (MOD)", with a note giving the model's limit; it printed the model's limit."""
    path = _dgauss_with(tmp_path, "minimum_object_distance = 150.0\n")
    lens = load_lens(str(path))
    assert close_focus(lens).mark_mm == pytest.approx(196.0, abs=0.05)  # the focus model stops there
    card = lens_card(lens, quality="draft")
    key = next(ax for ax in card.figure(dpi=30).axes if ax.get_label() == "key numbers")
    texts = [t.get_text() for t in key.texts]
    assert texts[texts.index("close focus (MOD)") + 1] == "150.0 mm"
    assert "beyond the focus model (reaches 196.0 mm)" in texts
    assert card.key["minimum_object_distance_mm"] == 150.0
    assert main(["compare", "lenses", "--lens", str(path), "--lens", "sigma_28mm_f1_4_art", "--focus", "2m",
                 "--fstop", "4", "--sensor", "S35", "--rays", "1000"]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("closest focus"))
    assert "150.0 mm (MOD; beyond the focus model, which reaches 196.0 mm)" in row
    assert "280.0 mm (MOD; beyond the focus model, which reaches 1.275 m)" in row  # Sigma's 28 cm; its patent's S
