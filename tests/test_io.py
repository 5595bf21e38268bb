"""Atomic writes: no clobber without force, normal file modes, nothing left behind."""

import os
import stat

import pytest

from physcam import ExportError
from physcam.io import atomic_write


def test_new_file_gets_the_umask_mode_not_private(tmp_path):
    old = os.umask(0o022)
    try:
        p = atomic_write(tmp_path / "a.txt", "x")
    finally:
        os.umask(old)
    assert stat.S_IMODE(p.stat().st_mode) == 0o644


def test_force_keeps_the_replaced_files_mode(tmp_path):
    p = tmp_path / "a.txt"
    p.write_text("old")
    p.chmod(0o640)
    atomic_write(p, "new", force=True)
    assert p.read_text() == "new"
    assert stat.S_IMODE(p.stat().st_mode) == 0o640


def test_no_clobber_and_no_temporary_left(tmp_path):
    p = tmp_path / "a.txt"
    atomic_write(p, "one")
    with pytest.raises(ExportError, match="--force"):
        atomic_write(p, "two")
    assert p.read_text() == "one"
    assert sorted(f.name for f in tmp_path.iterdir()) == ["a.txt"]


def _race_writer(args):
    """One of several processes writing the same new file at once (issue 8: no-clobber race)."""
    import time

    from physcam.errors import ExportError
    from physcam.io import atomic_write

    path, tag, start = args
    while time.time() < start:  # all processes leave the gate together
        pass
    try:
        atomic_write(path, f"written by {tag}\n" * 2000)
        return tag
    except ExportError as exc:
        assert "already exists" in str(exc)
        return None


def test_concurrent_no_clobber_writers_have_exactly_one_winner(tmp_path):
    import multiprocessing as mp
    import time

    ctx = mp.get_context("fork")
    with ctx.Pool(8) as pool:
        for trial in range(25):
            path = tmp_path / f"race{trial}.usda"
            start = time.time() + 0.05
            winners = [w for w in pool.map(_race_writer, [(str(path), k, start) for k in range(8)]) if w is not None]
            assert len(winners) == 1, f"trial {trial}: {len(winners)} writers reported success"
            assert path.read_text() == f"written by {winners[0]}\n" * 2000
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]  # no temporary left behind


# ---- temporaries a killed writer leaves (issue 24 item 12) ------------------------------------------
def _dead_pid() -> int:
    """The id of a process that has ended (a child reaped here; ids are not reused at once)."""
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def _litter(folder, target, host, pid, suffix=".tmp"):
    from physcam.io import TEMP_MARK

    p = folder / f".{target}{TEMP_MARK}{host}.{pid}.0badc0de{suffix}"
    p.write_bytes(b"half a file")
    return p


def test_the_next_write_removes_only_dead_local_writers_temporaries(tmp_path):
    import socket
    import subprocess
    import sys

    from physcam.io import _host

    assert _host() == "".join(c if c.isalnum() or c in "-_" else "-" for c in socket.gethostname())[:64]
    running = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        dead = _litter(tmp_path, "shot.usda", _host(), _dead_pid())
        dead_crate = _litter(tmp_path, "shot.usda", _host(), _dead_pid(), suffix=".usdc")
        alive = _litter(tmp_path, "shot.usda", _host(), running.pid)
        elsewhere = _litter(tmp_path, "shot.usda", "render-node-7", _dead_pid())
        other_target = _litter(tmp_path, "shot2.usda", _host(), _dead_pid())
        atomic_write(tmp_path / "shot.usda", "new")
        left = {p.name for p in tmp_path.iterdir()}
        assert dead.name not in left and dead_crate.name not in left
        assert {alive.name, elsewhere.name, other_target.name, "shot.usda"} == left
    finally:
        running.kill()
        running.wait()


def test_a_temporary_of_a_long_target_name_fits_the_file_system(tmp_path):
    name = "x" * 250 + ".usda"  # 255 bytes: the longest name most file systems take
    p = atomic_write(tmp_path / name, "ok")
    assert p.read_text() == "ok" and [f.name for f in tmp_path.iterdir()] == [name]


# ---- folders written as a whole (staged_folder) ----------------------------------------------

def test_a_folder_appears_whole_with_its_manifest(tmp_path):
    import hashlib
    from physcam.io import MANIFEST_NAME, folder_manifest, staged_folder
    out = tmp_path / "maps"
    with staged_folder(out, about={"command": "test"}) as tmp:
        assert not out.exists()  # nothing is visible while the folder is being written
        (tmp / "a.txt").write_text("alpha")
        (tmp / "sub").mkdir()
        (tmp / "sub" / "b.bin").write_bytes(b"\0\1\2")
    doc = folder_manifest(out)
    assert doc["about"] == {"command": "test"}
    assert [f["path"] for f in doc["files"]] == ["a.txt", "sub/b.bin"]
    assert doc["files"][0]["sha256"] == hashlib.sha256(b"alpha").hexdigest()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["maps"]  # no temporary left
    assert (out / MANIFEST_NAME).is_file()
    (out / "a.txt").write_text("changed length")
    assert folder_manifest(out) is None  # a folder changed since is not "complete"


def test_a_failed_rerun_keeps_the_previous_folder_whole(tmp_path):
    from physcam.io import folder_manifest, staged_folder
    out = tmp_path / "maps"
    with staged_folder(out) as tmp:
        (tmp / "first.txt").write_text("1")
    with pytest.raises(RuntimeError), staged_folder(out, force=True) as tmp:
        (tmp / "second.txt").write_text("2")
        raise RuntimeError("killed half way")
    assert sorted(p.name for p in out.iterdir()) == ["first.txt", "physcam-manifest.json"]
    assert folder_manifest(out) is not None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["maps"]
    with staged_folder(out, force=True) as tmp:
        (tmp / "second.txt").write_text("2")
    assert sorted(p.name for p in out.iterdir()) == ["physcam-manifest.json", "second.txt"]  # no mix


def test_a_folder_is_never_replaced_without_force_nor_a_users_folder_with_it(tmp_path):
    from physcam.errors import ExportError
    from physcam.io import staged_folder
    out = tmp_path / "shoot"
    out.mkdir()
    (out / "IMG_0001.png").write_bytes(b"the user's photo")
    with pytest.raises(ExportError, match="already exists"), staged_folder(out):
        pass
    with pytest.raises(ExportError, match="did not write"), staged_folder(out, force=True):
        pass
    assert (out / "IMG_0001.png").read_bytes() == b"the user's photo"
    empty = tmp_path / "empty"
    empty.mkdir()
    with staged_folder(empty, force=True) as tmp:
        (tmp / "x").write_text("x")
    assert (empty / "x").read_text() == "x"


def test_a_killed_writers_temporary_folder_is_removed_by_the_next_write(tmp_path):
    import subprocess
    import sys
    from physcam.io import staged_folder
    out = tmp_path / "maps"
    script = ("import os, signal, sys; from physcam.io import staged_folder\n"
              "with staged_folder(sys.argv[1]) as tmp:\n"
              "    (tmp / 'half.txt').write_text('half')\n"
              "    os.kill(os.getpid(), signal.SIGKILL)\n")
    subprocess.run([sys.executable, "-c", script, str(out)], check=False)
    assert not out.exists() and len(list(tmp_path.iterdir())) == 1  # the killed writer's temporary
    with staged_folder(out) as tmp:
        (tmp / "whole.txt").write_text("whole")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["maps"]


# ---- devices, FIFOs and sockets are never renamed over (issue 40 item 12) -------------------------

def _special_targets(tmp_path):
    """(label, path) of special files made in ``tmp_path``: a FIFO, a socket, and (where this process
    may make device nodes) the zero device's numbers (1, 5): none of them may be replaced."""
    import socket as socket_module

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    out = [("FIFO", fifo)]
    sock_path = tmp_path / "sock"
    sock = socket_module.socket(socket_module.AF_UNIX, socket_module.SOCK_STREAM)
    sock.bind(str(sock_path))
    out.append(("socket", sock_path))
    try:
        os.mknod(tmp_path / "zero", stat.S_IFCHR | 0o666, os.makedev(1, 5))
        out.append(("character device", tmp_path / "zero"))
    except OSError:  # not root, or a nodev mount: the FIFO and the socket still stand
        pass
    return out, sock


def test_a_fifo_socket_or_device_is_refused_never_replaced(tmp_path):
    from physcam.io import check_writable, staged

    targets, sock = _special_targets(tmp_path)
    try:
        for label, path in targets:
            before = os.stat(path)
            for force in (False, True):
                for write in (lambda: atomic_write(path, b"data", force=force),
                              lambda: staged(path, force=force, suffix=".usdc").__enter__(),
                              lambda: check_writable(path, force=force)):
                    with pytest.raises(ExportError, match="not a regular file") as exc:
                        write()
                    assert len(str(exc.value).splitlines()) == 1, label
            after = os.stat(path)
            assert (after.st_ino, stat.S_IFMT(after.st_mode)) == (before.st_ino, stat.S_IFMT(before.st_mode)), label
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for _, p in targets)  # no temporary
    finally:
        sock.close()


def test_the_null_device_is_written_through_and_stays_a_device(tmp_path):
    """A node with the null device's numbers (made in tmp where allowed) takes the bytes and stays a
    character device; only then is the system's /dev/null itself tried (so a regression fails on the
    copy in tmp first). Neither needs ``force``: nothing is overwritten."""
    from physcam.io import staged

    null = os.stat(os.devnull)
    copy = tmp_path / "null"
    try:
        os.mknod(copy, stat.S_IFCHR | 0o666, null.st_rdev)
    except OSError:
        copy = None
    for path in ([copy] if copy else []) + [os.devnull]:
        before = os.stat(path)
        assert atomic_write(path, b"discarded") == type(tmp_path)(path)
        with staged(path, force=True, suffix=".png") as tmp:
            tmp.write_bytes(b"\x89PNG discarded")
        after = os.stat(path)
        assert stat.S_ISCHR(after.st_mode) and (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev)
    assert sorted(p.name for p in tmp_path.iterdir()) == (["null"] if copy else [])


def test_standard_output_is_written_through(tmp_path):
    """``/dev/stdout`` is this process's standard output (a pipe here): the file's bytes go down the
    pipe, in order after what was printed before, and nothing in /dev is touched."""
    import subprocess
    import sys

    script = ("import sys; from physcam.io import atomic_write\n"
              "print('before', flush=False)\n"
              "atomic_write('/dev/stdout', b'the file\\n')\n"
              "print('after')\n")
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, check=True)
    assert p.stdout == b"before\nthe file\nafter\n"
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)


def test_cli_output_to_a_fifo_or_dev_null(tmp_path, capsys):
    from physcam.cli import main

    fifo = tmp_path / "cam.rib"
    os.mkfifo(fifo)
    argv = ["export", "rib", "--focal", "50", "--fstop", "2", "--focus", "3m", "--force", "-o"]
    assert main(argv + [str(fifo)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is a FIFO (named pipe), not a regular file" in err[0]
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    assert main(argv + [os.devnull]) == 0
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)


def test_a_folder_output_never_replaces_a_fifo_or_the_null_device(tmp_path):
    """Before any work is done (the block is never entered), with or without force."""
    from physcam.io import staged_folder

    fifo = tmp_path / "maps"
    os.mkfifo(fifo)
    for target in (fifo, os.devnull):
        for force in (False, True):
            with pytest.raises(ExportError, match="already exists|not a folder"), staged_folder(target, force=force):
                pytest.fail("the block ran")
    assert stat.S_ISFIFO(os.stat(fifo).st_mode) and stat.S_ISCHR(os.stat(os.devnull).st_mode)
    assert [p.name for p in tmp_path.iterdir()] == ["maps"]


def test_the_refusal_to_overwrite_speaks_to_both_kinds_of_user(tmp_path):
    """`pass --force (force=True)` read to a 1st AC at the command line like a second flag (round 8):
    the Python keyword is said to be Python's."""
    f = tmp_path / "card.pdf"
    atomic_write(f, b"x")
    with pytest.raises(ExportError, match=r"already exists; pass --force \(in Python, force=True\) to overwrite it"):
        atomic_write(f, b"y")
    assert f.read_bytes() == b"x"


@pytest.mark.parametrize("below", ["x.png", "a/b/x.png"])
def test_a_file_in_the_outputs_folder_path_is_refused_before_writing(tmp_path, below):
    """An output under a file (``notes.txt/x.png``, ``notes.txt/a/b/x.png``) cannot be written: refused
    by the check a command runs before its work, naming the file, and nothing is made."""
    from physcam.io import check_writable

    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(ExportError, match=r"a part of its folder .*notes\.txt is a file, not a folder"):
        check_writable(tmp_path / "notes.txt" / below)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_a_figure_under_a_file_is_refused_before_the_lens_is_loaded(tmp_path, capsys):
    """The CLI's check comes first: given a lens that does not exist, the refusal names the folder."""
    from physcam.cli import main

    (tmp_path / "notes.txt").write_text("mine")
    assert main(["spot", "--lens", "no_such_lens_anywhere", "-o", str(tmp_path / "notes.txt" / "x.png")]) == 2
    err = capsys.readouterr().err
    assert "is a file, not a folder" in err and "no_such_lens_anywhere" not in err


def test_an_output_in_folders_not_made_yet_passes_the_check(tmp_path):
    from physcam.io import check_writable

    assert check_writable(tmp_path / "new" / "deeper" / "x.png") == tmp_path / "new" / "deeper" / "x.png"
