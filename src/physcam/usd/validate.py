"""Check a stage with usd-core's own validators (UsdValidation) and physcam's rules.

:func:`validation_errors` runs every validator usd-core registers for a stage
(``UsdValidation.ValidationRegistry().GetOrLoadAllValidators()``: composition
errors, stage metadata, attribute type mismatches, encapsulation, ...) and
returns the messages of the errors (warnings are ignored); :func:`check_stage`
raises :class:`~physcam.errors.ExportError` with them, naming the prims.
"""

from __future__ import annotations

from ..errors import ExportError
from .plugin import ensure_registered, require_stage

__all__ = ["validation_errors", "check_stage"]


def validation_errors(stage, *, include_warnings: bool = False) -> list[str]:
    """Messages ``"<prim or layer>: <validator>: <message>"`` of usd-core's validators on ``stage``."""
    ensure_registered()
    require_stage(stage)
    from pxr import UsdValidation

    registry = UsdValidation.ValidationRegistry()
    validators = registry.GetOrLoadAllValidators()
    context = UsdValidation.ValidationContext(validators)
    errors = context.Validate(stage)
    wanted = {UsdValidation.ValidationErrorType.Error}
    if include_warnings:
        wanted.add(UsdValidation.ValidationErrorType.Warn)
    out = []
    for e in errors:
        if e.GetType() not in wanted:
            continue
        sites = []
        for site in e.GetSites():
            if site.IsPrim() or site.IsProperty():
                sites.append(str(site.GetPrim().GetPath() if site.IsPrim() else site.GetProperty().GetPath()))
            elif site.GetLayer():
                sites.append(site.GetLayer().identifier)
        where = ", ".join(sites) or "stage"
        out.append(f"{where}: {e.GetName()}: {e.GetMessage()}")
    return out


def check_stage(stage) -> None:
    """Raise :class:`ExportError` listing usd-core's validation errors on ``stage``, if any."""
    errors = validation_errors(stage)
    if errors:
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        raise ExportError(f"USD validation failed: {errors[0]}{more}")
