"""``python -m physcam.trace.kernels``: the tracing kernels this install has, and the one "auto" starts with.

One line per kernel (``c``: built or not, and the instruction set it runs; ``numba``: installed or not;
``numpy``: always), then ``auto: <kernel>`` (:func:`physcam.trace.kernels.loaded_backend`). Importing numba
to look for it is skipped: its presence is looked up, not loaded.
"""

from __future__ import annotations

import importlib.util

from ...errors import BackendError
from . import c_available, loaded_backend


def main() -> int:
    if c_available():
        from . import _c

        print(f"c: built ({_c.isa()})")
    else:
        from . import _c_error

        print(f"c: not built ({_c_error})")
    print("numba: " + ("installed (physcam[fast])" if importlib.util.find_spec("numba") else "not installed"))
    print("numpy: always")
    try:
        print(f"auto: {loaded_backend()}")
    except BackendError as exc:  # PHYSCAM_BACKEND names a kernel that cannot trace here
        print(f"auto: {exc}")
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
