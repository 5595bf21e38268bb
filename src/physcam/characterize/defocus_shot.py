"""A shot (an image sequence ``IN.####.exr``) through ``physcam defocus``, frame-parallel on Dask.

The same cluster as :func:`physcam.characterize.characterize`: a ``LocalCluster`` of
single-threaded worker processes by default, or a farm's scheduler (``tcp://HOST:PORT``). One
task per frame (:func:`physcam.analysis.defocus.exr.defocus_file`); the kernels live in one
folder on disk (:class:`~physcam.analysis.defocus.kernels.KernelCache`, one ``.npz`` per kernel,
written atomically) that every worker reads: the first frame runs alone to trace them, the others
then load them. Resumable per frame: a frame whose output exists is skipped unless ``force``. An
output frame that is an input frame (or the depth file) is refused before any frame is done.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError

__all__ = ["ShotSummary", "sequence_frames", "frame_path", "shot_kernel_folder", "defocus_sequence"]

_HASHES = re.compile(r"#+")


@dataclass
class ShotSummary:
    """What a shot run did: frame numbers done, skipped (output there) and the outputs."""

    done: list[int] = field(default_factory=list)
    skipped: list[int] = field(default_factory=list)
    outputs: list[str] = field(default_factory=list)
    kernel_folder: str = ""
    dashboard: str | None = None


def _pattern(text: str, what: str) -> tuple[str, int]:
    runs = _HASHES.findall(Path(text).name)
    if len(runs) != 1:
        raise InputError(f"the {what} {text!r} needs one run of # for the frame number, e.g. IN.####.exr")
    return text, len(runs[0])


def sequence_frames(pattern: str) -> list[tuple[int, Path]]:
    """The frames of ``pattern`` (one run of ``#`` in the file name, each # a digit), sorted by number."""
    pattern, n = _pattern(pattern, "image sequence")
    p = Path(pattern)
    head, tail = _HASHES.split(p.name)
    rx = re.compile(re.escape(head) + r"(\d{%d})" % n + re.escape(tail) + "$")
    frames = sorted((int(m.group(1)), f) for f in p.parent.glob(head + "?" * n + tail) if (m := rx.match(f.name)))
    if not frames:
        raise InputError(f"no frames match {pattern} (each # stands for one digit)")
    return frames


def frame_path(pattern: str, number: int) -> Path:
    """Frame ``number`` of ``pattern`` (one run of ``#``, each a digit: ``out.####.exr``, 7 -> ``out.0007.exr``)."""
    from ..errors import require_type

    require_type("pattern", pattern, str, "name.####.exr")
    if isinstance(number, bool) or not isinstance(number, int) or number < 0:
        raise InputError(f"a frame number is a whole number >= 0, got {number!r}")
    _, n = _pattern(pattern, "output sequence")
    return Path(_HASHES.sub(f"{number:0{n}d}", pattern))


def shot_kernel_folder(output_pattern: str) -> Path:
    """Where a shot's kernels are shared when no folder is given: ``kernels`` beside its outputs."""
    return frame_path(output_pattern, 0).parent / "kernels"


def _one_frame(image, output, lens, kernel_folder, force, options):
    from ..analysis.defocus.exr import defocus_file

    return defocus_file(image, output, lens, kernel_folder=kernel_folder, force=force, **options)


def defocus_sequence(pattern: str, output_pattern: str, lens, *, kernel_folder=None, scheduler: str | None = None,
                     workers: int | None = None, force: bool = False, **options) -> ShotSummary:
    """Defocus every frame of ``pattern`` into ``output_pattern`` (both ``name.####.exr``), one
    Dask task per frame (module notes). ``kernel_folder``: the shared kernel cache (default: a
    ``kernels`` folder beside the outputs); ``options``: those of ``defocus_file`` (focus_mm,
    fstop, sensor_width_mm, depth, ...)."""
    from .run import _connect, check_scheduler_address

    from ..io import refuse_inputs_as_outputs

    frames = sequence_frames(pattern)
    _pattern(output_pattern, "output sequence")
    depth = options.get("depth")
    inputs = [p for _, p in frames] + ([depth] if depth is not None and Path(str(depth)).is_file() else [])
    for number, _ in frames:  # before any frame is written: an output that is an input is refused
        refuse_inputs_as_outputs(inputs, [frame_path(output_pattern, number)])
    if scheduler is not None:
        check_scheduler_address(scheduler)
    folder = Path(kernel_folder) if kernel_folder is not None else shot_kernel_folder(output_pattern)
    out = ShotSummary(kernel_folder=str(folder))
    todo = []
    for number, path in frames:
        target = frame_path(output_pattern, number)
        out.outputs.append(str(target))
        (out.skipped if target.exists() and not force else todo).append(number)
        if todo and todo[-1] == number:
            todo[-1] = (number, path, target)
    if not todo:
        return out
    todo[0][2].parent.mkdir(parents=True, exist_ok=True)
    first, rest = todo[0], todo[1:]
    _one_frame(str(first[1]), str(first[2]), lens, str(folder), force, options)  # traces the kernels once
    out.done.append(first[0])
    if rest:
        client, cluster, out.dashboard, _ = _connect(scheduler, workers or os.cpu_count() or 1, 10.0)
        try:
            futures = [client.submit(_one_frame, str(p), str(t), lens, str(folder), force, options, pure=False,
                                     retries=1) for _, p, t in rest]
            client.gather(futures)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
        out.done.extend(n for n, _, _ in rest)
    return out
