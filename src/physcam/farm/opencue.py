"""A farm job as an OpenCue job specification, made by OpenCue's own ``pyoutline`` without a Cuebot.

Each :class:`~physcam.farm.job.Step` becomes a ``Shell`` layer of the outline whose range is the
step's frames and whose chunk is the job's (OpenCue runs one frame of a layer per chunk of
``chunk`` frames and substitutes ``#FRAME_START#`` and ``#FRAME_END#``, the chunk's first and last
frame, in its command); a step that waits for others depends on them layer-on-layer. The outline
is serialised by ``outline.cuerun.OutlineLauncher.serialize(use_pycuerun=False)`` (the commands run
as written, not through pycuerun): the XML ``cjsl`` specification a Cuebot takes, e.g. with
``pycue``'s ``opencue.api.launchSpec`` (docs/farm.md). The command is one shell line, each
argument quoted for a POSIX shell. The session folder pyoutline sets up for a launch through
pycuerun is made in a temporary folder and removed: nothing is written in the user's home. Reference: OpenCue documentation, "Outline" and "Cue job
specification" (opencue.io/docs).
"""

from __future__ import annotations

import shlex
import tempfile

from ..errors import ExportError, InputError, require_type
from .job import FarmJob

__all__ = ["opencue_spec", "FRAME_TOKENS"]

#: OpenCue's tokens for the first and last frame of the chunk a frame runs
FRAME_TOKENS = "#FRAME_START#-#FRAME_END#"


def _word(text, what: str) -> str:
    require_type(what, text, str)
    if not text or any(c.isspace() for c in text) or not text.isprintable() or len(text) > 64:
        raise InputError(f"the OpenCue {what} is one word of at most 64 printable characters, got {text!r}")
    return text


def opencue_spec(job: FarmJob, *, show: str, shot: str, user: str) -> str:
    """The OpenCue job specification (XML text) of ``job`` for ``show`` / ``shot``, submitted as ``user``."""
    from ..extras import require_extra

    require_type("job", job, FarmJob, "physcam.farm.job.FarmJob")
    show, shot, user = _word(show, "show"), _word(shot, "shot"), _word(user, "user")
    require_extra("opencue", "OpenCue outlines (physcam farm --to opencue)")
    import outline
    import outline.cuerun
    from outline.modules.shell import Shell

    ol = outline.Outline(job.name, shot=shot, show=show, user=user)
    layers = {}
    for s in job.steps:
        layer = Shell(s.name, command=shlex.join(s.command(FRAME_TOKENS, job.workdir)),
                      range=f"{s.first}-{s.last}", chunk=s.chunk)
        ol.add_layer(layer)
        for a in s.after:
            layer.depend_all(layers[a])
        layers[s.name] = layer
    # pyoutline sets an outline up (a session folder with a copy of it, under ~/.opencue/sessions) before
    # it serialises: that folder is for launching through pycuerun, so it goes to a temporary folder here
    home_sessions = outline.config.get("outline", "session_dir", raw=True)
    with tempfile.TemporaryDirectory(prefix="physcam-outline-") as sessions:
        outline.config.set("outline", "session_dir", sessions.replace("%", "%%"))
        try:
            return outline.cuerun.OutlineLauncher(ol, user=user).serialize(use_pycuerun=False)
        except Exception as exc:  # noqa: BLE001 - pyoutline's own errors (OutlineException, config) in one line
            raise ExportError(f"pyoutline could not serialise the job: {type(exc).__name__}: "
                              f"{str(exc).splitlines()[0] if str(exc) else ''}") from None
        finally:
            outline.config.set("outline", "session_dir", home_sessions)
