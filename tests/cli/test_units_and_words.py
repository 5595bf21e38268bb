"""Issue 39 item 9: units and words that mislead.

- One rule for a bare focus, near or far: millimetres, or feet under `--units ft` or `units = "ft"` in
  the user config (a note says so); a bare number closer than the lens focuses: "did you mean 3m?".
  Lengths inside the camera (--focal) stay millimetres. 10 ft = 3048 mm (the international foot).
- `--units ft` reports print no scene distance in mm in their notes (the hyperfocal note did).
- A distortion fit is "good" in the CLI and on its figure (the figure said "acceptable").
"""

from __future__ import annotations

import json
import re

import pytest

from physcam.cli import main


def _report(capsys, *argv):
    rc = main(["report", *argv, "--json"])
    out, err = capsys.readouterr()
    return rc, (json.loads(out) if rc == 0 else None), err


def test_a_bare_focus_is_millimetres_and_too_close_says_did_you_mean(capsys):
    rc, _, err = _report(capsys, "--focal", "50", "--fstop", "4", "--focus", "3", "--sensor", "S35")
    assert rc == 2 and "did you mean 3m?" in err and "Traceback" not in err
    rc, _, err = _report(capsys, "--lens", "dgauss_50mm", "--fstop", "4", "--focus", "3", "--sensor", "S35")
    assert rc == 2 and "did you mean 3m?" in err
    rc, d, _ = _report(capsys, "--focal", "50", "--fstop", "4", "--focus", "3000", "--sensor", "S35")
    assert rc == 0 and d["focus_from_film_mm"] == 3000.0
    rc, _, err = _report(capsys, "--focal", "50", "--fstop", "4", "--focus", "3m", "--near", "3",
                         "--sensor", "S35")  # the bare near limit is 3 mm: refused, never taken as metres
    assert rc == 2


def test_feet_in_the_config_make_a_bare_scene_distance_feet(capsys, tmp_path, monkeypatch):
    cfg = tmp_path / "config.toml"
    cfg.write_text('units = "ft"\n')
    monkeypatch.setenv("PHYSCAM_CONFIG", str(cfg))
    rc, d, err = _report(capsys, "--focal", "50", "--fstop", "4", "--focus", "10", "--sensor", "S35")
    assert rc == 0 and d["focus_from_film_mm"] == pytest.approx(3048.0)
    assert d["focal_length_mm"] == 50.0  # a length inside the camera stays millimetres
    assert 'a bare number is feet here (units = "ft" in the user config): --focus 10 read in feet' in err
    rc, d, err = _report(capsys, "--focal", "50", "--fstop", "4", "--near", "8", "--far", "14", "--sensor", "S35")
    assert rc == 0 and d["measured"] == {"near_from_film_mm": pytest.approx(2438.4),
                                         "far_from_film_mm": pytest.approx(4267.2)}
    rc, d, _ = _report(capsys, "--focal", "50", "--fstop", "4", "--focus", "3000mm", "--sensor", "S35")
    assert d["focus_from_film_mm"] == 3000.0  # written units as written


def test_units_ft_on_the_command_line_too(capsys):
    rc, d, err = _report(capsys, "--focal", "50", "--fstop", "4", "--focus", "10", "--units", "ft", "--sensor", "S35")
    assert rc == 0 and d["focus_from_film_mm"] == pytest.approx(3048.0) and "(--units ft)" in err


def test_feet_reports_print_no_scene_distance_in_millimetres(capsys):
    assert main(["report", "--focal", "35", "--fstop", "4", "--focus", "hyperfocal", "--units", "ft",
                 "--sensor", "S35"]) == 0
    out = capsys.readouterr().out
    notes = [line for line in out.splitlines() if line.startswith("note:")]
    assert any("hyperfocal" in n for n in notes)
    # a scene distance (metres or more) in mm: "mark 10600 mm from the film" was the hyperfocal note
    assert not any(re.search(r"\b\d{4,}(\.\d+)? mm\b", n) for n in notes), notes
    row = next(line for line in out.splitlines() if line.startswith("focus mark"))
    assert "'" in row and '"' in row  # feet and inches


def test_a_fit_is_good_in_the_cli_and_on_its_figure(tmp_path, capsys):
    from physcam.analysis.distortion.models import fit_models, samples_from_field
    from physcam.analysis.distortion.stmap import distortion_field
    from physcam.lens.library import load_lens
    from physcam.optics.state import camera_state

    res = distortion_field(camera_state(load_lens("dgauss_50mm"), focus_mm=2000.0, sensor_mm=(24.89, 18.66)),
                           width_px=512, height_px=384, maps=False)
    fit = fit_models(samples_from_field(res), ["brown"])[0]
    fig = fit.plot_residual()
    title = fig.axes[0].get_title()
    assert title.endswith(": good") and "acceptable" not in title
    assert main(["distortion", "--lens", "dgauss_50mm", "--focus", "2m", "--resolution", "512x384",
                 "--fit", "brown"]) == 0
    assert ": good" in capsys.readouterr().out


@pytest.mark.parametrize("spelling, system", [("feet", "ft"), ("foot", "ft"), ("FT", "ft"), ("metres", "m"),
                                              ("meters", "m"), ("metre", "m")])
def test_units_take_the_common_spellings(capsys, spelling, system):
    """--units feet prints what --units ft prints (a first-day review: feet was refused)."""
    argv = ["hyperfocal", "--focal", "35,50", "--sensor", "S35", "--units"]
    assert main([*argv, spelling]) == 0
    said = capsys.readouterr().out
    assert main([*argv, system]) == 0
    assert said == capsys.readouterr().out
    assert main([*argv, "yards"]) == 2
    assert "invalid choice: 'yards'" in capsys.readouterr().err


def test_feet_spelled_out_in_the_config_is_feet(capsys, tmp_path, monkeypatch):
    cfg = tmp_path / "config.toml"
    cfg.write_text('units = "feet"\n')
    monkeypatch.setenv("PHYSCAM_CONFIG", str(cfg))
    rc, d, _ = _report(capsys, "--focal", "50", "--fstop", "4", "--focus", "10", "--sensor", "S35")
    assert rc == 0 and d["focus_from_film_mm"] == pytest.approx(3048.0)  # 10 ft = 3048 mm
