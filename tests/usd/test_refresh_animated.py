"""`physcam usd check` / `usd refresh` of a camera with a keyed lens (a focus pull, an f-stop ramp): checked and
recomputed time code by time code (round 10; before, any time-sampled focus or f-stop was refused).

Oracles: a thin lens's closed form at each time code's focus F and f-stop N (the lens s' in front of the film
with s + s' = F and 1/s + 1/s' = 1/f: s' = (F - sqrt(F (F - 4 f))) / 2; the companion's fStop keeps
focalLength / fStop = f / N); for a real lens, physcam's own on-set report of that lens at that focus and stop
(physcam.onset.report, called directly); a stage refreshed then checked is current; usd-core's validators pass.
"""

from __future__ import annotations

import json
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from _documents import check_document
from physcam.cli import main
from physcam.usd.validate import validation_errors

from pxr import Usd  # noqa: E402

CAM, MODEL, GEOM = "/Cameras/Camera", "/Cameras/Camera/Pinhole", "/Cameras/Camera/Camera"


def _rel(a, b, tol=2e-6):
    return abs(a - b) <= tol * max(abs(a), abs(b))


def _check_json(capsys, f):
    capsys.readouterr()
    rc = main(["usd", "check", str(f), "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert check_document(doc) == "physcam.usd_check"  # the schema's time_codes and stale_samples
    return rc, doc


def _pull(tmp_path, name="pull"):
    marks = tmp_path / f"{name}.csv"
    marks.write_text("frame,focus,fstop\n1,2m,2.8\n10,4m,4\n", encoding="utf-8")
    f = tmp_path / f"{name}.usda"
    assert main(["usd", "animate", str(f), "--focal", "50", "--marks", str(marks), "--sensor", "S35"]) == 0
    return f


def test_a_focus_pull_as_written_is_current(tmp_path, capsys):
    f = _pull(tmp_path)
    rc, doc = _check_json(capsys, f)
    assert rc == 0 and doc["stale"] is False and doc["time_codes"] == [1.0, 10.0] and doc["stale_samples"] == []


def test_an_edited_thin_lens_pull_is_stale_at_its_time_codes_and_refreshed_to_the_closed_form(tmp_path, capsys):
    f = _pull(tmp_path)
    stage = Usd.Stage.Open(str(f))
    stage.GetPrimAtPath(CAM).GetAttribute("lens:main:fStop").Set(5.6, 10.0)  # the ramp's last stop
    stage.GetPrimAtPath(MODEL).GetAttribute("focusDistance").Set(3000.0, 5.0)  # a new mark at frame 5
    stage.Save()
    rc, doc = _check_json(capsys, f)
    assert rc == 1 and doc["stale"] and doc["time_codes"] == [1.0, 5.0, 10.0]
    stale = {s["time"]: s["attributes"] for s in doc["stale_samples"]}
    assert sorted(stale) == [5.0, 10.0]  # frame 1 is as it was
    assert f"{GEOM}.fStop" in stale[10.0] and f"{GEOM}.focalLength" not in stale[10.0]  # the stop, not the focus
    assert f"{GEOM}.focalLength" in stale[5.0] and f"{GEOM}.focusDistance" in stale[5.0]
    capsys.readouterr()
    assert main(["usd", "check", str(f)]) == 1
    assert "time code 10: stale" in capsys.readouterr().out

    capsys.readouterr()
    assert main(["usd", "refresh", str(f), "--json"]) == 0
    done = json.loads(capsys.readouterr().out)
    assert check_document(done) == "physcam.usd_refresh" and done["written"] and not done["stale"]
    assert {c["time"] for c in done["changed"]} == {5.0, 10.0}  # frame 1's samples kept as they were
    stage = Usd.Stage.Open(str(f))
    assert validation_errors(stage) == []
    cam, model, geom = (stage.GetPrimAtPath(p) for p in (CAM, MODEL, GEOM))
    f_mm = 50.0
    for t, focus, fstop in ((1.0, 2000.0, 2.8), (5.0, 3000.0, 2.8 + (5.6 - 2.8) * 4 / 9), (10.0, 4000.0, 5.6)):
        assert _rel(model.GetAttribute("focusDistance").Get(t), focus) and _rel(cam.GetAttribute(
            "lens:main:fStop").Get(t), fstop)
        s_img = (focus - math.sqrt(focus * (focus - 4 * f_mm))) / 2  # the lens in front of the film
        assert _rel(geom.GetAttribute("focalLength").Get(t), s_img, 5e-6), t  # cm stage: tenths of a cm are mm
        assert _rel(cam.GetAttribute("lens:main:iris").Get(t), f_mm / fstop)
        assert _rel(cam.GetAttribute("iris").Get(t), f_mm / fstop)  # usd animate keys the body's too: kept in step
        assert _rel(geom.GetAttribute("fStop").Get(t), fstop * s_img / f_mm, 5e-6)
        assert _rel(geom.GetAttribute("exposure:fStop").Get(t), fstop)
        pupil = cam.GetAttribute("lens:main:entrancePupilDistance").Get(t)  # a thin lens's pupil: the file's
        assert _rel(geom.GetAttribute("focusDistance").Get(t), (focus - pupil) / 10.0)
        assert _rel(-geom.GetAttribute("xformOp:translate").Get(t)[2], pupil / 10.0)
    rc, doc = _check_json(capsys, f)
    assert rc == 0 and doc["stale_samples"] == []


def test_a_keyed_focus_on_a_real_lens_is_solved_at_each_time_code(tmp_path, capsys):
    from physcam.lens.library import load_lens
    from physcam.onset.report import report_camera, solve_report
    from physcam.optics.sensors import Sensor

    f = tmp_path / "lens.usda"
    assert main(["usd", "write", str(f), "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "3m", "--sensor",
                 "S35"]) == 0
    stage = Usd.Stage.Open(str(f))  # a layout artist keys a focus pull and an f-stop over the default
    focus = stage.GetPrimAtPath(MODEL).GetAttribute("focusDistance")
    focus.Set(2000.0, 1.0)
    focus.Set(5000.0, 24.0)
    stop = stage.GetPrimAtPath(CAM).GetAttribute("lens:main:fStop")
    stop.Set(2.8, 1.0)
    stop.Set(4.0, 24.0)
    stage.Save()
    assert main(["usd", "check", str(f)]) == 1
    assert main(["usd", "refresh", str(f)]) == 0
    stage = Usd.Stage.Open(str(f))
    assert validation_errors(stage) == []
    cam, model, geom = (stage.GetPrimAtPath(p) for p in (CAM, MODEL, GEOM))
    w, h = cam.GetAttribute("sensor:main:aperture").Get()
    sensor = Sensor(key="custom", name="S35", width_mm=float(w), height_mm=float(h))
    lens = load_lens("dgauss_50mm")
    for t, mark, n in ((1.0, 2000.0, 2.8), (24.0, 5000.0, 4.0)):
        r = solve_report(report_camera(focal_length_mm=None, sensor=sensor, fstop=n, focus_mm=mark, coc=0.025,
                                       lens=lens))
        assert _rel(model.GetAttribute("focalLength").Get(t), r.focal_length_mm)  # the EFL at the focus
        assert _rel(cam.GetAttribute("lens:main:entrancePupilDistance").Get(t), r.entrance_pupil_from_film_mm)
        assert _rel(cam.GetAttribute("lens:main:frontPrincipalPlaneDistance").Get(t), r.h1_from_film_mm)
        assert _rel(cam.GetAttribute("lens:main:rearPrincipalPlaneDistance").Get(t), r.h2_from_film_mm)
        assert _rel(cam.GetAttribute("lens:main:pinholeFocalLength").Get(t), r.pinhole_focal_length_mm)
        assert _rel(geom.GetAttribute("focalLength").Get(t), r.pinhole_focal_length_mm, 2e-5)  # a float32 view
        assert _rel(geom.GetAttribute("focusDistance").Get(t), (mark - r.entrance_pupil_from_film_mm) / 10.0)
    assert _rel(model.GetAttribute("focusDistance").Get(), 3000.0)  # the default, kept
    pulled = [geom.GetAttribute("focalLength").Get(t) for t in (1.0, 24.0)]
    assert pulled[0] > pulled[1]  # breathing: the closer focus frames tighter
    rc, doc = _check_json(capsys, f)
    assert rc == 0 and doc["time_codes"] == [1.0, 24.0] and doc["stale_samples"] == []


def _refused(capsys, action, f):
    before = f.read_bytes()
    capsys.readouterr()
    assert main(["usd", action, str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(f) in err and "Traceback" not in err, err
    assert f.read_bytes() == before
    return err


def test_a_sample_that_cannot_be_focused_is_refused_naming_its_time_code(tmp_path, capsys):
    f = _pull(tmp_path)
    stage = Usd.Stage.Open(str(f))
    stage.GetPrimAtPath(MODEL).GetAttribute("focusDistance").Set(150.0, 7.0)  # inside 4 f: no image of it
    stage.Save()
    for action in ("check", "refresh"):
        err = _refused(capsys, action, f)
        assert "at time code 7" in err and f"usd {action} cannot solve this sample" in err, err  # the command run


@pytest.mark.parametrize("edit", ["sensor", "real-lens"])
def test_samples_check_and_refresh_cannot_follow_are_refused(tmp_path, capsys, edit):
    if edit == "sensor":
        f = _pull(tmp_path)
        stage = Usd.Stage.Open(str(f))
        stage.GetPrimAtPath(CAM).GetAttribute("sensor:main:aperture").Set((20.0, 15.0), 4.0)
        stage.Save()
        expected = "sensor:main:aperture is animated"
    else:  # usd animate --lens keys the real lens's pupils without storing the lens
        marks = tmp_path / "pull.csv"
        marks.write_text("frame,focus\n1,2m\n10,4m\n", encoding="utf-8")
        f = tmp_path / "rx.usda"
        assert main(["usd", "animate", str(f), "--lens", "dgauss_50mm", "--fstop", "2.8", "--marks", str(marks),
                     "--sensor", "S35"]) == 0
        expected = "does not store"
    for action in ("check", "refresh"):
        assert expected in _refused(capsys, action, f)



def test_a_shots_keyed_focus_over_a_vendor_lens_is_refreshed_in_the_shot(tmp_path):
    """A shot (body and vendor lens files referenced, physcam.usd.kit) whose focus override a layout artist keys:
    the refresh writes its samples as shot opinions, the lens file untouched, and the shot checks current."""
    from physcam.lens.library import load_lens
    from physcam.onset.report import report_camera, solve_report
    from physcam.optics.sensors import Sensor
    from physcam.usd.author import CameraSpec
    from physcam.usd.kit import check_shot, refresh_shot, write_body_file, write_shot, write_vendor_lens

    lens, body, shot = (tmp_path / n for n in ("lens.usda", "body.usda", "shot.usda"))
    write_vendor_lens(lens, load_lens("dgauss_50mm"), focus_mm=3000.0, fstop=2.8)
    write_body_file(body, CameraSpec.of(focal_length_mm=50.0, fstop=2.8, focus_mm=3000.0, sensor_width_mm=24.89,
                                        sensor_height_mm=18.66))
    write_shot(shot, body, lens, overrides={"focus_mm": 2500.0})
    lens_bytes = lens.read_bytes()
    stage = Usd.Stage.Open(str(shot))
    focus = stage.GetPrimAtPath("/Cameras/Shot/Pinhole").GetAttribute("focusDistance")
    focus.Set(2000.0, 1.0)
    focus.Set(4000.0, 48.0)
    stage.Save()
    before = check_shot(shot)
    assert before["stale"] and [s["time"] for s in before["stale_samples"]] == [1.0, 48.0]
    after = refresh_shot(shot)
    assert after["written"] and not after["stale"] and lens.read_bytes() == lens_bytes
    stage = Usd.Stage.Open(str(shot))
    assert validation_errors(stage) == []
    w, h = stage.GetPrimAtPath("/Cameras/Shot").GetAttribute("sensor:main:aperture").Get()
    r = solve_report(report_camera(focal_length_mm=None, lens=load_lens("dgauss_50mm"), fstop=2.8, focus_mm=4000.0,
                                   sensor=Sensor(key="custom", name="S35", width_mm=float(w), height_mm=float(h))))
    geom = stage.GetPrimAtPath("/Cameras/Shot/Camera")
    assert _rel(geom.GetAttribute("focalLength").Get(48.0), r.pinhole_focal_length_mm, 2e-5)
    assert _rel(stage.GetPrimAtPath("/Cameras/Shot").GetAttribute("lens:main:entrancePupilDistance").Get(48.0),
                r.entrance_pupil_from_film_mm)


def _dgauss(tmp_path, name="lens.usda"):
    f = tmp_path / name
    assert main(["usd", "write", str(f), "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "3m", "--sensor",
                 "S35"]) == 0
    return f


def _keyed_dgauss(tmp_path, keys):
    """:func:`_dgauss` with its focus keyed as a layout artist keys it: ``keys`` (time code, mark in mm) pairs."""
    f = _dgauss(tmp_path)
    stage = Usd.Stage.Open(str(f))
    focus = stage.GetPrimAtPath(MODEL).GetAttribute("focusDistance")
    for t, mark in keys:
        focus.Set(mark, t)
    stage.Save()
    return f


def test_keys_without_a_default_still_check_and_refresh_the_cameras_other_inputs(tmp_path, capsys):
    """A DCC export writes a keyed focus as samples only (no default): an ISO, shutter and clipping change on the
    body is stale, and the refresh writes them to the companion (the closed forms: ISO as is, the shutter's close
    = open + duration x frame rate (24 fps), the clipping range as the lens gives it, in scene units)."""
    f = _dgauss(tmp_path)
    stage = Usd.Stage.Open(str(f))
    focus = stage.GetPrimAtPath(MODEL).GetAttribute("focusDistance")
    focus.Set(3000.0, 1.0)
    focus.Set(1500.0, 24.0)
    focus.ClearDefault()
    stage.Save()
    assert main(["usd", "refresh", str(f)]) == 0
    rc, doc = _check_json(capsys, f)
    assert rc == 0 and doc["time_codes"] == [1.0, 24.0]
    stage = Usd.Stage.Open(str(f))
    cam = stage.GetPrimAtPath(CAM)
    cam.GetAttribute("sensor:main:iso").Set(3200.0)
    cam.GetAttribute("shutterDuration").Set(0.01)
    cam.GetAttribute("lens:main:clippingRange").Set((1.0, 500.0))
    stage.Save()
    rc, doc = _check_json(capsys, f)
    assert rc == 1 and doc["stale"] and doc["stale_samples"] == []
    assert main(["usd", "refresh", str(f)]) == 0
    stage = Usd.Stage.Open(str(f))
    geom = stage.GetPrimAtPath(GEOM)
    assert geom.GetAttribute("exposure:iso").Get() == 3200.0
    assert _rel(geom.GetAttribute("shutter:close").Get() - geom.GetAttribute("shutter:open").Get(), 0.01 * 24)
    assert tuple(geom.GetAttribute("clippingRange").Get()) == (1.0, 500.0)  # the lens's, in the stage's unit
    focus = stage.GetPrimAtPath(MODEL).GetAttribute("focusDistance")  # no default added to the keys
    assert focus.GetResolveInfo(Usd.TimeCode.Default()).GetSource() != Usd.ResolveInfoSourceDefault
    assert validation_errors(stage) == []
    rc, doc = _check_json(capsys, f)
    assert rc == 0 and not doc["stale"]


def _layer(name):
    from pxr import Sdf

    layer = Sdf.Layer.CreateNew(str(name))
    layer.defaultPrim = "Cameras"
    layer.pseudoRoot.SetInfo("metersPerUnit", 0.01)
    layer.pseudoRoot.SetInfo("upAxis", "Y")
    return layer


def test_a_focus_pull_in_a_sublayer_refreshes_only_its_samples_in_the_root_layer(tmp_path, capsys):
    """The animation in a sublayer over a current still camera: the refresh writes only the samples' values in
    the shot's root layer, no copy of the still companion, and reports only time-coded changes."""
    from pxr import Sdf

    _dgauss(tmp_path, "camera.usda")
    anim = _layer(tmp_path / "anim.usda")
    model = Sdf.CreatePrimInLayer(anim, MODEL)
    for p in ("/Cameras", CAM, MODEL):
        anim.GetPrimAtPath(p).specifier = Sdf.SpecifierOver
    a = Sdf.AttributeSpec(model, "focusDistance", Sdf.ValueTypeNames.Float)
    anim.SetTimeSample(a.path, 1, 3000.0)
    anim.SetTimeSample(a.path, 24, 1500.0)
    anim.Save()
    shot = _layer(tmp_path / "shot.usda")
    shot.subLayerPaths[:] = ["anim.usda", "camera.usda"]
    shot.Save()
    f = tmp_path / "shot.usda"
    capsys.readouterr()
    assert main(["usd", "refresh", str(f), "--json"]) == 0
    done = json.loads(capsys.readouterr().out)
    assert done["written"] and not done["stale"] and done["changed"]
    assert all("time" in c for c in done["changed"]), [c for c in done["changed"] if "time" not in c][:3]
    assert _root_defaults(f) == []
    camera = Usd.Stage.Open(str(tmp_path / "camera.usda"))  # the body's ISO, in the still camera's layer
    camera.GetPrimAtPath(CAM).GetAttribute("sensor:main:iso").Set(800.0)
    camera.Save()
    capsys.readouterr()
    assert main(["usd", "refresh", str(f), "--json"]) == 0
    done = json.loads(capsys.readouterr().out)
    assert done["written"] and not done["stale"]
    assert [(c["attribute"], c["before"], c["after"]) for c in done["changed"]] == [
        (f"{GEOM}.exposure:iso", 100.0, 800.0)]  # the one value that changed, and no copy of the others
    assert _root_defaults(f) == [f"{GEOM}.exposure:iso"]
    assert validation_errors(Usd.Stage.Open(str(f))) == []


def _root_defaults(f):
    from pxr import Sdf

    root = Sdf.Layer.FindOrOpen(str(f))
    root.Reload()
    out = []
    root.Traverse("/", lambda p: out.append(str(p)) if p.IsPropertyPath() and root.GetAttributeAtPath(p)
                  .HasDefaultValue() else None)
    return out


def test_a_kit_shots_body_iris_is_not_a_sample_of_the_lens(tmp_path, capsys):
    """A shot (body and lens files) keyed at its still focus: the body's own ``iris`` (used only when no lens is
    applied, the schema) is not stale, and the refresh does not key it."""
    def run(*argv):
        capsys.readouterr()
        return main(["usd", *map(str, argv)])

    body, lens, shot = (tmp_path / n for n in ("alexa35.usda", "dgauss50.usda", "camera.usda"))
    assert run("kit", "body", body, "--sensor", "ALEXA 35", "--flange", "44") == 0
    assert run("kit", "vendor", lens, "--lens", "dgauss.50mm", "--focus", "1.5m", "--fstop", "4") == 0
    assert run("kit", "shot", shot, "--body", body, "--lens", lens, "--focus", "2m", "--fstop", "2.8") == 0
    stage = Usd.Stage.Open(str(shot))
    stage.GetPrimAtPath("/Cameras/Shot/Pinhole").GetAttribute("focusDistance").Set(2000.0, 1.0)
    stage.Save()
    rc, doc = _check_json(capsys, shot)
    assert rc == 0 and doc["stale_samples"] == [], doc["stale_samples"]
    assert run("refresh", shot) == 0
    assert not Usd.Stage.Open(str(shot)).GetPrimAtPath("/Cameras/Shot").GetAttribute("iris").GetNumTimeSamples()


def test_time_codes_are_printed_as_the_time_codes_they_are(tmp_path, capsys):
    """Keys at time codes 123456, 123456.5 and 1234567 (a long shot's frame numbers, a half frame): each stale one
    is named exactly, not rounded to six digits (123456.5 read as 123456; 1234567 as 1.23457e+06)."""
    f = _keyed_dgauss(tmp_path, ((123456.0, 3000.0), (123456.5, 2000.0), (1234567.0, 1000.0)))
    capsys.readouterr()
    assert main(["usd", "check", str(f)]) == 1
    out = capsys.readouterr().out
    assert "(first 123456.5: " in out and "  time code 123456.5: stale" in out and "  time code 1234567: stale" in out
    assert main(["usd", "refresh", str(f)]) == 0
    out = capsys.readouterr().out
    assert " at time code 123456.5: " in out and " at time code 1234567: " in out and "e+06" not in out


@settings(max_examples=200, deadline=None)
@given(st.floats(allow_nan=False, allow_infinity=False))
def test_a_time_codes_text_reads_back_to_that_time_code(t):
    from physcam.usd.keyed_lens import time_code_text

    text = time_code_text(t)
    assert float(text) == t and ("." not in text and "e" not in text) == float(t).is_integer()


def test_one_keyed_time_code_reads_in_the_singular(tmp_path, capsys):
    f = _dgauss(tmp_path)
    stage = Usd.Stage.Open(str(f))
    stage.GetPrimAtPath(MODEL).GetAttribute("focusDistance").Set(2000.0, 1.0)
    stage.Save()
    capsys.readouterr()
    assert main(["usd", "check", str(f)]) == 1
    out = capsys.readouterr().out
    assert "(1 keyed time code) STALE: 1 of its time codes is stale (first 1: " in out, out


def test_a_path_that_is_not_a_camera_is_named_so_on_an_animated_file(tmp_path, capsys):
    f = _pull(tmp_path)
    for action in ("check", "refresh"):
        capsys.readouterr()
        assert main(["usd", action, str(f), "--path", "/Cameras"]) == 2
        err = capsys.readouterr().err.strip()
        assert err.endswith("/Cameras is a Xform, not a PhysicalCamera") and str(f) in err, err


@pytest.mark.parametrize("lens", ["still", "keyed"])
def test_a_hand_keyed_companion_sample_is_refused_not_deleted(tmp_path, capsys, lens):
    """A companion attribute keyed by hand where the lens is not keyed: refused in one line naming it, on a still
    lens as on a keyed one (before, a keyed lens's refresh deleted the artist's key), the file left as it was."""
    f = _dgauss(tmp_path) if lens == "still" else _pull(tmp_path)
    stage = Usd.Stage.Open(str(f))
    stage.GetPrimAtPath(GEOM).GetAttribute("focalLength").Set(40.0, 5.0)
    stage.Save()
    for action in ("check", "refresh"):
        err = _refused(capsys, action, f)
        assert f"{GEOM}.focalLength is keyed at time code 5, where the lens's focus" in err, err


def test_a_still_lens_with_one_sampled_sensor_reads_in_the_singular(tmp_path, capsys):
    f = _dgauss(tmp_path)
    stage = Usd.Stage.Open(str(f))
    stage.GetPrimAtPath(CAM).GetAttribute("sensor:main:aperture").Set((20.0, 15.0), 4.0)
    stage.Save()
    assert f"{CAM}.sensor:main:aperture is animated (1 time sample): usd check" in _refused(capsys, "check", f)


def _delete_keys(f, t, *attrs):
    """A layout artist deletes the lens's keys at time code ``t`` (usd-core, as a DCC would)."""
    stage = Usd.Stage.Open(str(f))
    for prim, name in attrs:
        stage.GetPrimAtPath(prim).GetAttribute(name).ClearAtTime(t)
    stage.Save()


def _samples(f, t):
    stage = Usd.Stage.Open(str(f))
    return {str(a.GetPath()) for p in (CAM, MODEL, GEOM) for a in stage.GetPrimAtPath(p).GetAttributes()
            if t in a.GetTimeSamples()}


def _values_at(f, t):
    stage = Usd.Stage.Open(str(f))
    return {n: stage.GetAttributeAtPath(n).Get(t) for n in _samples(f, t)}


_THIN_LENS_KEYS = ((MODEL, "focusDistance"), (CAM, "lens:main:fStop"), (MODEL, "focalLength"))
_THIN_LENS_LEFT = {f"{CAM}.{n}" for n in ("iris", "lens:main:iris", "lens:main:entrancePupilDistance",
                                          "lens:main:apertureDistance")} | {
    f"{GEOM}.{n}" for n in ("focalLength", "horizontalAperture", "verticalAperture", "fStop", "exposure:fStop",
                            "focusDistance", "xformOp:translate")}  # usd animate --focal's samples but its keys


def _three_marks(tmp_path):
    marks = tmp_path / "pull.csv"
    marks.write_text("frame,focus,fstop\n1,2m,2.8\n5,3m,4\n10,4m,4\n", encoding="utf-8")
    f = tmp_path / "pull.usda"
    assert main(["usd", "animate", str(f), "--focal", "50", "--marks", str(marks), "--sensor", "S35"]) == 0
    return f


def test_a_deleted_thin_lens_key_leaves_samples_the_refresh_removes(tmp_path, capsys):
    """usd animate --focal keys frames 1, 5 and 10; the artist deletes the lens's keys at 5 (focus, f-stop and the
    thin lens's focal length): the check names the eleven samples left there (the list written out by hand from
    usd animate's per-frame attributes), the refresh removes them and only them, and the file checks current."""
    f = _three_marks(tmp_path)
    kept = {t: _values_at(f, t) for t in (1.0, 10.0)}
    _delete_keys(f, 5.0, *_THIN_LENS_KEYS)
    rc, doc = _check_json(capsys, f)
    assert rc == 1 and doc["stale"] and doc["time_codes"] == [1.0, 10.0]
    assert [(s["time"], s["left"], set(s["attributes"])) for s in doc["stale_samples"]] == [(5.0, True, _THIN_LENS_LEFT)]
    capsys.readouterr()
    assert main(["usd", "check", str(f)]) == 1
    out = capsys.readouterr().out
    assert "time code 5: stale, left from a deleted key at time code 5: " in out and "deleted key (first 5: 11 " in out

    capsys.readouterr()
    assert main(["usd", "refresh", str(f), "--json"]) == 0
    done = json.loads(capsys.readouterr().out)
    assert check_document(done) == "physcam.usd_refresh" and done["written"] and not done["stale"]
    assert {(c["attribute"], c["time"]) for c in done["changed"]} == {(n, 5.0) for n in _THIN_LENS_LEFT}
    assert all(c["after"] is None and c["before"] is not None for c in done["changed"])
    assert _samples(f, 5.0) == set() and {t: _values_at(f, t) for t in (1.0, 10.0)} == kept  # the others untouched
    assert validation_errors(Usd.Stage.Open(str(f))) == []
    rc, doc = _check_json(capsys, f)
    assert rc == 0 and doc["stale_samples"] == [] and doc["time_codes"] == [1.0, 10.0]


def test_a_deleted_focus_key_on_a_stored_lens_leaves_samples_the_refresh_removes(tmp_path, capsys):
    """A real lens (stored) keyed at 1, 12 and 24 and refreshed, then the focus key at 12 deleted: the refresh's own
    samples there (the lens's pupils and principal planes among them) no longer keep 12 keyed; the text
    refresh lists each removal, and the file checks current."""
    f = _keyed_dgauss(tmp_path, ((1.0, 2000.0), (12.0, 2500.0), (24.0, 5000.0)))
    assert main(["usd", "refresh", str(f)]) == 0
    written = _samples(f, 12.0) - {f"{MODEL}.focusDistance"}
    assert {f"{CAM}.lens:main:pinholeFocalLength", f"{CAM}.lens:main:entrancePupilDistance"} <= written
    kept = {t: _values_at(f, t) for t in (1.0, 24.0)}
    _delete_keys(f, 12.0, (MODEL, "focusDistance"))
    rc, doc = _check_json(capsys, f)
    assert rc == 1 and [(s["time"], s["left"], set(s["attributes"])) for s in doc["stale_samples"]] == [
        (12.0, True, written)]
    capsys.readouterr()
    assert main(["usd", "refresh", str(f)]) == 0
    out = capsys.readouterr().out
    assert all(f"  {n} at time code 12: " in out for n in written) and out.count("-> (none)") == len(written), out
    assert _samples(f, 12.0) == set() and {t: _values_at(f, t) for t in (1.0, 24.0)} == kept
    assert validation_errors(Usd.Stage.Open(str(f))) == []
    rc, doc = _check_json(capsys, f)
    assert rc == 0 and not doc["stale"]


@pytest.mark.parametrize("edit", ["hand key", "one fewer"])
def test_a_deleted_key_with_other_samples_is_refused_not_deleted(tmp_path, capsys, edit):
    """At a time code no lens input is keyed at, only exactly the samples usd animate and refresh write there are
    removed: one more (an artist's key on the companion's clipping range) or one fewer (an artist deleted the
    companion's focal length key too: what is left may be theirs) is today's refusal, the file left as it was."""
    f = _three_marks(tmp_path)
    _delete_keys(f, 5.0, *_THIN_LENS_KEYS)
    stage = Usd.Stage.Open(str(f))
    geom = stage.GetPrimAtPath(GEOM)
    if edit == "hand key":  # named before the derived samples beside it
        geom.GetAttribute("clippingRange").Set((1.0, 1000.0), 5.0)
        expected = f"{GEOM}.clippingRange is animated (1 time sample): usd "
    else:
        geom.GetAttribute("focalLength").ClearAtTime(5.0)
        expected = "is keyed at time code 5, where the lens's focus, f-stop and focal length are not: usd "
    stage.Save()
    for action in ("check", "refresh"):
        assert expected + action in _refused(capsys, action, f)


def test_samples_left_in_a_sublayer_are_refused_naming_the_layer(tmp_path, capsys):
    """The pull and its samples in a sublayer (anim.usda) under the shot's root layer: the refresh writes only the
    root layer, so samples a deleted key left in anim.usda are refused naming it, both files left as they were."""
    from pxr import Sdf

    f = _three_marks(tmp_path)
    f.rename(tmp_path / "anim.usda")
    shot = _layer(tmp_path / "shot.usda")
    shot.subLayerPaths[:] = ["anim.usda"]
    shot.Save()
    anim = Sdf.Layer.FindOrOpen(str(tmp_path / "anim.usda"))
    for prim, name in _THIN_LENS_KEYS:
        anim.EraseTimeSample(Sdf.Path(f"{prim}.{name}"), 5.0)
    anim.Save()
    before = anim.ExportToString()
    for action in ("check", "refresh"):
        err = _refused(capsys, action, tmp_path / "shot.usda")
        assert "left from a deleted key, in " in err and "anim.usda: usd refresh writes only " in err and "at time code 5" in err, err
    anim.Reload()
    assert anim.ExportToString() == before


def test_a_key_deleted_in_a_sublayer_leaves_root_layer_samples_the_refresh_removes(tmp_path, capsys):
    """The focus keys in a sublayer (anim.usda), the refresh's samples in the shot's root layer: the key at 12
    deleted in anim.usda, the refresh removes its samples at 12 from the root layer, anim.usda untouched."""
    from pxr import Sdf

    _dgauss(tmp_path, "camera.usda")
    anim = _layer(tmp_path / "anim.usda")
    Sdf.CreatePrimInLayer(anim, MODEL)
    for p in ("/Cameras", CAM, MODEL):
        anim.GetPrimAtPath(p).specifier = Sdf.SpecifierOver
    focus = Sdf.AttributeSpec(anim.GetPrimAtPath(MODEL), "focusDistance", Sdf.ValueTypeNames.Float).path
    for t, mark in ((1, 2000.0), (12, 2500.0), (24, 5000.0)):
        anim.SetTimeSample(focus, t, mark)
    anim.Save()
    shot = _layer(tmp_path / "shot.usda")
    shot.subLayerPaths[:] = ["anim.usda", "camera.usda"]
    shot.Save()
    f = tmp_path / "shot.usda"
    assert main(["usd", "refresh", str(f)]) == 0
    written = _samples(f, 12.0) - {f"{MODEL}.focusDistance"}
    assert {f"{CAM}.lens:main:entrancePupilDistance", f"{GEOM}.focusDistance"} <= written
    anim.EraseTimeSample(focus, 12)
    anim.Save()
    before = (tmp_path / "anim.usda").read_bytes()
    rc, doc = _check_json(capsys, f)
    assert rc == 1 and [(s["time"], s["left"], set(s["attributes"])) for s in doc["stale_samples"]] == [
        (12.0, True, written)]
    assert main(["usd", "refresh", str(f)]) == 0
    assert _samples(f, 12.0) == set() and (tmp_path / "anim.usda").read_bytes() == before
    rc, doc = _check_json(capsys, f)
    assert rc == 0 and not doc["stale"] and doc["time_codes"] == [1.0, 24.0]
    assert validation_errors(Usd.Stage.Open(str(f))) == []


def test_a_pull_in_a_sublayer_edited_at_one_key_keeps_every_keys_values(tmp_path, capsys):
    """usd animate's pull (keys 1, 5, 10, 15) as the sublayer of a shot, its focus edited at 10 in that sublayer:
    the refresh writes into the shot's root layer, whose samples of an attribute replace the sublayer's whole
    set, so it must write every key there, not only the changed one (a review's find, older than round 10: the
    companion then held frame 10's value on every frame). Oracle: the thin lens's closed form at each key."""
    from pxr import Sdf

    marks = tmp_path / "pull.csv"
    marks.write_text("frame,focus,fstop\n1,2m,2.8\n5,3m,2.8\n10,4m,4\n15,6m,4\n", encoding="utf-8")
    assert main(["usd", "animate", str(tmp_path / "anim.usda"), "--focal", "50", "--marks", str(marks),
                 "--sensor", "S35"]) == 0
    shot = _layer(tmp_path / "shot.usda")
    shot.subLayerPaths[:] = ["anim.usda"]
    shot.Save()
    anim = Sdf.Layer.FindOrOpen(str(tmp_path / "anim.usda"))
    anim.SetTimeSample(Sdf.Path(f"{MODEL}.focusDistance"), 10.0, 4500.0)
    anim.Save()
    f = tmp_path / "shot.usda"
    assert main(["usd", "refresh", str(f)]) == 0
    stage = Usd.Stage.Open(str(f))
    focus = stage.GetAttributeAtPath(f"{GEOM}.focusDistance")
    assert focus.GetTimeSamples() == [1.0, 5.0, 10.0, 15.0]
    model = stage.GetPrimAtPath(MODEL).GetAttribute("focusDistance")
    pupil = stage.GetPrimAtPath(CAM).GetAttribute("lens:main:entrancePupilDistance")
    for t in (1.0, 5.0, 10.0, 15.0):
        F = model.Get(t)  # mm from the film
        s_img = (F - math.sqrt(F * (F - 4.0 * 50.0))) / 2.0
        # the companion focuses at the subject's distance from the pupil (cm): the thin lens s' in front of the
        # film at the keys left alone; at 10 the pupil as the file holds it (a thin lens's is not re-solved)
        at = s_img if t != 10.0 else pupil.Get(t)
        assert _rel(focus.Get(t) * 10.0, F - at, 1e-6), (t, focus.Get(t), F - at)
    capsys.readouterr()
    rc, doc = _check_json(capsys, f)
    assert rc == 0 and doc["stale_samples"] == [], doc["stale_samples"]
    assert validation_errors(stage) == []


def test_a_key_added_refreshed_then_deleted_leaves_samples_the_refresh_removes(tmp_path, capsys):
    """The everyday loop (a review's find): usd animate keys 1, 5 and 10; the artist adds a focus key at 7, refreshes
    (every derived attribute is sampled at 7 then, also where its value between the old keys was right), then
    deletes that key: the samples at 7 are refresh's own (usd animate's pupils are not among them), so a check
    reports them left and a refresh removes them; the file then checks current and the other keys are untouched."""
    f = _three_marks(tmp_path)
    stage = Usd.Stage.Open(str(f))
    stage.GetPrimAtPath(MODEL).GetAttribute("focusDistance").Set(2500.0, 7.0)
    stage.Save()
    assert main(["usd", "refresh", str(f)]) == 0
    at7 = _samples(f, 7.0) - {f"{MODEL}.focusDistance"}
    assert at7 == _THIN_LENS_LEFT - {f"{CAM}.lens:main:entrancePupilDistance", f"{CAM}.lens:main:apertureDistance"}
    kept = {t: _values_at(f, t) for t in (1.0, 5.0, 10.0)}
    _delete_keys(f, 7.0, (MODEL, "focusDistance"))
    rc, doc = _check_json(capsys, f)
    assert rc == 1 and [(d["time"], d["left"]) for d in doc["stale_samples"]] == [(7.0, True)]
    assert main(["usd", "refresh", str(f)]) == 0
    assert _samples(f, 7.0) == set()
    assert {t: _values_at(f, t) for t in (1.0, 5.0, 10.0)} == kept
    rc, doc = _check_json(capsys, f)
    assert rc == 0 and doc["stale_samples"] == []
    assert validation_errors(Usd.Stage.Open(str(f))) == []
