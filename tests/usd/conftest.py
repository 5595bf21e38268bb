"""USD tests: register physcam's schema plugin before any stage exists in this process."""

import physcam.usd  # noqa: F401  (registers the PhysicalCamera plugin on import)
