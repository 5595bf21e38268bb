"""Register physcam's codeless PhysicalCamera schema plugin with USD.

physcam calls :func:`ensure_registered` before it touches a stage, so its schema
types are known in this process. Other USD applications (usdview, DCCs, renderers)
find the plugin through the environment instead::

    export PXR_PLUGINPATH_NAME=$(python -c "import physcam.usd.plugin as p; print(p.PLUGIN_DIR)")

USD reads that variable once, when its plugin registry starts, so it must be set
before the application starts. See docs/usd.md.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["PLUGIN_DIR", "SCHEMA_TYPES", "ensure_registered", "require_stage", "require_prim"]

#: Folder holding plugInfo.json and generatedSchema.usda (for PXR_PLUGINPATH_NAME).
PLUGIN_DIR = Path(__file__).resolve().parent / "plugin"

#: Prim type names and API schema names the plugin defines.
SCHEMA_TYPES = (
    "PhysicalCamera",
    "PhysicalCameraSensorAPI",
    "PhysicalCameraLensAPI",
    "PhysicalCameraLensModel",
    "PhysicalCameraLensModelPinhole",
    "PhysicalCameraLensModelOrthographic",
    "PhysicalCameraLensModelPrescription",
)

_done = False


def ensure_registered() -> None:
    """Register the plugin once per process (a no-op when PXR_PLUGINPATH_NAME already did).

    USD builds its schema registry once, on first use, so this must run before the
    process creates its first stage; :mod:`physcam.usd` calls it on import.

    Raises :class:`~physcam.errors.ExportError` when the plugin files are missing or USD
    does not know the PhysicalCamera type afterwards.
    """
    global _done
    if _done:
        return
    import os
    import sys

    from ..errors import ExportError

    info = PLUGIN_DIR / "plugInfo.json"
    if not info.is_file() or not (PLUGIN_DIR / "generatedSchema.usda").is_file():
        raise ExportError(
            f"physcam's USD schema plugin is missing from {PLUGIN_DIR}; run python scripts/gen_usd_schema.py"
        )
    if "pxr.Plug" not in sys.modules:
        # Before USD's plugin registry starts, the environment is the surest route.
        paths = [p for p in os.environ.get("PXR_PLUGINPATH_NAME", "").split(os.pathsep) if p]
        if str(PLUGIN_DIR) not in paths:
            os.environ["PXR_PLUGINPATH_NAME"] = os.pathsep.join([str(PLUGIN_DIR), *paths])
    from pxr import Plug, Usd

    Plug.Registry().RegisterPlugins(str(PLUGIN_DIR))  # no-op when already registered
    if not Usd.SchemaRegistry().FindConcretePrimDefinition("PhysicalCamera"):
        raise ExportError(
            "USD's schema registry was built in this process before physcam registered its PhysicalCamera "
            "plugin; import physcam.usd before creating any USD stage, or set "
            f"PXR_PLUGINPATH_NAME={PLUGIN_DIR}"
        )
    _done = True


def require_stage(stage):
    """``stage`` if it is a ``Usd.Stage``, else :class:`~physcam.errors.WrongTypeError`."""
    from pxr import Usd

    from ..errors import require_type

    return require_type("stage", stage, Usd.Stage, "open one with physcam.usd.read.open_stage(file)")


def require_prim(prim, name: str = "prim"):
    """``prim`` if it is a valid ``Usd.Prim``, else :class:`~physcam.errors.WrongTypeError`."""
    from pxr import Usd

    from ..errors import WrongTypeError, require_type

    require_type(name, prim, Usd.Prim, "get one with stage.GetPrimAtPath(path)")
    if not prim.IsValid():
        raise WrongTypeError(f"{name} is not a valid prim (no prim at that path?)")
    return prim
