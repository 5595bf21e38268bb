"""Wrong argument types in the Python API raise physcam's errors or TypeError with a sentence
(issue 8), never a bare AttributeError/IndexError/KeyError from deep inside.

Every public function (``__all__`` of every module) is called with each required argument in turn
replaced by values of the wrong type, the others sensible. A ValueError is accepted too (Python's
own word for "a number was expected": ``float('dgauss')``), as is any PhysCamError."""

from __future__ import annotations

import inspect
import warnings

import pytest

from _public_api import public_objects
from physcam.errors import PhysCamError
from physcam.lens.library import load_lens

WRONG = ["dgauss", None, [1, 2], {"a": 1}, object(), b"x", 3 + 2j]
SKIP_MODULES = (".cli", "__main__", ".kernels")
#: decorators and tiny helpers whose argument is a function, not data
#: Keyword arguments that keep a function's valid-looking calls cheap (a folder name is a valid out_dir:
#: one lens, not the whole library, goes into that extension zip).
CHEAP = {"build_extension": {"lenses": ["dgauss_50mm"]}}
#: lens_payload: a name ('dgauss') is a valid slug, so that call computes a lens's whole payload (a minute);
#: its argument types are checked first (tests/blender/test_extension.py builds real payloads)
SKIP_FUNCTIONS = {"takes_prescription", "takes_text", "takes_report", "takes_camera", "require_type", "lens_payload"}


def _public_functions():
    return [pytest.param(fn, id=f"{mod}.{name}") for mod, name, fn in public_objects(SKIP_MODULES)
            if inspect.isfunction(fn) and name not in SKIP_FUNCTIONS]


@pytest.mark.parametrize("fn", _public_functions())
def test_wrong_types_get_a_sentence(fn, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a text argument that is a valid path ('dgauss') may be written to
    lens = load_lens("dgauss_50mm")
    params = [p for p in inspect.signature(fn).parameters.values()
              if p.default is p.empty and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
    for i, p in enumerate(params):
        for bad in WRONG:
            kwargs = {q.name: (bad if j == i else lens if q.name in ("lens", "prescription", "p") else 50.0)
                      for j, q in enumerate(params)}
            kwargs.update(CHEAP.get(fn.__name__, {}))
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    fn(**kwargs)
            except (PhysCamError, TypeError, ValueError):
                pass
            except Exception as exc:  # noqa: BLE001 - the point of the test
                pytest.fail(f"{fn.__name__}({p.name}={bad!r}) raised {type(exc).__name__}: {exc}")
