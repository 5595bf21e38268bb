"""``physcam microlens insert`` and ``render`` (issue 13.4): files written atomically, no clobber
without --force, refusals in one line."""

from __future__ import annotations

import json

import pytest

from physcam.cli import main
from physcam.lens.formats.iset import microlens_of
from physcam.lens.library import load_lens
from physcam.optics.focusing import focus


def _insert(tmp_path, *extra):
    out = tmp_path / "lf.json"
    argv = ["microlens", "insert", "dgauss_50mm", "--microlens-focal", "0.224", "--xdim", "31", "--ydim", "21",
            "--film-width", "1.24", "--film-height", "0.84", "-o", str(out), *extra]
    return main(argv), out


def test_insert_writes_iset_json_focused_on_the_array(tmp_path, capsys):
    rc, out = _insert(tmp_path, "--focus", "0.8m", "--json")
    assert rc == 0
    info = json.loads(capsys.readouterr().out)
    doc = json.loads(out.read_text())
    assert doc["microlens"]["dimensions"] == [31, 21] and len(doc["microlens"]["offsets"]) == 31 * 21
    m = microlens_of(load_lens(str(out)))
    # --focus 0.8m: the main lens images a subject 800 mm from the sensor on the array, 0.224 mm in front of it
    st = focus(load_lens("dgauss_50mm"), 800.0 - 0.224)
    assert m["film_to_lens_mm"] == pytest.approx(st.back_focus_mm + 0.224, rel=1e-12)
    assert m["sensor_offset_mm"] == 0.224 and m["thin_focal_length_mm"] == 0.224
    assert info["pitch_mm"] == pytest.approx([0.04, 0.04])
    assert _insert(tmp_path, "--focus", "0.8m")[0] == 2  # exists
    assert "already exists" in capsys.readouterr().err
    assert _insert(tmp_path, "--film-to-lens", "40", "--force")[0] == 0
    assert microlens_of(load_lens(str(out)))["film_to_lens_mm"] == pytest.approx(40.0, abs=1e-12)


@pytest.mark.parametrize("extra, message", [
    ((), None),  # the default film-to-lens, lenstool's 50 mm
    (("--focus", "0.8m", "--film-to-lens", "40"), "either --focus or --film-to-lens"),
    (("--microlens", "dgauss_50mm"), "one of them"),
])
def test_insert_refusals(tmp_path, capsys, extra, message):
    rc, _ = _insert(tmp_path, *extra)
    if message is None:
        assert rc == 0
        return
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]


def test_render_points_and_plane(tmp_path, capsys):
    assert _insert(tmp_path, "--focus", "0.8m")[0] == 0
    capsys.readouterr()
    lf = str(tmp_path / "lf.json")
    fig = tmp_path / "pts.png"
    assert main(["microlens", "render", lf, "--fstop", "5.6", "--point", "0.5m", "--point", "5m", "--rays", "20000",
                 "-o", str(fig), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert fig.stat().st_size > 1000
    assert d["resolution"] == [31 * 9, 21 * 9] and d["rays_traced"] == 40000
    assert d["refocus"][0]["slope_lenslets_per_view"] < 0 < d["refocus"][1]["slope_lenslets_per_view"]
    assert main(["microlens", "render", lf, "--fstop", "5.6", "--plane", "0.8m", "--spp", "1",
                 "--pixels-per-lenslet", "5"]) == 0
    assert "plane 800 mm" in capsys.readouterr().out
    # refusals: nothing to render, a lens without an array, an existing figure
    for argv, msg in ((["microlens", "render", lf], "nothing to render"),
                      (["microlens", "render", "dgauss_50mm", "--point", "1m"], "no microlens array"),
                      (["microlens", "render", lf, "--point", "1m", "-o", str(fig)], "already exists")):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and msg in err[0]
