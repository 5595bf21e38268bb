"""Frozen records that cost less to define: a frozen dataclass whose ``__repr__``, ``__eq__``,
``__hash__``, ``__setattr__`` and ``__delattr__`` are shared functions instead of code compiled for each
class (issue 43).

``dataclasses.dataclass`` writes the source of every generated method and compiles it when the class
is defined: about 1 ms a class on the shared 2-core machine, 38 ms of the 100 ms a ``physcam report
--lens`` took for the 30 records on its path. :func:`record` is ``dataclass(frozen=True)`` with five
of its six generated methods replaced by functions compiled once, into this module's bytecode, that
do what the generated ones do (CPython 3.11's ``dataclasses._repr_fn``, ``_cmp_fn``, ``_hash_add`` and
``_frozen_get_del_attr``): the repr ``Name(field=value!r, ...)`` of the fields with ``repr=True``,
equality of the tuples of the fields with ``compare=True`` between instances of the very same class
(anything else: ``NotImplemented``), the hash of that tuple, and ``FrozenInstanceError`` for any
assignment or deletion once a field is set (``__init__`` sets each field once). ``__init__`` is
dataclasses' own, so ``fields``, ``replace``, ``asdict``, ``__dataclass_params__`` and the signature are
those of ``dataclass(frozen=True)``.
"""

from __future__ import annotations

import dataclasses
from operator import attrgetter

__all__ = ["record"]


def _key(names: tuple[str, ...]):
    """A function of an instance giving the tuple of its ``names`` attributes (always a tuple)."""
    if not names:
        return lambda obj: ()
    get = attrgetter(*names)
    return get if len(names) > 1 else (lambda obj: (get(obj),))


def _repr(self) -> str:
    parts = ", ".join(f"{name}={getattr(self, name)!r}" for name in type(self).__record_repr__)
    return f"{type(self).__qualname__}({parts})"


def _eq(self, other):
    if other.__class__ is self.__class__:
        key = type(self).__record_compare__
        return key(self) == key(other)
    return NotImplemented


def _hash(self) -> int:
    return hash(type(self).__record_hash__(self))


def _is_set(obj, name: str) -> bool:
    d = getattr(obj, "__dict__", None)
    return name in d if d is not None else hasattr(obj, name)  # (slots: an unset slot has no value)


def _setattr(self, name, value):
    if name not in type(self).__dataclass_fields__ or _is_set(self, name):
        raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")
    object.__setattr__(self, name, value)  # __init__ (or unpickling) setting a field the first time


def _delattr(self, name):
    raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")


def record(cls=None, /, **options):
    """``@record`` or ``@record(slots=True, ...)``: ``@dataclass(frozen=True, ...)`` with shared
    ``__repr__``/``__eq__``/``__hash__`` (module notes). A method the class body defines is kept."""

    def wrap(c):
        own = {name for name in ("__repr__", "__eq__", "__hash__") if name in c.__dict__}
        if "__eq__" in own and c.__dict__.get("__hash__", 0) is None:
            own.discard("__hash__")  # set to None by Python for a body with __eq__ alone: dataclass adds one
        # a record over another dataclass keeps dataclass's frozen methods (dataclass checks that the
        # frozen-ness of a class and of its bases agree)
        inherits = any(hasattr(b, "__dataclass_fields__") for b in c.__mro__[1:])
        out = dataclasses.dataclass(c, frozen=inherits, repr=False, eq=False, **options)
        fs = dataclasses.fields(out)
        out.__record_repr__ = tuple(f.name for f in fs if f.repr)
        out.__record_compare__ = _key(tuple(f.name for f in fs if f.compare))
        out.__record_hash__ = _key(tuple(f.name for f in fs if (f.compare if f.hash is None else f.hash)))
        shared = [("__repr__", _repr), ("__eq__", _eq), ("__hash__", _hash)]
        if not inherits:
            shared += [("__setattr__", _setattr), ("__delattr__", _delattr)]
        for name, fn in shared:
            if name not in own:
                setattr(out, name, fn)
        params = out.__dataclass_params__  # what the class is: dataclass(frozen=True)'s repr, eq and frozen
        params.repr = params.eq = params.frozen = True
        return out

    return wrap if cls is None else wrap(cls)
