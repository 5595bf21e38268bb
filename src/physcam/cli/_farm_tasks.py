"""``physcam farm-task --step STEP --frames FIRST-LAST -- COMMAND``: one task of a farm job (docs/farm.md).

Every task is resumable and leaves no mixed result when killed:

* defocus (``kernels``, ``frames``): each frame of the range whose output is not there is run as
  ``physcam defocus IN.NNNN.exr ... -o OUT.NNNN.exr --kernel-cache DIR`` (the job's command for that
  one frame, through the CLI itself), whose EXR is written atomically; a frame whose output exists is
  skipped, as ``physcam defocus IN.####.exr`` skips it. The kernels are read from, or traced into,
  the shared cache (one file per kernel, written atomically).
* characterize (``cells``, ``usd``): :func:`physcam.farm.grid_tasks.run_points` and
  :func:`~physcam.farm.grid_tasks.finish_lenses` (a cell in the index is skipped).
* calibrate (``calibrate``, ``usd``): the deliverables written whole as ``physcam calibrate`` writes
  them (:func:`physcam.io.staged_folder`; a folder whose manifest is complete is skipped), then the
  variant from its calibration.json, checked as ``physcam calibrate --usd`` checks it, unless the lens
  file has it.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError

#: The steps of each kind of job
KIND_STEPS = {"defocus": ("kernels", "frames"), "characterize": ("cells", "usd"), "calibrate": ("calibrate", "usd")}


def run_step(args) -> dict:
    """Run the task; returns its summary ``{"step", "kind", "frames", "done", "skipped", ..., "lines"}``."""
    from ..farm.frames import parse_frames
    from ._farm_jobs import _InDir, inner_command, parse_command

    inner = inner_command(args.physcam_command)
    if args.step not in KIND_STEPS[inner[0]]:
        raise InputError(f"a {inner[0]} job has the steps {', '.join(KIND_STEPS[inner[0]])}, not {args.step!r}")
    first, last = parse_frames(args.frames)
    folder = args.cwd or os.getcwd()
    if not os.path.isdir(folder):
        raise InputError(f"--cwd {folder}: no such folder (is the job's working folder reachable from here?)")
    with _InDir(folder):
        ns = parse_command(inner)
        run = {"defocus": _defocus, "characterize": _characterize, "calibrate": _calibrate}[inner[0]]
        res = run(args, ns, inner, first, last)
    return {"step": args.step, "kind": inner[0], "frames": [first, last], **res}


# ---------------------------------------------------------------------------------------------- defocus
def _frame_command(inner, ns, image: str, output: str) -> list[str]:
    """The job's defocus command for one frame: the sequence's input and output replaced by the frame's,
    ``--json`` added; checked by parsing it back."""
    from ._farm_jobs import parse_command

    out, i, seen = [], 0, False
    while i < len(inner):
        t = inner[i]
        if t in ("-o", "--output") and i + 1 < len(inner):
            out += [t, output]
            i += 2
            continue
        if t.startswith("--output="):
            t = "--output=" + output
        elif t.startswith("-o") and not t.startswith("--"):
            t = "-o" + output
        elif t == ns.image and not seen:
            t, seen = image, True
        out.append(t)
        i += 1
    if "--json" not in out:
        out.append("--json")
    again = parse_command(out)
    if (again.image, again.output) != (image, output):
        raise InputError(f"cannot tell the image and output of the command {' '.join(inner)[:120]} apart")
    return out


def _defocus(args, ns, inner, first, last) -> dict:
    import contextlib
    import io
    import json
    import sys

    from ..characterize.defocus_shot import frame_path
    from . import main

    done, skipped, lines, traced = [], [], [], []
    for n in range(first, last + 1):
        image, target = str(frame_path(ns.image, n)), str(frame_path(ns.output, n))
        if Path(target).exists():
            skipped.append(n)
            lines.append(f"frame {n}: {target} is there, skipped")
            continue
        argv = _frame_command(inner, ns, image, target)
        buf, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(err):
            rc = main(argv)
        said = [ln for ln in err.getvalue().splitlines() if ln.strip()]
        if rc != 0:
            why = next((ln for ln in reversed(said) if ln.startswith("physcam: error: ")), f"exit {rc}")
            raise InputError(f"frame {n}: {why.removeprefix('physcam: error: ')}")
        for ln in said:  # its notes and warnings, for the farm's log
            print(ln, file=sys.stderr)
        doc = json.loads(buf.getvalue())
        done.append(n)
        traced.append(int(doc["kernels_traced"]))
        lines.append(f"frame {n}: wrote {target} ({doc['kernels_traced']} kernels traced, {doc['seconds']:.1f} s)")
    return {"done": done, "skipped": skipped, "kernels_traced": traced, "lines": lines}


# ----------------------------------------------------------------------------------------- characterize
def _characterize(args, ns, inner, first, last) -> dict:
    from ..farm.grid_tasks import finish_lenses, run_points
    from ._farm_jobs import command_lenses
    from .characterize import _grid

    if not args.run_id:
        raise InputError("a characterize farm task needs the job's --run-id (physcam farm puts it in every task)")
    grid = _grid(ns)
    lenses = command_lenses(ns)
    if args.step == "usd":
        got = finish_lenses(lenses, grid, ns.output, args.run_id)
        return {"done": [1], "skipped": [], "usd": got,
                "lines": [f"{u['file']}: variant {u['variant']}" for u in got] or ["the USD files have this grid"]}
    res = run_points(lenses, grid, ns.output, args.run_id, first, last)
    if res["failed"]:
        f = res["failed"][0]
        raise InputError(f"{len(res['failed'])} cells failed (first: {f['lens']} {f['kind']} {f['cell']}: "
                         f"{f['error']})")
    return {"done": list(range(first, last + 1)), "skipped": [], "cells_computed": res["computed"],
            "cells_present": res["present"],
            "lines": [f"grid points {first}-{last}: {res['computed']} cells made, {res['present']} there already"]}


# -------------------------------------------------------------------------------------------- calibrate
def _calibrate(args, ns, inner, first, last) -> dict:
    from ..io import folder_manifest

    if args.step == "usd":
        return _calibrate_usd(ns)
    out = Path(ns.output)
    if folder_manifest(out) is not None:
        return {"done": [], "skipped": [1], "lines": [f"{out}: written whole already, skipped"]}
    from ._calibrate_files import check_outputs, deliverables, write_all
    from .calibrate import compute

    ns.usd = ns.variant = None  # the variant is the usd step's
    plan = check_outputs(ns)
    cal, _ = compute(ns)
    payload, _ = deliverables(cal, ns, plan)
    written = write_all(payload, None, cal, ns, plan)  # the folder whole, as physcam calibrate writes it
    return {"done": [1], "skipped": [], "lines": [f"wrote {p}" for p in written]}


def _calibrate_usd(ns) -> dict:
    import json

    from ..usd.kit import characterization_target, read_characterizations
    from ._calibrate_files import _check_usd, add_calibration_variant

    usd = Path(ns.usd)
    if usd.exists() and ns.variant in read_characterizations(usd)["variants"]:
        return {"done": [], "skipped": [1], "lines": [f"{usd}: has the variant {ns.variant}, skipped"]}
    calib = Path(ns.output) / "calibration.json"
    if not calib.is_file():
        raise InputError(f"{calib}: not there; the calibrate step has not run")
    doc = json.loads(calib.read_text(encoding="utf-8"))
    target = dict(characterization_target(usd, ns.variant), file=usd, variant=ns.variant)
    _check_usd(doc, target)  # a NOT good calibration, or another lens's, never goes into the lens file
    lens = None
    if ns.lens is not None:
        from ..lens.library import load_lens

        lens = load_lens(ns.lens)
    add_calibration_variant(doc, target, lens=lens, fstop=ns.fstop, output=ns.output)
    return {"done": [1], "skipped": [], "lines": [f"{usd}: variant {ns.variant}"]}
