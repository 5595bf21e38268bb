"""``physcam farm``: a physcam command line as a render-farm job; ``physcam farm-task``: one of its tasks.

Examples::

  physcam farm --to openjd -o job.json --chunk 4 -- defocus shot/render.####.exr --lens dgauss_50mm \\
      --focus 2m --fstop 2.8 -o dof/dof.####.exr
  physcam farm --to opencue -o job.xml --show myshow --shot sh010 -- characterize dgauss_50mm --focus 1m,inf -o lib/
  physcam farm --to tasks -o job.txt -- calibrate charts/ --corners 9x6 --square 25mm -o calib/ --usd lens.usda

docs/farm.md: the jobs, their steps, and how to submit them to Deadline Cloud, OpenCue, Deadline 10
and Tractor.
"""

from __future__ import annotations

import argparse

from ._common import whole
from ._output import add_output_options, document, emit_json

EPILOG = """\
examples:
  physcam farm --to openjd -o job.json --chunk 4 -- defocus shot/render.####.exr --lens dgauss_50mm --focus 2m --fstop 2.8 -o dof/dof.####.exr
  physcam farm --to tasks -o job.txt --chunk 2 -- characterize dgauss_50mm --focus 1m,2m,inf --fstop 2.8,4 -o library/
  physcam farm --to opencue -o job.xml --show myshow --shot sh010 -- calibrate charts/ --corners 9x6 --square 25mm -o calib/

Everything after -- is the physcam command line the job runs (defocus of a sequence, characterize,
calibrate), checked now. Each task runs `physcam farm-task --step STEP --frames FIRST-LAST -- COMMAND` from
the working folder; a task finds what is already written and does the rest, so a retried task
resumes. docs/farm.md.
"""

#: The steps a farm task can be (docs/farm.md): defocus kernels, frames; characterize cells, usd; calibrate, usd
STEPS = ("kernels", "frames", "cells", "calibrate", "usd")


def register(sub) -> None:
    p = sub.add_parser("farm", help="write a render-farm job (Open Job Description, OpenCue, a plain task list) "
                                    "running a physcam defocus, characterize or calibrate command line in chunked, "
                                    "resumable tasks",
                       description="Turn a physcam command line into a farm job: chunked tasks that resume, "
                                   "kernels and lens caches prepared once and shared by path (docs/farm.md).",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--to", required=True, choices=("openjd", "opencue", "tasks"),
                   help="openjd: an Open Job Description template (Deadline Cloud, openjd run); opencue: an OpenCue "
                        "job specification (XML, through pyoutline); tasks: one shell command line per task "
                        "(Deadline 10, Tractor, any queue)")
    p.add_argument("-o", "--output", required=True, metavar="JOB", help="the job file to write")
    p.add_argument("--chunk", type=whole("chunk", lo=1, hi=100_000), default=1, metavar="N",
                   help="frames (defocus) or grid points (characterize) per task (default 1)")
    p.add_argument("--frames", default=None, metavar="FIRST-LAST",
                   help="defocus: the frames to run (default: those of IN.####.exr found now)")
    p.add_argument("--name", default=None, metavar="NAME", help="the job's name (default physcam-COMMAND-JOBFILE)")
    p.add_argument("--physcam", default="physcam", metavar="CMD",
                   help="how a farm machine runs physcam (default: physcam on its PATH), e.g. /opt/physcam/bin/physcam")
    p.add_argument("--workdir", default=None, metavar="DIR",
                   help="the folder the command's relative paths start from on the farm (default: this one)")
    p.add_argument("--show", default="testing", metavar="SHOW", help="opencue: the show (default testing)")
    p.add_argument("--shot", default="physcam", metavar="SHOT", help="opencue: the shot (default physcam)")
    p.add_argument("--user", default=None, metavar="USER", help="opencue: the job's user (default: you)")
    p.add_argument("--force", action="store_true", help="overwrite an existing job file")
    add_output_options(p, what="the job's summary")
    p.add_argument("physcam_command", nargs=argparse.REMAINDER, metavar="-- COMMAND ...",
                   help="the physcam command line the job runs (after --)")
    p.set_defaults(handler=run_farm)

    t = sub.add_parser("farm-task", help="run one task of a physcam farm job (the command a job's tasks call)",
                       description="Run frames FIRST-LAST of a step of the job physcam farm wrote for COMMAND; "
                                   "what is already written is skipped (docs/farm.md).")
    t.add_argument("--step", required=True, choices=STEPS, help="the step the task belongs to")
    t.add_argument("--frames", required=True, metavar="FIRST-LAST",
                   help="the task's frames (defocus) or grid points (characterize); 1 for a one-task step")
    t.add_argument("--cwd", default=None, metavar="DIR", help="the job's working folder")
    t.add_argument("--run-id", default=None, metavar="ID", help="characterize: the job's run id")
    add_output_options(t, what="what the task did")
    t.add_argument("physcam_command", nargs=argparse.REMAINDER, metavar="-- COMMAND ...",
                   help="the job's physcam command line (after --)")
    t.set_defaults(handler=run_task)


def run_farm(args) -> int:
    import os
    from pathlib import Path

    from ..io import atomic_write
    from ._farm_jobs import plan_job, write_job

    workdir = os.path.abspath(args.workdir or os.getcwd())
    if not os.path.isdir(workdir):
        from ..errors import InputError

        raise InputError(f"--workdir {args.workdir}: no such folder")
    job, inner = plan_job(args, workdir)
    text = write_job(job, args)
    path = atomic_write(args.output, text, force=args.force)
    d = {"job_file": str(path), "to": args.to, "command": inner, **job.to_dict()}
    if args.json:
        emit_json(document("farm", d, units={"frames": "frame numbers (defocus) or grid points numbered from 1 "
                                                       "(characterize)"}))
        return 0
    print(f"{job.name}: physcam {job.kind}, {job.task_count} tasks in {len(job.steps)} steps, from {workdir}")
    for s in job.steps:
        after = f" after {', '.join(s.after)}" if s.after else ""
        print(f"  {s.name}: {job.frames_are} {s.first}-{s.last}, {len(s.tasks())} task(s) of {s.chunk}{after}: {s.what}")
    print(f"wrote {Path(path)}")
    return 0


def run_task(args) -> int:
    from ._farm_tasks import run_step

    res = run_step(args)
    if args.json:
        emit_json(document("farm_task", res, units={"time": "s"}))
        return 0
    for line in res["lines"]:
        print(line)
    return 0
