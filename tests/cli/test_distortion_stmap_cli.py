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


def test_fits_in_json_and_their_files(tmp_path, capsys):
    """The issue's command: maps, 3DE4, Brown-Conrady and Nuke files, and --json of the fits."""
    out = tmp_path / "out"
    rc = main(["distortion", "dgauss_50mm", "--focus", "2m", "--sensor", "ALEXA 35", "--resolution", "1152x791",
               "--stmap", str(out), "--fit", "3de4", "--fit", "brown", "--fit", "nuke", "--json"])
    assert rc == 0
    d = json.loads(capsys.readouterr().out)
    models = [f["model"] for f in d["fits"]]
    assert models == ["3DE4 Radial - Standard, Degree 4", "Brown-Conrady D-U", "Brown-Conrady U-D"]
    for f in d["fits"]:
        assert f["acceptable"] and 0 <= f["residual_px"]["rms"] <= f["residual_px"]["max"] <= 0.5
    names = {p.rsplit("/", 1)[-1] for p in d["written"]}
    assert {"3de4_radial_standard_degree_4.txt", "brown_conrady.json", "physcam_stmap.nk", "residual_3de4.png",
            "distortion.exr", "undistortion.exr"} <= names
    brown = json.loads((out / "brown_conrady.json").read_text())
    from _documents import check_document

    assert check_document(brown) == "physcam.distortion_brown_conrady"
    entries = brown["opentrackio_lens_distortion"]
    assert [e["model"] for e in entries] == ["Brown-Conrady D-U", "Brown-Conrady U-D"]
    # six radial terms in OpenLensIO order, what Unreal and camdkit read (issue 31; tests/live/test_interop.py)
    assert all(len(e["radial"]) == 6 and len(e["tangential"]) == 2 for e in entries)
    assert entries[0]["radial"][0] > 0 > entries[1]["radial"][0]  # barrel: D-U grows the radius, U-D shrinks it


def test_distortion_across_focus_table(capsys):
    from physcam.analysis.distortion.field import real_distortion
    from physcam.lens.library import load_lens

    rc = main(["distortion", "zuiko_18mm_f3_5", "--resolution", "1024x683", "--across-focus", "0.4m,1m,inf",
               "--sensor", "FF", "--json"])
    assert rc == 0
    d = json.loads(capsys.readouterr().out)
    rows = d["rows"]
    assert [r["focus_from_film_mm"] for r in rows] == [400.0, 1000.0, None]
    # distortion breathes: the barrel deepens as the lens focuses close
    assert rows[0]["corner_distortion_pct"] < rows[1]["corner_distortion_pct"] < rows[2]["corner_distortion_pct"] < 0
    # at infinity the corner figure agrees with the field-angle table's (a separate 1-D code path, chief rays
    # from infinity): its distortion where the real chief ray reaches the corner radius, 21.633 mm
    assert main(["distortion", "dgauss_50mm", "--resolution", "1024x683", "--across-focus", "inf", "--sensor", "FF",
                 "--json"]) == 0
    corner = json.loads(capsys.readouterr().out)["rows"][0]["corner_distortion_pct"]
    pts = real_distortion(load_lens("dgauss_50mm"), np.linspace(0.0, 24.0, 97), sensor_width_mm=36,
                          sensor_height_mm=24).points
    h = np.array([p.real_height_mm for p in pts])
    pct = np.array([p.distortion_pct for p in pts])
    ref = np.interp(np.hypot(18.0, 12.0), np.abs(h), pct)
    assert corner < -1.0 and abs(corner - ref) < 0.01
    # text table for people
    assert main(["distortion", "zuiko_18mm_f3_5", "--resolution", "1024x683", "--across-focus", "0.5m,inf"]) == 0
    assert "pinhole mm" in capsys.readouterr().out


def test_fit_options_need_their_partners(tmp_path, capsys):
    for argv in (["--fit", "brown"], ["--across-focus", "1m"], ["--resolution", "512x342", "--fit", "nuke"],
                 ["--resolution", "512x342", "--across-focus", "1m", "--focus", "2m"],
                 ["--resolution", "512x342", "--fit", "brown", "--max-residual", "0"]):
        rc = main(["distortion", "dgauss_50mm", *argv])
        err = capsys.readouterr().err
        assert rc == 2 and err.startswith("physcam: error:") and err.count("\n") == 1, (argv, err)


def test_the_usd_fit_file_is_a_document(tmp_path, capsys):
    from _documents import check_document

    out = tmp_path / "usd"
    assert main(["distortion", "dgauss_50mm", "--resolution", "512x384", "--stmap", str(out), "--fit", "usd"]) == 0
    doc = json.loads((out / "usd_lens_distortion.json").read_text())
    assert check_document(doc) == "physcam.distortion_usd"
    assert doc["usd"]["lensDistortion:k1"] == doc["coefficients"]["k1"]
