"""What a compositor sends physcam defocus and gets back (issue 42 items 4-5, issue 40 item 13).

Real OpenEXR files in and out: every other layer, pass and part comes back pixel for pixel in its
own type, with its header; the depth can be a named channel of a separate file, or a pass Blender 5
wrote through its compositor (R = G = B); a deep EXR is refused in one line; an output that is an
input (the same path, a symbolic or hard link, the depth file, a sequence onto itself) is refused
before anything is written; the PSF stack is written whole (a killed rerun leaves the old stack or
the new one, complete)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

OpenEXR = pytest.importorskip("OpenEXR")

from physcam.analysis.defocus.exr import defocus_file, read_exr  # noqa: E402
from physcam.errors import InputError  # noqa: E402
from physcam.io import MANIFEST_NAME, folder_manifest  # noqa: E402
from physcam.lens.library import load_lens  # noqa: E402

W, H = 64, 40
OPTS = dict(focus_mm=2000.0, fstop=2.8, sensor_width_mm=36.0, tile=32)
LENS = load_lens("dgauss_50mm")
CLI = [sys.executable, "-m", "physcam"]
CAMERA = ["--lens", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8", "--sensor-width", "36", "--sensor-height", "22.5",
          "--tile", "32"]


def _write(path, parts):
    """parts: [(name, header extras, {channel: array})]; one part is a plain file."""
    base = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    if len(parts) == 1:
        _, extra, chans = parts[0]
        with OpenEXR.File({**base, **extra}, chans) as f:
            f.write(str(path))
        return
    objs = [OpenEXR.Part({**base, **extra}, chans, name) for name, extra, chans in parts]
    with OpenEXR.File(objs) as f:
        f.write(str(path))


def _picture(rng):
    col = {c: rng.uniform(0, 2, (H, W)).astype(np.float16) for c in "RGB"}
    z = np.full((H, W), 3.0, np.float32)
    z[10:30, 20:40] = 0.6
    return col, z


def _channels(path):
    with OpenEXR.File(str(path), separate_channels=True) as f:
        return [(p.name(), {k: c.pixels.copy() for k, c in p.channels.items()}, dict(p.header)) for p in f.parts]


def test_other_layers_and_parts_come_back_as_read(tmp_path):
    """Issue 42 item 4: AOVs (half and float), an ID pass (uint), the depth, a second part and the
    header's own attributes come back pixel for pixel in their own types; the colour (half, as sent)
    is the defocused one, its alpha (1) stays 1."""
    rng = np.random.default_rng(1)
    col, z = _picture(rng)
    aov = {"diffuse.R": rng.uniform(0, 1, (H, W)).astype(np.float16),
           "normal.X": rng.uniform(-1, 1, (H, W)).astype(np.float32),
           "id.V": rng.integers(0, 2**31, (H, W)).astype(np.uint32)}
    main = {**col, "A": np.ones((H, W), np.float16), "Z": z, **aov}
    extra = {"owner": "shot 042", "physcamTest": 7}
    _write(tmp_path / "in.exr", [("beauty", extra, main), ("cryptomatte", {}, {"crypto.R": rng.uniform(0, 1, (H, W)).astype(np.float32)})])
    res = defocus_file(tmp_path / "in.exr", tmp_path / "out.exr", LENS, **OPTS)
    before, after = _channels(tmp_path / "in.exr"), _channels(tmp_path / "out.exr")
    assert [p[0] for p in after] == [p[0] for p in before]
    for (_, b, hb), (_, a, ha) in zip(before, after):
        assert set(a) == set(b)
        for name in b:
            assert a[name].dtype == b[name].dtype, name
            if name not in ("R", "G", "B", "A"):
                assert np.array_equal(a[name], b[name]), name
        for k in ("owner", "physcamTest"):
            if k in hb:
                assert ha[k] == hb[k]
    out = after[0][1]
    assert not np.array_equal(out["R"], before[0][1]["R"])  # defocused
    assert np.abs(out["A"].astype(float) - 1.0).max() <= 1e-3  # half precision
    assert res["alpha_channel"] == "A" and set(res["kept_channels"]) >= {"Z", "diffuse.R", "normal.X", "id.V", "crypto.R"}


def test_a_depth_file_channel_can_be_named(tmp_path):
    """Issue 42 item 4: a depth file with two depth channels is refused until one is named
    (--depth-channel); named, the picture is the one defocused with that depth as a channel of the image."""
    rng = np.random.default_rng(2)
    col, z = _picture(rng)
    _write(tmp_path / "in.exr", [("", {}, {**col, "Z": z})])
    _write(tmp_path / "plain.exr", [("", {}, dict(col))])
    _write(tmp_path / "z.exr", [("", {}, {"depth.Z": (1 / z).astype(np.float32), "camera.Z": z})])
    with pytest.raises(InputError, match="several depth channels"):
        defocus_file(tmp_path / "plain.exr", tmp_path / "a.exr", LENS, depth=str(tmp_path / "z.exr"), **OPTS)
    defocus_file(tmp_path / "plain.exr", tmp_path / "b.exr", LENS, depth=str(tmp_path / "z.exr"),
                 depth_channel="camera.Z", **OPTS)
    defocus_file(tmp_path / "in.exr", tmp_path / "c.exr", LENS, **OPTS)
    b, c = read_exr(tmp_path / "b.exr").channels, read_exr(tmp_path / "c.exr").channels
    for ch in "RGB":
        np.testing.assert_array_equal(b[ch], c[ch])


def test_blender5_compositor_depth_is_read_and_a_colour_file_is_not(tmp_path):
    """Issue 42 item 4: Blender 5 writes a pass sent through the compositor as R, G, B, A, the pass in
    each colour channel: read from R. A colour picture given as the depth is refused in one sentence."""
    rng = np.random.default_rng(3)
    col, z = _picture(rng)
    _write(tmp_path / "in.exr", [("", {}, dict(col))])
    _write(tmp_path / "depth.exr", [("", {}, {"R": z, "G": z, "B": z, "A": np.ones((H, W), np.float32)})])
    _write(tmp_path / "ref.exr", [("", {}, {**col, "Z": z})])
    res = defocus_file(tmp_path / "in.exr", tmp_path / "out.exr", LENS, depth=str(tmp_path / "depth.exr"), **OPTS)
    assert res["depth_channel"] == "R"
    defocus_file(tmp_path / "ref.exr", tmp_path / "ref_out.exr", LENS, **OPTS)
    np.testing.assert_array_equal(read_exr(tmp_path / "out.exr").channels["R"], read_exr(tmp_path / "ref_out.exr").channels["R"])
    with pytest.raises(InputError, match="colour picture, not a depth pass"):
        defocus_file(tmp_path / "in.exr", tmp_path / "bad.exr", LENS, depth=str(tmp_path / "in.exr"), **OPTS)


def _cli(*args, timeout=300):
    return subprocess.run([*CLI, *map(str, args)], capture_output=True, text=True, timeout=timeout)


def _one_line(p):
    lines = [ln for ln in p.stderr.strip().splitlines() if not ln.startswith("physcam: note")]
    return p.returncode == 2 and len(lines) == 1 and "Traceback" not in p.stderr


def test_a_deep_exr_is_refused_in_one_line(tmp_path):
    """Issue 42 item 4: a deep EXR (samples per pixel) is refused with one sentence, exit 2."""
    samples = np.empty((H, W), dtype=object)
    for i in range(H):
        for j in range(W):
            samples[i, j] = np.array([1.0, 2.0], dtype=np.float32)
    with OpenEXR.File({"type": OpenEXR.deepscanline, "compression": OpenEXR.ZIPS_COMPRESSION},
                      {"R": samples, "G": samples, "B": samples, "Z": samples}) as f:
        f.write(str(tmp_path / "deep.exr"))
    p = _cli("defocus", tmp_path / "deep.exr", *CAMERA, "-o", tmp_path / "out.exr")
    assert _one_line(p) and "deep EXR" in p.stderr
    assert not (tmp_path / "out.exr").exists()


@pytest.mark.parametrize("how", ["same path", "symlink", "hard link", "depth file", "relative path"])
def test_an_output_that_is_an_input_is_refused(tmp_path, how):
    """Issue 40 item 13: ``defocus IN.exr -o IN.exr --force`` overwrote the source render and its
    depth pass. Refused in one line whatever the spelling, --force or not; the inputs are untouched."""
    rng = np.random.default_rng(4)
    col, z = _picture(rng)
    _write(tmp_path / "in.exr", [("", {}, dict(col))])
    _write(tmp_path / "z.exr", [("", {}, {"Z": z})])
    before = {p: p.read_bytes() for p in (tmp_path / "in.exr", tmp_path / "z.exr")}
    out = {"same path": tmp_path / "in.exr", "depth file": tmp_path / "z.exr",
           "relative path": tmp_path / "sub" / ".." / "in.exr"}.get(how, tmp_path / "other.exr")
    (tmp_path / "sub").mkdir()
    if how == "symlink":
        os.symlink(tmp_path / "in.exr", out)
    elif how == "hard link":
        os.link(tmp_path / "in.exr", out)
    p = _cli("defocus", tmp_path / "in.exr", "--depth", tmp_path / "z.exr", *CAMERA, "-o", out, "--force")
    assert _one_line(p) and "is the input" in p.stderr
    for path, data in before.items():
        assert path.read_bytes() == data


def test_a_sequence_onto_itself_is_refused(tmp_path):
    """Issue 40 item 13 for a shot: an output pattern whose frames are the input frames is refused
    before any frame is written."""
    pytest.importorskip("distributed")
    rng = np.random.default_rng(5)
    col, z = _picture(rng)
    for n in (1, 2):
        _write(tmp_path / f"in.{n:04d}.exr", [("", {}, {**col, "Z": z})])
    before = (tmp_path / "in.0001.exr").read_bytes()
    p = _cli("defocus", tmp_path / "in.####.exr", *CAMERA, "-o", tmp_path / "in.####.exr", "--force", "--workers", "1")
    assert _one_line(p) and "is the input" in p.stderr
    assert (tmp_path / "in.0001.exr").read_bytes() == before


def test_cli_defocus_json_document(tmp_path):
    """A render with a Z channel defocuses through the CLI; the --json document meets its schema and
    names what was kept."""
    import jsonschema

    from physcam.cli._output import schema_file

    rng = np.random.default_rng(6)
    col, z = _picture(rng)
    _write(tmp_path / "in.exr", [("", {}, {**col, "Z": z, "diffuse.R": col["R"]})])
    p = _cli("defocus", tmp_path / "in.exr", *CAMERA, "-o", tmp_path / "out.exr", "--json")
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    jsonschema.validate(doc, json.loads(schema_file(doc["schema"]).read_text()))
    assert doc["depth_channel"] == "Z" and doc["depth_kind"] == "planar" and doc["alpha_channel"] is None
    assert set(doc["kept_channels"]) == {"Z", "diffuse.R"} and doc["kernels_traced"] > 0


KERNELS = ["defocus-kernels", *CAMERA[:-2], "--resolution", "64x40", "--field-grid", "2x2"]


def test_kernel_stack_is_written_whole_and_replaced_whole(tmp_path):
    """Issue 42 item 5: a rerun (--force) replaces the stack as a whole: its manifest lists exactly the
    new kernels and index.json; a folder of someone else's files is never replaced."""
    out = tmp_path / "psf"
    p = _cli(*KERNELS, "--depths", "1m,inf", "-o", out)
    assert p.returncode == 0, p.stderr
    first = folder_manifest(out)
    assert first is not None and len([f for f in first["files"] if f["path"].endswith(".exr")]) == 4 * 2
    p = _cli(*KERNELS, "--depths", "0.5m,1m,4m", "-o", out, "--force")
    assert p.returncode == 0, p.stderr
    second = folder_manifest(out)
    names = sorted(f["path"] for f in second["files"])
    index = json.loads((out / "index.json").read_text())
    assert names == sorted([e["file"] for e in index["kernels"]] + ["index.json"])
    assert sorted(os.listdir(out)) == sorted(names + [MANIFEST_NAME]) and len(index["kernels"]) == 4 * 3
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("mine")
    p = _cli(*KERNELS, "--depths", "1m", "-o", tmp_path / "mine", "--force")
    assert _one_line(p) and (tmp_path / "mine" / "notes.txt").read_text() == "mine"


def test_a_killed_stack_rerun_leaves_a_whole_stack(tmp_path):
    """Issue 42 item 5: a killed --force rerun left a mix of old and new kernels under the old
    index.json. Killed at any moment, the folder is the old stack or the new one, each complete (its
    manifest matches what is on disk)."""
    out = tmp_path / "psf"
    assert _cli(*KERNELS, "--depths", "1m", "-o", out).returncode == 0
    old = folder_manifest(out)
    for delay in (0.5, 2.0, 4.0):
        proc = subprocess.Popen([*CLI, *KERNELS, "--depths", "0.5m,1m,2m,4m,8m,inf", "-o", str(out), "--force"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(delay)
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
        now = folder_manifest(out)
        assert now is not None, f"killed after {delay} s: the stack is not whole"
        assert now["files"] == old["files"] or len(now["files"]) == 4 * 6 + 1
        old = now


def test_a_lens_file_inside_the_stack_folder_is_refused(tmp_path):
    """The lens file is an input of defocus-kernels: an output folder holding it is refused."""
    import shutil

    from physcam.lens.library import list_lenses

    out = tmp_path / "psf"
    assert _cli(*KERNELS, "--depths", "1m", "-o", out).returncode == 0
    shutil.copy(next(r.path for r in list_lenses() if r.slug == "dgauss_50mm"), out / "lens.toml")
    args = [a if a != "dgauss_50mm" else str(out / "lens.toml") for a in KERNELS]
    p = _cli(*args, "--depths", "1m", "-o", out, "--force")
    assert _one_line(p) and "lies inside the output folder" in p.stderr
    assert (out / "lens.toml").exists()
