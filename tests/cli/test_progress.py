"""Progress for people at a terminal (issue 47): a command still running after 2 s shows a spinner
with its elapsed time on standard error, only when that is a terminal and the output is not --json
or --csv; standard output stays exactly what it is without it. The delay is
``PHYSCAM_PROGRESS_AFTER`` (0 here, so a quick command shows it)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a pseudo-terminal (pty)")


def _physcam(args, *, tty: bool, after: str = "0"):
    """(status, stdout, stderr) of ``physcam ARGS`` with stdout a pipe and stderr a terminal (a pty) or a pipe."""
    env = dict(os.environ, PHYSCAM_PROGRESS_AFTER=after, COLUMNS="100")
    env.pop("PHYSCAM_BACKEND", None)
    cmd = [sys.executable, "-m", "physcam", *args]
    if not tty:
        p = subprocess.run(cmd, capture_output=True, env=env, timeout=300)
        return p.returncode, p.stdout, p.stderr
    import pty

    master, slave = pty.openpty()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=slave, env=env)
    os.close(slave)
    err = b""
    while True:
        try:
            chunk = os.read(master, 4096)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        err += chunk
    out = p.stdout.read()
    os.close(master)
    return p.wait(timeout=300), out, err


def test_a_spinner_on_a_terminal_and_the_output_untouched():
    rc, out, err = _physcam(["spot", "--lens", "dgauss_50mm"], tty=True)
    assert rc == 0 and b"physcam spot" in err and b"0:00:0" in err  # its name and the elapsed time
    rc2, out2, err2 = _physcam(["spot", "--lens", "dgauss_50mm"], tty=False)
    assert rc2 == 0 and out == out2 and b"physcam spot" not in err2  # piped: nothing
    assert b"RMS" in out


def test_nothing_with_json_or_before_the_delay():
    rc, out, err = _physcam(["spot", "--lens", "dgauss_50mm", "--json"], tty=True)
    assert rc == 0 and out.startswith(b"{") and b"physcam spot" not in err
    rc, out, err = _physcam(["spot", "--lens", "dgauss_50mm"], tty=True, after="60")
    assert rc == 0 and b"physcam spot" not in err
