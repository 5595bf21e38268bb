"""A farm job as an Open Job Description template (specification 2023-09), validated by ``openjd-model``.

Open Job Description (OpenJD) is the job format of AWS Deadline Cloud and of any scheduler that takes
it; ``openjd run`` (openjd-cli) runs a template on one machine. Each :class:`~physcam.farm.job.Step`
becomes a step whose one task parameter ``Frame`` is a ``CHUNK[INT]`` over the step's frames with
``defaultTaskCount`` = the job's chunk (the ``TASK_CHUNKING`` extension: the scheduler hands a task a
contiguous run of frames, rendered ``FIRST-LAST``, and may balance the runs' lengths), so a task runs
``physcam farm-task --step STEP --frames {{Task.Param.Frame}} ...``. A step waits for its ``after`` steps
(``dependencies``). The working folder is the job parameter ``WorkDir`` (type PATH, so a studio's
path mapping rules apply); its default is relative to the template's folder as the specification
asks, and only when it lies inside it (else it is given at submission: ``-p WorkDir=DIR``).
The task's command is its argument list, never a shell line: no quoting is involved.

Reference: Open Job Description, Template Schemas 2023-09 (github.com/OpenJobDescription/
openjd-specifications, wiki "2023-09 Template Schemas"; RFC 0001 "Task chunking").
"""

from __future__ import annotations

import os

from ..errors import ExportError
from .job import FRAMES, WORKDIR, FarmJob

__all__ = ["SPECIFICATION", "EXTENSIONS", "openjd_template", "validate_openjd_template"]

SPECIFICATION = "jobtemplate-2023-09"
EXTENSIONS = ("TASK_CHUNKING",)


def _arg(text: str) -> str:
    """A command-line argument as OpenJD format-string text: the placeholders become its expressions;
    text with ``{{`` of its own is refused (2023-09 has no way to write it literally)."""
    if "{{" in text.replace(FRAMES, "").replace(WORKDIR, "") or "}}" in text:
        raise ExportError(f"an argument holds '{{{{' or '}}}}', which Open Job Description reads as an expression: "
                          f"{text[:80]!r}; rename the file or folder")
    return text.replace(FRAMES, "{{Task.Param.Frame}}").replace(WORKDIR, "{{Param.WorkDir}}")


def openjd_template(job: FarmJob, template_folder) -> dict:
    """The template of ``job`` as a dict (module notes); ``template_folder``: where it will be saved (the
    default of ``WorkDir`` is relative to it)."""
    from ..errors import require_type

    require_type("job", job, FarmJob, "physcam.farm.job.FarmJob")
    rel = os.path.relpath(job.workdir, os.path.abspath(template_folder))
    workdir = {"name": "WorkDir", "type": "PATH", "objectType": "DIRECTORY",
               "description": f"the folder the physcam command's relative paths start from (submitted from "
                              f"{job.workdir})"}
    if rel != os.pardir and not rel.startswith(os.pardir + os.sep) and not os.path.isabs(rel):
        workdir["default"] = rel  # the specification allows a default only inside the template's folder
    steps = []
    for s in job.steps:
        step = {"name": s.name, "description": s.what or s.name,
                "parameterSpace": {"taskParameterDefinitions": [{
                    "name": "Frame", "type": "CHUNK[INT]", "range": f"{s.first}-{s.last}",
                    "chunks": {"defaultTaskCount": s.chunk, "rangeConstraint": "CONTIGUOUS"}}]},
                "script": {"actions": {"onRun": {"command": _arg(s.argv[0]),
                                                 "args": [_arg(a) for a in s.argv[1:]]}}}}
        if s.after:
            step["dependencies"] = [{"dependsOn": a} for a in s.after]
        steps.append(step)
    return {"specificationVersion": SPECIFICATION, "extensions": list(EXTENSIONS), "name": job.name,
            "description": f"physcam {job.kind}: {job.task_count} tasks in {len(job.steps)} steps "
                           f"(physcam farm; docs/farm.md)",
            "parameterDefinitions": [workdir],
            "steps": steps}


def validate_openjd_template(template: dict):
    """Decode ``template`` with ``openjd-model`` (every check of the specification); returns the decoded
    ``JobTemplate``, or raises :class:`ExportError` with openjd-model's first complaint."""
    from ..extras import require_extra

    require_extra("farm", "Open Job Description templates (physcam farm --to openjd)")
    from openjd.model import DecodeValidationError, decode_job_template

    try:
        return decode_job_template(template=template, supported_extensions=list(EXTENSIONS))
    except DecodeValidationError as exc:
        first = str(exc).strip().splitlines()
        raise ExportError("openjd-model refuses the job template: " + " ".join(first[:3])[:400]) from None
