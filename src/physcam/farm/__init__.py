"""physcam's heavy work on a render farm (docs/farm.md).

A physcam command line (``defocus`` of a sequence, ``characterize``, ``calibrate``) becomes a
:class:`~.job.FarmJob`: named steps of chunked tasks, each task a ``physcam farm-task`` command line
(:mod:`.job`, frame ranges in :mod:`.frames`). The job is written for the farm manager a studio runs:
an Open Job Description template validated by ``openjd-model`` (:mod:`.openjd`: AWS Deadline Cloud,
``openjd run``), an OpenCue job specification made by OpenCue's ``pyoutline`` (:mod:`.opencue`), or
a plain list of shell command lines (:mod:`.tasklist`: Deadline 10, Tractor, any queue). A
characterize task makes its grid points with the very function Dask runs (:mod:`.grid_tasks`).
Layer: above ``characterize`` (whose task functions it runs), below ``cli`` (which plans the jobs
from its own parse of the command line and runs the tasks).
"""

from .frames import chunks, frames_text, parse_frames
from .job import FRAMES, KINDS, WORKDIR, FarmJob, Step, job_name, task_argv

__all__ = ["FarmJob", "Step", "KINDS", "FRAMES", "WORKDIR", "job_name", "task_argv", "parse_frames",
           "frames_text", "chunks"]
