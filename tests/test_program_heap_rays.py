"""The spot diagram and the lens comparison give the program's heap room, as the pupil engine does (issue 47,
round 21; docs/performance.md): their ray arrays (1e5 rays a level, a bokeh, an illumination grid) come and go,
and with glibc's default 128 KiB of top pad each one was paged in anew (a cold `physcam spot -o png` 27,700
minor page faults, `compare` 46,500; with the pad 15,500 and 16,700). Only in the program: a library caller's
allocator is left alone. Nothing they compute changes (their --json and PNG bytes are main's: the round's notes).
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from physcam import _program
from physcam.analysis.image_quality.spot import spot_diagram
from physcam.lens.library import load_lens
from physcam.onset.lens_compare import lens_measurements
from physcam.optics.sensors import find_sensor
from physcam.optics.state import as_designed


def test_the_library_leaves_the_callers_allocator_alone():
    lens = load_lens("dgauss_50mm")
    spot_diagram(as_designed(lens), (0.0,), rings=4, refine=1)
    lens_measurements(lens, focus_mm=2000.0, fstop=2.8, sensor=find_sensor("S35"), rays=1000)
    assert not _program.RUNNING and _program.roomy_heap() is False


@pytest.mark.parametrize("call", [
    "from physcam.analysis.image_quality.spot import spot_diagram\n"
    "from physcam.optics.state import as_designed\n"
    "spot_diagram(as_designed(load_lens('dgauss_50mm')), (0.0,), rings=4, refine=1)\n",
    "from physcam.onset.lens_compare import lens_measurements\n"
    "from physcam.optics.sensors import find_sensor\n"
    "lens_measurements(load_lens('dgauss_50mm'), focus_mm=2000.0, fstop=2.8, sensor=find_sensor('S35'), rays=1000)\n",
], ids=["spot", "compare"])
def test_the_program_gives_the_rays_heap_room(call):
    if not sys.platform.startswith("linux") or not os.confstr("CS_GNU_LIBC_VERSION").startswith("glibc"):
        pytest.skip("M_TOP_PAD is glibc's")
    code = ("from physcam import _program\n_program.start()\nfrom physcam.lens.library import load_lens\n"
            "assert not _program._roomy\n" + call + "print(_program._roomy)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert out.stdout.strip() == "True"
