"""``physcam distortion --focus --resolution --stmap``: files written once, bad input writes none."""

from __future__ import annotations

import json

import numpy as np

from physcam.cli import main


def test_stmap_cli_writes_float_exrs_of_the_frame(tmp_path, capsys):
    import OpenEXR

    out = tmp_path / "maps"
    rc = main(["distortion", "zuiko_18mm_f3_5", "--focus", "2m", "--resolution", "512x342", "--stmap", str(out),
               "--json"])
    assert rc == 0
    d = json.loads(capsys.readouterr().out)
    ox, oy = d["overscan_px"]
    assert d["undistorted_size_px"] == [512 + 2 * ox, 342 + 2 * oy]
    with OpenEXR.File(str(out / "distortion.exr"), separate_channels=True) as f:
        assert f.channels()["R"].pixels.shape == (342, 512) and f.channels()["R"].pixels.dtype == np.float32
    with OpenEXR.File(str(out / "undistortion.exr"), separate_channels=True) as f:
        assert f.channels()["G"].pixels.shape == (342 + 2 * oy, 512 + 2 * ox)
    assert (out / "distortion.png").is_file() and (out / "undistortion.png").is_file()
    # a second run without --force refuses and leaves the files alone
    before = (out / "distortion.exr").read_bytes()
    assert main(["distortion", "zuiko_18mm_f3_5", "--focus", "2m", "--resolution", "512x342", "--stmap", str(out)]) == 2
    assert (out / "distortion.exr").read_bytes() == before


def test_bad_stmap_input_is_one_error_and_no_file(tmp_path, capsys):
    for argv in (["--focus", "5cm", "--resolution", "512x342"], ["--resolution", "0x342"],
                 ["--resolution", "100000x342"], ["--focus", "2m"]):
        out = tmp_path / "none"
        rc = main(["distortion", "zuiko_18mm_f3_5", *argv, "--stmap", str(out)])
        err = capsys.readouterr().err
        assert rc == 2 and "Traceback" not in err and err.strip()
        assert not out.exists()


def test_without_the_new_options_the_table_is_unchanged(capsys):
    assert main(["distortion", "zuiko_18mm_f3_5", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert "points" in d and "overscan_px" not in d


def test_plot_file_with_resolution_is_refused_not_ignored(tmp_path, capsys):
    """-o (the table's plot) with --resolution was silently ignored: refused with the way forward."""
    from physcam.cli import main

    rc = main(["distortion", "zeiss_distagon_35mm_f4", "--resolution", "256x171", "-o", str(tmp_path / "d.png")])
    err = capsys.readouterr().err
    assert rc == 2 and "--stmap DIR" in err and not (tmp_path / "d.png").exists()
