"""A farm job as a plain task list: one shell command line per task, for any farm manager.

Deadline 10, Tractor, a studio's own queue or ``xargs -P``: every line that is not a comment is one
task, a POSIX shell command line with its chunk's frames written out (``--frames 1002-1005``). The
tasks come step by step in the order they must run: a step's tasks only after every task of the steps
it waits for has succeeded; the tasks of one step in any order, at once. Each step is introduced by
comment lines naming it, its frames, its chunk, what it waits for, and its command as Deadline 10's
CommandLine job takes it: the executable, and the arguments with Deadline's frame tokens
``<STARTFRAME>-<ENDFRAME>`` (an argument holding a space between ``<QUOTE>`` tokens; ``deadlinecommand
-SubmitCommandLineJob -executable ... -arguments ... -frames ... -chunksize ...``, docs/farm.md). The
first line says the format: ``# physcam farm tasks 1``.
"""

from __future__ import annotations

import shlex

from ..errors import require_type
from .frames import frames_text
from .job import FarmJob

__all__ = ["FORMAT_LINE", "DEADLINE_TOKENS", "deadline_arguments", "task_list", "read_task_list"]

FORMAT_LINE = "# physcam farm tasks 1"
#: Deadline 10's tokens for the first and last frame of a task
DEADLINE_TOKENS = "<STARTFRAME>-<ENDFRAME>"


def deadline_arguments(argv) -> str:
    """``argv`` as one Deadline Arguments string: words joined by spaces, a word with whitespace (or none
    at all) between ``<QUOTE>`` tokens, which Deadline replaces by double quotes."""
    require_type("arguments", argv, (list, tuple), "the command's words")
    out = []
    for a in argv:
        require_type("argument", a, str)
        out.append(f"<QUOTE>{a}<QUOTE>" if not a or any(c.isspace() for c in a) else a)
    return " ".join(out)


def task_list(job: FarmJob) -> str:
    """The task list of ``job`` (module notes)."""
    require_type("job", job, FarmJob, "physcam.farm.job.FarmJob")
    out = [FORMAT_LINE,
           f"# job {job.name}: physcam {job.kind}, {job.task_count} tasks in {len(job.steps)} steps; "
           f"working folder {shlex.quote(job.workdir)}",
           "# each line that is not a comment is one task; run a step's tasks after every task of the steps it "
           "waits for, a step's own tasks in any order, at once"]
    for s in job.steps:
        out += ["#",
                f"# step {s.name}: {job.frames_are} {frames_text(s.first, s.last)}, chunk {s.chunk}, "
                f"{len(s.tasks())} task{'s' if len(s.tasks()) > 1 else ''}, after: {', '.join(s.after) or 'nothing'}; {s.what}",
                "# deadline executable: " + s.argv[0],
                "# deadline arguments: " + deadline_arguments(s.command(DEADLINE_TOKENS, job.workdir)[1:])]
        out += [shlex.join(s.command(frames_text(a, b), job.workdir)) for a, b in s.tasks()]
    return "\n".join(out) + "\n"


def read_task_list(text: str) -> list[tuple[str, list[str]]]:
    """The tasks of a task list as (step name, argv) in order (the step from the comment before them)."""
    require_type("task list", text, str)
    step, tasks = None, []
    for line in text.splitlines():
        if line.startswith("# step "):
            step = line[len("# step "):].split(":", 1)[0]
        elif line.strip() and not line.startswith("#"):
            tasks.append((step, shlex.split(line)))
    return tasks
