"""A farm job: named steps of chunked tasks, each task one ``physcam farm-task`` command line.

The job says, for any farm manager, what runs and in which order; the writers turn it into an Open
Job Description template (:mod:`.openjd`), an OpenCue outline (:mod:`.opencue`) or a plain task list
(:mod:`.tasklist`). A :class:`Step` covers a frame range ``first..last`` cut into chunks of ``chunk``
frames (a chunk is one task; "frames" are the shot's frames for ``defocus`` and the numbered grid
points for ``characterize``), and waits for every task of the steps in ``after``. Its command line
holds two placeholders the writers fill in their manager's own way: :data:`FRAMES` (the chunk's
``FIRST-LAST``: ``{{Task.Param.Frame}}`` in OpenJD, ``#FRAME_START#-#FRAME_END#`` in OpenCue,
``<STARTFRAME>-<ENDFRAME>`` in Deadline 10) and :data:`WORKDIR` (the folder the command's relative
paths start from: a PATH job parameter in OpenJD, so a studio's path mapping applies).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import InputError
from .frames import MAX_FRAME, chunks, frames_text

__all__ = ["FRAMES", "WORKDIR", "KINDS", "Step", "FarmJob", "task_argv", "job_name"]

#: Placeholder of a task's frame range in a step's command line
FRAMES = "<physcam:frames>"
#: Placeholder of the job's working folder in a step's command line
WORKDIR = "<physcam:workdir>"
#: The physcam commands a farm job runs
KINDS = ("defocus", "characterize", "calibrate")

_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$")


@dataclass(frozen=True)
class Step:
    """One step: tasks over frames ``first..last`` in chunks of ``chunk``, after the steps ``after``."""

    name: str
    first: int
    last: int
    chunk: int
    argv: tuple[str, ...]  # the task command line, with FRAMES and WORKDIR where they go
    after: tuple[str, ...] = ()
    what: str = ""  # one line: what a task of this step does

    def tasks(self) -> list[tuple[int, int]]:
        """Each task's (first, last) frame, in order: every frame of the step exactly once."""
        return chunks(self.first, self.last, self.chunk)

    def command(self, frames: str, workdir: str) -> list[str]:
        """The command line with the placeholders replaced (a whole argument or a part of one)."""
        return [a.replace(FRAMES, frames).replace(WORKDIR, workdir) for a in self.argv]

    def to_dict(self) -> dict:
        return {"name": self.name, "frames": frames_text(self.first, self.last), "chunk": self.chunk,
                "tasks": len(self.tasks()), "after": list(self.after), "what": self.what}


@dataclass(frozen=True)
class FarmJob:
    """A job of ``kind`` (one of :data:`KINDS`) run from the folder ``workdir`` (absolute)."""

    name: str
    kind: str
    workdir: str
    steps: tuple[Step, ...]
    frames_are: str = "frames"  # what a step's frame numbers count: "frames" or "grid points"

    def __post_init__(self):
        if self.kind not in KINDS:
            raise InputError(f"a farm job runs one of {', '.join(KINDS)}, got {self.kind!r}")
        names = [s.name for s in self.steps]
        if not names or len(set(names)) != len(names):
            raise InputError(f"a farm job has steps with distinct names, got {names}")
        for i, s in enumerate(self.steps):
            if not 0 <= s.first <= s.last <= MAX_FRAME:
                raise InputError(f"step {s.name}: frames {s.first}-{s.last} out of 0-{MAX_FRAME}")
            if any(a not in names[:i] for a in s.after):
                raise InputError(f"step {s.name} waits for a step that does not come before it: {list(s.after)}")

    @property
    def task_count(self) -> int:
        return sum(len(s.tasks()) for s in self.steps)

    def to_dict(self) -> dict:
        return {"name": self.name, "kind": self.kind, "workdir": self.workdir, "frames_are": self.frames_are,
                "tasks": self.task_count, "steps": [s.to_dict() for s in self.steps]}


def job_name(text: str) -> str:
    """``text`` as a job name every manager takes: letters, digits, ``.``, ``_``, ``-``, at most 64."""
    if not isinstance(text, str) or not _NAME.match(text):
        raise InputError(f"a job name is 1 to 64 letters, digits, '.', '_' or '-' (starting with a letter or digit), "
                         f"got {text!r}")
    return text


def task_argv(physcam: list[str], step: str, command: list[str], extra: list[str] | tuple = ()) -> tuple[str, ...]:
    """``physcam farm-task --step STEP --frames FRAMES --cwd WORKDIR [extra] -- COMMAND...``."""
    return (*physcam, "farm-task", "--step", step, "--frames", FRAMES, "--cwd", WORKDIR, *extra, "--", *command)
