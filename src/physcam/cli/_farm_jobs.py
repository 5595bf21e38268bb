"""The jobs of ``physcam farm`` (docs/farm.md): a physcam command line, checked, as the steps of a farm job.

* ``defocus IN.####.exr ... -o OUT.####.exr``: step ``kernels`` defocuses the first frame alone, which
  traces the kernels into the shared kernel cache (``--kernel-cache``, added to the command when it is
  not given: ``kernels`` beside the outputs, as the Dask run shares them); step ``frames`` defocuses
  the others in chunks, loading those kernels. Frames: ``--frames`` or those found now.
* ``characterize LENS... -o LIBRARY``: step ``cells`` makes the grid's points (lens x focus x f-stop,
  numbered from 1; :mod:`physcam.farm.grid_tasks`) in chunks; step ``usd`` adds each lens's
  characterization variant, under the run id the job fixes now.
* ``calibrate IMAGES... -o DIR``: step ``calibrate`` writes the deliverables (ST-maps, fitted models,
  sheet, calibration.json) as a folder written whole; step ``usd`` (with ``--usd``) adds the day's
  variant from calibration.json (``--variant``, fixed now when not given).

A command is checked before the job is written, as the command itself would check it, and the options
that make no sense on a farm are refused: ``--force`` (a task skips what is written, so a retried task
resumes), ``--scheduler``/``--workers`` (Dask's), ``--dry-run``/``--limit``.
"""

from __future__ import annotations

import os
import shlex
from pathlib import Path

from ..errors import InputError

#: Options a farm job refuses in its command, and why
REFUSED = {
    "force": "--force: a farm task skips the outputs already written, so a retried task resumes; remove old outputs "
             "or write elsewhere",
    "scheduler": "--scheduler sizes a Dask run; a farm job's tasks run on the farm's machines",
    "workers": "--workers sizes a Dask run; a farm job's tasks run on the farm's machines",
    "dry_run": "--dry-run: physcam farm checks the command when it writes the job",
    "limit": "--limit: a farm job makes the whole grid (its tasks skip what is done)",
}


def inner_command(tokens) -> list[str]:
    """The physcam command line after ``--`` (the ``--`` itself dropped)."""
    inner = list(tokens or [])
    if inner[:1] == ["--"]:
        inner = inner[1:]
    if not inner:
        raise InputError("give the physcam command line the job runs after --, e.g. physcam farm --to openjd -o "
                         "job.json -- defocus IN.####.exr --lens L --focus 2m --fstop 2.8 -o OUT.####.exr")
    from ..farm.job import KINDS

    if inner[0] not in KINDS:
        raise InputError(f"a farm job runs physcam {', '.join(KINDS)}; got {inner[0]!r}")
    return inner


def parse_command(inner: list[str]):
    """physcam's own parse of ``inner``: the namespace, or an :class:`InputError` with argparse's complaint."""
    import contextlib
    import io

    from . import build_parser
    from ._common import merge_lens_argument

    parser = build_parser(inner)
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err):
            ns = parser.parse_args(inner)
            merge_lens_argument(ns, parser)
    except SystemExit:
        why = err.getvalue().strip().splitlines()
        raise InputError(f"the command after --: {why[-1].removeprefix('physcam: error: ') if why else 'not valid'}") \
            from None
    return ns


def _refuse(ns, keys) -> None:
    for k in keys:
        if getattr(ns, k, None) not in (None, False):
            raise InputError(REFUSED[k])


class _InDir:
    """Work in ``folder`` for the block (the command's relative paths start there)."""

    def __init__(self, folder):
        self.folder = folder

    def __enter__(self):
        self.old = os.getcwd()
        os.chdir(self.folder)

    def __exit__(self, *exc):
        os.chdir(self.old)
        return False


def plan_job(args, workdir: str):
    """(the :class:`~physcam.farm.job.FarmJob`, the command line its tasks run) of ``physcam farm`` ``args``."""
    from ..farm.job import job_name

    inner = inner_command(args.physcam_command)
    ns = parse_command(inner)
    if args.frames is not None and inner[0] != "defocus":
        raise InputError("--frames picks the frames of a defocus job; a characterize job's tasks are its grid "
                         "points, a calibrate job has one task")
    physcam = shlex.split(args.physcam)
    if not physcam:
        raise InputError("--physcam: give the command that runs physcam on a farm machine, e.g. physcam")
    name = job_name(args.name or f"physcam-{inner[0]}-{Path(args.output).stem}"[:64].rstrip("._-"))
    plan = {"defocus": _defocus, "characterize": _characterize, "calibrate": _calibrate}[inner[0]]
    with _InDir(workdir):
        return plan(args, ns, inner, physcam, name, workdir)


def _defocus(args, ns, inner, physcam, name, workdir):
    from ..extras import require_extra

    # its tasks run `physcam defocus IN.####.exr`, which needs dask (as the command says); named here
    # before physcam.characterize's own check, which would name `physcam characterize`
    require_extra("dask", "a defocus sequence as a farm job (physcam farm -- defocus IN.####.exr)")
    from ..characterize.defocus_shot import frame_path, sequence_frames, shot_kernel_folder
    from ..farm.frames import parse_frames
    from ..farm.job import FarmJob, Step, task_argv

    _refuse(ns, ("force", "scheduler", "workers"))
    if "#" not in ns.image:
        raise InputError("a defocus farm job runs a sequence IN.####.exr -o OUT.####.exr (one frame needs no farm)")
    frame_path(ns.output, 0)  # the output is a sequence too
    if args.frames is not None:
        first, last = parse_frames(args.frames)
    else:
        found = [n for n, _ in sequence_frames(ns.image)]
        first, last = found[0], found[-1]
        if found != list(range(first, last + 1)):
            raise InputError(f"{ns.image}: frames {first}-{last} with gaps; give --frames FIRST-LAST to run a range")
    if ns.kernel_cache is None:
        inner = [*inner, "--kernel-cache", str(shot_kernel_folder(ns.output))]
    steps = [Step("kernels", first, first, 1, task_argv(physcam, "kernels", inner),
                  what=f"defocus frame {first} alone: it traces the kernels into the shared cache")]
    if last > first:
        steps.append(Step("frames", first + 1, last, args.chunk, task_argv(physcam, "frames", inner),
                          after=("kernels",), what="defocus the other frames, loading the shared kernels"))
    return FarmJob(name, "defocus", workdir, tuple(steps)), inner


def command_lenses(ns) -> dict:
    """{slug: Prescription} of a characterize command's lenses (as ``physcam characterize`` loads them,
    a zoom lens once per ``--zoom`` position)."""
    from .characterize import characterize_lenses

    return characterize_lenses(ns)


def _characterize(args, ns, inner, physcam, name, workdir):
    from ..characterize import characterize
    from ..characterize.run import new_run_id
    from ..farm.grid_tasks import grid_points
    from ..farm.job import FarmJob, Step, task_argv
    from .characterize import _grid

    _refuse(ns, ("scheduler", "workers", "dry_run", "limit"))
    grid = _grid(ns)
    lenses = command_lenses(ns)
    characterize(lenses, grid, ns.output, dry_run=True, force_large=ns.force_large)  # every check of a real run
    points = len(grid_points(lenses, grid))
    run = ["--run-id", new_run_id()]
    steps = [Step("cells", 1, points, args.chunk, task_argv(physcam, "cells", inner, run),
                  what="make the cells of grid points (lens x focus x f-stop) into the library")]
    if not ns.no_usd:
        steps.append(Step("usd", 1, 1, 1, task_argv(physcam, "usd", inner, run), after=("cells",),
                          what="add each lens's characterization variant to its USD file"))
    return FarmJob(name, "characterize", workdir, tuple(steps), frames_are="grid points"), inner


def _calibrate(args, ns, inner, physcam, name, workdir):
    import datetime as _dt

    from ..farm.job import FarmJob, Step, task_argv
    from ._calibrate_files import check_outputs

    _refuse(ns, ("force",))
    if ns.usd is not None and ns.variant is None:
        inner = [*inner, "--variant", "calibration_" + _dt.datetime.now(_dt.UTC).strftime("%Y%m%d")]
        ns.variant = inner[-1]
    check_outputs(ns)  # the options, the images' headers, the output folder and the lens file, as calibrate does
    steps = [Step("calibrate", 1, 1, 1, task_argv(physcam, "calibrate", inner),
                  what="calibrate from the charts; write the ST-maps, fitted models, sheet and calibration.json "
                       "as one folder")]
    if ns.usd is not None:
        steps.append(Step("usd", 1, 1, 1, task_argv(physcam, "usd", inner), after=("calibrate",),
                          what=f"add the variant {ns.variant} to {ns.usd}"))
    return FarmJob(name, "calibrate", workdir, tuple(steps)), inner


def write_job(job, args) -> str:
    """The job file's text in the format of ``--to``."""
    if args.to == "openjd":
        import json

        from ..farm.openjd import openjd_template, validate_openjd_template

        template = openjd_template(job, os.path.dirname(os.path.abspath(args.output)))
        validate_openjd_template(template)
        return json.dumps(template, indent=1) + "\n"
    if args.to == "opencue":
        import getpass

        from ..farm.opencue import opencue_spec

        return opencue_spec(job, show=args.show, shot=args.shot, user=args.user or getpass.getuser())
    from ..farm.tasklist import task_list

    return task_list(job)
