"""physcam defocus of a shot (IN.####.exr) frame-parallel on Dask (issue 34): every frame equals
the same frame defocused alone, the kernels are traced once into the shared folder, and a rerun
skips the frames already written (resumable) unless forced. Real Dask (a LocalCluster), real EXRs."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("distributed")

from physcam.analysis.defocus.exr import defocus_file, read_exr  # noqa: E402
from physcam.characterize.defocus_shot import defocus_sequence, sequence_frames  # noqa: E402
from physcam.errors import InputError  # noqa: E402
from physcam.lens.library import load_lens  # noqa: E402

W, H = 48, 32
LENS = load_lens("dgauss_50mm")
OPTS = dict(focus_mm=2000.0, fstop=2.8, sensor_width_mm=36.0, tile=16)


def _exr(path, planes):
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {k: np.ascontiguousarray(v, np.float32) for k, v in planes.items()}) as f:
        f.write(str(path))


@pytest.fixture
def shot(tmp_path):
    rng = np.random.default_rng(3)
    for n in (7, 8, 9):
        z = np.full((H, W), 3.0)
        z[10:20, 10 + n:20 + n] = 0.6  # a near block moving right
        _exr(tmp_path / f"in.{n:04d}.exr", {**{c: rng.uniform(0, 1, (H, W)) for c in "RGB"}, "Z": z})
    (tmp_path / "in.12.exr").write_bytes(b"")  # not a frame of the pattern (2 digits)
    return tmp_path


def test_frames_match_one_by_one_and_rerun_skips(shot):
    """Frames equal the one-by-one defocus; the output folder is made; reruns skip what exists."""
    out = str(shot / "out" / "dof.####.exr")
    s = defocus_sequence(str(shot / "in.####.exr"), out, LENS, workers=1, **OPTS)
    assert s.done == [7, 8, 9] and s.skipped == []
    kernels = sorted((shot / "out" / "kernels").rglob("*.npz"))
    assert kernels
    ref = defocus_file(shot / "in.0008.exr", shot / "ref.exr", LENS, **OPTS)
    assert ref["kernels_traced"] > 0
    got, want = read_exr(shot / "out" / "dof.0008.exr"), read_exr(shot / "ref.exr")
    for c in "RGB":
        np.testing.assert_allclose(got.channels[c], want.channels[c], rtol=1e-5, atol=1e-6)
    mtime = (shot / "out" / "dof.0007.exr").stat().st_mtime_ns
    again = defocus_sequence(str(shot / "in.####.exr"), out, LENS, workers=1, **OPTS)
    assert again.done == [] and again.skipped == [7, 8, 9]
    assert (shot / "out" / "dof.0007.exr").stat().st_mtime_ns == mtime
    (shot / "out" / "dof.0008.exr").unlink()
    third = defocus_sequence(str(shot / "in.####.exr"), out, LENS, workers=1, **OPTS)
    assert third.done == [8] and third.skipped == [7, 9]


def test_patterns_are_checked(shot):
    assert [n for n, _ in sequence_frames(str(shot / "in.####.exr"))] == [7, 8, 9]
    with pytest.raises(InputError, match="one run of #"):
        sequence_frames(str(shot / "in.exr"))
    with pytest.raises(InputError, match="no frames match"):
        sequence_frames(str(shot / "in.#####.exr"))


def test_cli_sequence_json_document(shot):
    """``physcam defocus IN.####.exr -o OUT.####.exr --json``: the document validates against its
    schema and names the frames; a second run skips them all."""
    import json
    import subprocess
    import sys

    import jsonschema

    from physcam.cli._output import schema_file

    args = [sys.executable, "-m", "physcam", "defocus", str(shot / "in.####.exr"), "--lens", "dgauss_50mm", "--focus",
            "2m", "--fstop", "2.8", "--sensor-width", "36", "--sensor-height", "24", "--tile", "16", "--workers", "1",
            "-o", str(shot / "o" / "d.####.exr"), "--json"]
    (shot / "o").mkdir()
    for done, skipped in (([7, 8, 9], []), ([], [7, 8, 9])):
        p = subprocess.run(args, capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr
        doc = json.loads(p.stdout)
        jsonschema.validate(doc, json.loads(schema_file(doc["schema"]).read_text()))
        assert (doc["frames_done"], doc["frames_skipped"]) == (done, skipped)
