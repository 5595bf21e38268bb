"""``python -m physcam.trace.kernels``: the tracing kernels this install has, and the one "auto" starts with.

One line per kernel (``c``: built or not, and the instruction set it runs; ``numba``: installed or not;
``numpy``: always), then ``auto: <kernel>`` (:func:`physcam.trace.kernels.loaded_backend`). Importing numba
to look for it is skipped: its presence is looked up, not loaded.
"""

from __future__ import annotations

import importlib.util

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
    print(f"auto: {loaded_backend()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
