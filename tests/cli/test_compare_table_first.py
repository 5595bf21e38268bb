"""``physcam compare -o`` prints its table before it draws its figure (round 22).

Cold, the table's work (the lenses' measurements) is about a third of the command and the figure the rest
(docs/performance.md, round 22: `benchmarks/compare_floor.py`); the table is now read while the figure is drawn.
Checked on the real program: as the table's last row arrives the run is stopped (SIGSTOP), and the figure file
must not exist yet (drawing it takes a few hundred ms of CPU after the table); let go, the run writes it and says so."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest


@pytest.mark.skipif(not hasattr(signal, "SIGSTOP"), reason="needs POSIX job-control signals")
def test_the_table_comes_before_the_figure(tmp_path):
    figure = tmp_path / "cmp.png"
    env = {**os.environ, "COLUMNS": "200"}
    run = subprocess.Popen([sys.executable, "-m", "physcam", "compare", "--lens", "dgauss_50mm", "--lens",
                            "tessar_50mm_f2_8", "--sensor", "S35", "-o", str(figure)], stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path)
    try:
        for line in run.stdout:
            if line.startswith("entrance pupil from film"):
                run.send_signal(signal.SIGSTOP)
                break
        else:
            pytest.fail(f"no table: {run.stderr.read()[-800:]}")
        assert not figure.exists()
        run.send_signal(signal.SIGCONT)
        rest, err = run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            run.send_signal(signal.SIGCONT)
            run.kill()
            run.wait()
    assert run.returncode == 0, err
    assert rest.splitlines()[-1] == f"wrote {figure}"
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
