"""physcam's optional extras: what each needs, and one clear error when it is missing.

``pip install physcam`` gives the on-set report, lens loading, Gaussian optics, the tracer, the
analyses and their figures. The rest comes in extras (docs/install.md), each checked where its
package is entered (``physcam.usd``, ``physcam.live``, ``physcam.characterize``, ``physcam.serve``)
or where its one function needs it (EXR writers), so a missing extra is one sentence naming the
``pip install`` that fixes it, never an ImportError from deep inside:

=========  ====================================  ============================================
extra      packages                              what it gives
=========  ====================================  ============================================
fast       numba                                 the JIT tracing kernels (same rays, faster)
usd        usd-core                              PhysicalCamera USD files, kits, readers
exr        OpenEXR                               ST-maps and images as EXR
live       jsonschema, fastjsonschema, cbor2     OpenTrackIO samples (physcam live)
dask       dask[distributed], bokeh, pyarrow     physcam characterize on a cluster
serve      starlette, uvicorn, httptools, segno  physcam serve, the phone page
calibrate  opencv-python-headless                physcam calibrate: charts found in photographs
farm       openjd-model                          physcam farm --to openjd: validated job templates
opencue    opencue-pyoutline                     physcam farm --to opencue: OpenCue outlines
all        all of the above
=========  ====================================  ============================================
"""

from __future__ import annotations

import importlib.util

from .errors import InputError, MissingExtraError, require_type

__all__ = ["EXTRAS", "require_extra", "missing_modules"]

#: extra -> (import name, PyPI name) of each package it brings
EXTRAS = {
    "fast": (("numba", "numba"),),
    "usd": (("pxr", "usd-core"),),
    "exr": (("OpenEXR", "OpenEXR"),),
    "live": (("jsonschema", "jsonschema"), ("fastjsonschema", "fastjsonschema"), ("cbor2", "cbor2")),
    "dask": (("distributed", "dask[distributed]"), ("bokeh", "bokeh"), ("pyarrow", "pyarrow")),
    "serve": (("starlette", "starlette"), ("uvicorn", "uvicorn"), ("httptools", "httptools"), ("segno", "segno")),
    "calibrate": (("cv2", "opencv-python-headless"),),
    "farm": (("openjd.model", "openjd-model"),),
    "opencue": (("outline", "opencue-pyoutline"),),
}


def missing_modules(extra: str) -> list[str]:
    """The PyPI names of ``extra``'s packages that cannot be imported here."""
    require_type("extra", extra, str, "one of " + ", ".join(EXTRAS))
    if extra not in EXTRAS:
        raise InputError(f"unknown extra {extra!r}; physcam's extras are {', '.join(EXTRAS)}")
    out = []
    for module, package in EXTRAS[extra]:
        try:
            found = importlib.util.find_spec(module) is not None
        except (ImportError, ValueError):  # a parent package missing, or a module set to None
            found = False
        if not found:
            out.append(package)
    return out


def require_extra(extra: str, what: str) -> None:
    """Raise :class:`~physcam.errors.MissingExtraError` naming the fix when ``extra`` is not installed;
    ``what`` says what needed it (e.g. "USD cameras")."""
    require_type("what", what, str, 'what needs the extra, e.g. "USD cameras"')
    missing = missing_modules(extra)
    if missing:
        raise MissingExtraError(f"{what} needs physcam's '{extra}' extra ({', '.join(missing)} "
                                f"{'is' if len(missing) == 1 else 'are'} not installed): "
                                f"pip install 'physcam[{extra}]'")
