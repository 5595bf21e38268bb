"""Issue 40, item 13: an output never overwrites an input, and a folder of outputs is written whole.

- ``physcam.io.refuse_inputs_as_outputs`` tells one file by its device and inode, so another
  spelling of the path, a symbolic link and a hard link are all the input; the CLI runs it on every
  command before any work (a command's other path arguments are its inputs).
- The folders a command writes (``distortion --stmap``, ``export blender/pbrt/mitsuba``, ``compare
  blender``, ``demo``) are published whole (``physcam.io.staged_folder``): a rerun SIGKILLed while it
  writes leaves the previous folder exactly as it was, never a mix of two runs; the next run removes
  the killed one's temporary folder. The kill lands mid-write every time: the run stops itself
  (SIGSTOP) as it puts its second file in place, and is killed there.
"""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from physcam.cli import main
from physcam.errors import ExportError
from physcam.io import MANIFEST_NAME, folder_manifest

ROOT = Path(__file__).resolve().parents[2]
NIKKOR = ROOT / "tests/data/reference_lenses/physical-camera-toml/nikkor_fisheye_16mm_f2_8.toml"  # needs repairs
CLIP = ROOT / "src/physcam/data/samples/arri_alexa_lf_B001C001_first48.csv"


def test_one_file_by_any_name_is_refused(tmp_path):
    from physcam.io import refuse_inputs_as_outputs

    lens = tmp_path / "lens.toml"
    lens.write_text("x")
    os.link(lens, tmp_path / "hard.toml")
    os.symlink(lens, tmp_path / "soft.toml")
    (tmp_path / "sub").mkdir()
    for out in (lens, tmp_path / "hard.toml", tmp_path / "soft.toml", tmp_path / "sub" / ".." / "lens.toml",
                str(lens)):
        with pytest.raises(ExportError, match="is the input") as exc:
            refuse_inputs_as_outputs([str(lens)], [out])
        assert len(str(exc.value).splitlines()) == 1
    with pytest.raises(ExportError, match="inside the output folder"):
        refuse_inputs_as_outputs([lens], [], folders=[tmp_path])
    # not the input: a new file, another file, a name that is no file (a bundled lens), the null device
    (tmp_path / "other.toml").write_text("x")
    refuse_inputs_as_outputs([lens, "dgauss_50mm", None, ""], [tmp_path / "new.rib", tmp_path / "other.toml",
                                                             os.devnull, None])
    refuse_inputs_as_outputs([lens], [tmp_path / "sub"])  # a file output: an input beside it is fine
    assert lens.read_text() == "x"


@pytest.mark.parametrize("case", ["lens fix", "export rib", "usd animate", "metadata opentrackio", "hard link"])
def test_a_command_refuses_to_write_over_its_input(tmp_path, capsys, case):
    """Each of these overwrote its input with ``--force`` before (the lens repaired in place, a lens
    file replaced by a RIB, the focus marks by the camera, the clip by its OpenTrackIO JSON)."""
    lens = tmp_path / "lens.toml"
    lens.write_bytes(NIKKOR.read_bytes())
    marks = tmp_path / "marks.usda"
    marks.write_text("frame,focus\n1,2m\n2,3m\n")
    clip = tmp_path / "clip.json"
    clip.write_bytes(CLIP.read_bytes())
    os.link(lens, tmp_path / "hard.rib")
    argv, victim = {
        "lens fix": (["lens", "fix", "--lens", str(lens), "-o", str(lens), "--apply", "--force"], lens),
        "export rib": (["export", "rib", "--lens", str(lens), "--focus", "2m", "-o", f"{tmp_path}/./lens.toml",
                        "--force"], lens),
        "usd animate": (["usd", "animate", str(marks), "--marks", str(marks), "--focal", "50", "--fstop", "2",
                         "--force"], marks),
        "metadata opentrackio": (["metadata", "opentrackio", str(clip), "-o", str(clip), "--force"], clip),
        "hard link": (["export", "rib", "--lens", str(lens), "--focus", "2m", "-o", str(tmp_path / "hard.rib"),
                       "--force"], lens),
    }[case]
    before = victim.read_bytes()
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is the input" in err[0]
    assert victim.read_bytes() == before and (tmp_path / "hard.rib").read_bytes() == lens.read_bytes()


def test_an_input_inside_an_output_folder_is_refused(tmp_path, capsys):
    """``--force`` replaces a folder physcam wrote: a lens file put in it since would go with it."""
    out = tmp_path / "maps"
    argv = ["distortion", "--resolution", "96x64", "--focus", "2m", "--stmap", str(out), "--force"]
    assert main(argv + ["--lens", "dgauss_50mm"]) == 0
    lens = out / "mine.toml"
    lens.write_bytes((ROOT / "src/physcam/data/lenses/dgauss_50mm.toml").read_bytes())
    assert main(argv + ["--lens", str(lens)]) == 2
    assert "inside the output folder" in capsys.readouterr().err
    assert lens.is_file()


# ---- folders written whole -------------------------------------------------------------------

def _tree(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize("argv, files", [
    (["distortion", "dgauss_50mm", "--resolution", "96x64", "--focus", "2m", "--fit", "brown", "--fit", "3de4",
      "--fit", "nuke", "--stmap"], {"distortion.exr", "undistortion.png", "physcam_stmap.nk", "brown_conrady.json"}),
    (["export", "pbrt", "--lens", "dgauss_50mm", "--focus", "2m", "-o"], {"dgauss_50mm.dat"}),
    (["export", "mitsuba", "--focal", "50", "--fstop", "2", "--focus", "2m", "-o"], {"camera.xml", "camera.json"}),
    (["export", "blender", "--lens", "cooke_triplet_50mm_f4_5", "--focus", "2m", "-o"],
     {"cooke_triplet_50mm_f4_5.osl", "setup_cooke_triplet_50mm_f4_5.py"}),
], ids=["distortion", "pbrt", "mitsuba", "blender"])
def test_a_folder_is_published_whole_with_its_manifest(tmp_path, capsys, argv, files):
    out = tmp_path / "out"
    assert main(argv + [str(out)]) == 0
    doc = folder_manifest(out)
    assert doc is not None and doc["about"]["command"].startswith("physcam ")
    listed = {f["path"] for f in doc["files"]}
    assert files <= listed and listed | {MANIFEST_NAME} == set(_tree(out))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no temporary folder left
    for p in out.iterdir():  # no file names the temporary folder it was written in
        assert b".physcam-tmp." not in p.read_bytes(), p.name
    before = _tree(out)
    assert main(argv + [str(out)]) == 2  # exists, no --force
    (out / "extra.txt").write_text("the user's note")
    assert main(argv + [str(out), "--force"]) == 2  # changed by the user since: not physcam's to replace
    assert "did not write" in capsys.readouterr().err
    (out / "extra.txt").unlink()
    assert _tree(out) == before
    assert main(argv + [str(out), "--force"]) == 0 and folder_manifest(out) is not None


#: ``python -c`` this, then physcam's arguments: physcam, stopped by itself as it puts its second file of
#: the output folder (named in $STOP_IN: the folder or its temporary) in place, a physcam temporary
#: linked or renamed to its name, so that a SIGKILL lands mid-write.
_STOP_AT_SECOND_FILE = """
import os, runpy, signal, sys
seen, folder = [], os.environ["STOP_IN"]
def stopping(call):
    def run(src, dst, *args, **kwargs):
        dst_path = os.fspath(dst)
        if (".physcam-tmp." in os.fspath(src) and folder in dst_path
                and not dst_path.endswith("physcam-manifest.json")):
            seen.append(dst)
            if len(seen) == 2:
                os.kill(os.getpid(), signal.SIGSTOP)
        return call(src, dst, *args, **kwargs)
    return run
os.link, os.replace = stopping(os.link), stopping(os.replace)
sys.argv = ["physcam", *sys.argv[1:]]
runpy.run_module("physcam", run_name="__main__", alter_sys=True)
"""


def _kill_mid_write(argv, folder_name: str, timeout_s=300.0) -> None:
    with tempfile.TemporaryFile() as err:
        proc = subprocess.Popen([sys.executable, "-c", _STOP_AT_SECOND_FILE, *argv], stdout=subprocess.DEVNULL,
                                stderr=err, env=dict(os.environ, STOP_IN=folder_name))
        try:
            deadline = time.monotonic() + timeout_s
            while True:
                pid, status = os.waitpid(proc.pid, os.WUNTRACED | os.WNOHANG)
                if pid:
                    break
                if time.monotonic() > deadline:
                    pytest.fail(f"the run neither stopped nor ended in {timeout_s} s")
                time.sleep(0.01)
            if not os.WIFSTOPPED(status):
                proc.returncode = status
                err.seek(0)
                pytest.fail(f"the run ended (status {status}) before its second file: {err.read().decode()[-500:]}")
        finally:
            if proc.returncode is None:
                proc.kill()
                assert proc.wait(timeout=60) == -signal.SIGKILL


@pytest.mark.slow
def test_a_rerun_killed_mid_write_leaves_the_previous_folder_whole(tmp_path):
    """``distortion --stmap DIR --force`` at 2 m, then a rerun at 3 m SIGKILLed after its first file:
    DIR holds the 2 m run, every file of it and nothing of the 3 m one (before, the 3 m
    ``distortion.exr`` sat beside the 2 m ``undistortion.exr``, looking complete). The next run
    publishes the 3 m folder and leaves no temporary."""
    out = tmp_path / "maps"
    base = ["distortion", "zuiko_18mm_f3_5", "--resolution", "128x96", "--fit", "brown", "--fit", "3de4",
            "--fit", "nuke", "--stmap", str(out), "--force", "--focus"]
    assert main(base + ["2m"]) == 0
    first = _tree(out)
    _kill_mid_write(base + ["3m"], "maps")
    assert _tree(out) == first and folder_manifest(out) is not None
    litter = [p.name for p in tmp_path.iterdir() if p.name != "maps"]
    assert litter and all(n.startswith(".maps.physcam-tmp.") for n in litter), litter  # the killed run's
    assert main(base + ["3m"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["maps"]
    second = _tree(out)
    assert set(second) == set(first) and all(second[k] != first[k] for k in ("distortion.exr", "undistortion.exr"))
