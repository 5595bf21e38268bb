"""physcam.usd: the PhysicalCamera USD schema (a codeless plugin) and its cameras.

Importing this package registers the schema plugin with USD (it must happen before
the process creates its first stage; see :mod:`physcam.usd.plugin`). Modules:
``author`` (write a PhysicalCamera and its companion UsdGeomCamera), ``read``
(composed prims back to physcam values), ``kit`` (the proposal's pipeline use cases),
``validate`` (usd-core's validators). Reference: docs/usd.md.
"""

from ..extras import require_extra

require_extra("usd", "physcam.usd (USD cameras)")

from .plugin import PLUGIN_DIR, SCHEMA_TYPES, ensure_registered  # noqa: E402

ensure_registered()

__all__ = ["PLUGIN_DIR", "SCHEMA_TYPES", "ensure_registered"]
