"""What the xdist workers of one test session share: a folder and locks in it."""

from __future__ import annotations

import contextlib
import fcntl
import os
from pathlib import Path


def session_folder(tmp_path_factory) -> Path:
    """The temporary folder common to every worker of this session (each worker's own basetemp is a
    subfolder of it under pytest-xdist; without xdist, the session's basetemp)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@contextlib.contextmanager
def session_lock(tmp_path_factory, name: str):
    """Hold the session-wide lock ``name``: one worker at a time runs the block; yields the common folder."""
    folder = session_folder(tmp_path_factory)
    with open(folder / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        yield folder


#: The lenses of the session's extension zip (tests/conftest.py, ``extension_zip``, which ships them in the
#: library's order): every lens a Blender or zip test renders or reads, and one of each kind the builder
#: and the shader treat apart:
#: a front and a rear anamorphic, one with an asphere (the Navarro: the rectangular pupil's asphere), a
#: fisheye, zooms focusing as a unit (Canon's; Laikin's, whose stop varies with the zoom) and by an inner
#: group (Nikon's AF-S, a close distance per zoom position), the largest tables (the Angenieux f/1),
#: aspheres (the Canon RF and the Noct), the cheapest (dgauss_77deg). Building all 51 bundled lenses cost
#: the suite about 230 s of CPU (three minutes of a worker, 2026-11-29: its single largest step) for 35
#: more lenses of these kinds through the same code; the suite no longer proves each of those builds and
#: compiles: `make blender-extension` and `benchmarks/blender_extension.py --build` build the whole
#: library (before a release).
EXTENSION_LENSES = (
    "dgauss_50mm", "dgauss_77deg_3_5201mm", "cooke_triplet_50mm_f4_5", "tessar_50mm_f2_8", "zeiss_distagon_35mm_f4",
    "zuiko_18mm_f3_5", "canon_rf_85mm_f1_2", "nikkor_z_58mm_f0_95_noct", "angenieux_us2701982_100mm_f1",
    "nikkor_fisheye_16mm_f2_8", "neil_front_anamorphic_2x", "panavision_rear_anamorphic_1_3x",
    "navarro_anamorphic_2x", "canon_ef_70_200mm_f2_8_zoom", "laikin_zoom_15_150mm", "nikon_af_s_70_200mm_f2_8e_zoom",
)
