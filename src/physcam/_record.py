"""Frozen records that cost less to define: a frozen dataclass whose ``__repr__``, ``__eq__``,
``__hash__``, ``__setattr__`` and ``__delattr__`` are shared functions instead of code compiled for each
class (issue 43).

``dataclasses.dataclass`` writes the source of every generated method and compiles it when the class
is defined: about 1 ms a class on the shared 2-core machine, 38 ms of the 100 ms a ``physcam report
--lens`` took for the 30 records on its path. :func:`record` is ``dataclass(frozen=True)`` with its six
generated methods replaced by functions compiled once, into this module's bytecode, that do what the
generated ones do (CPython 3.11's ``dataclasses._init_fn``, ``_repr_fn``, ``_cmp_fn``, ``_hash_add`` and
``_frozen_get_del_attr``): ``__init__`` takes the same parameters (defaults, default factories,
keyword-only fields, ``__post_init__``; its ``inspect.signature`` is dataclass's), the repr is
``Name(field=value!r, ...)`` of the fields with ``repr=True``, equality compares the tuples of the fields
with ``compare=True`` between instances of the very same class (anything else: ``NotImplemented``), the
hash is that tuple's, and any assignment or deletion raises ``FrozenInstanceError`` once a field is set.
dataclass still collects the fields, so ``fields``, ``replace``, ``asdict`` and ``__dataclass_params__``
are those of ``dataclass(frozen=True)``. A record over another dataclass keeps dataclass's ``__init__``,
``__setattr__`` and ``__delattr__``; a record with an ``InitVar`` is refused.
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


class _Init:
    """How a record's shared ``__init__`` fills its fields: the parameters in order (positional ones
    first, keyword-only after, as dataclass orders them), their defaults and default factories, the
    fields set without a parameter, and whether ``__post_init__`` follows."""

    __slots__ = ("positional", "names", "defaults", "factories", "fixed", "post")

    def __init__(self, cls, fs):
        params = [f for f in fs if f.init]
        self.positional = tuple(f.name for f in params if not f.kw_only)
        self.names = self.positional + tuple(f.name for f in params if f.kw_only)
        self.defaults = {f.name: f.default for f in params if f.default is not dataclasses.MISSING}
        self.factories = {f.name: f.default_factory for f in params if f.default_factory is not dataclasses.MISSING}
        self.fixed = tuple((f.name, f.default, f.default_factory) for f in fs if not f.init
                           and (f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING))
        self.post = hasattr(cls, "__post_init__")


def _init(self, *args, **kwargs):
    """dataclass's ``__init__`` for any record: the same parameters, defaults, errors and ``__post_init__``."""
    plan = type(self).__record_init__
    where = f"{type(self).__qualname__}.__init__()"
    if len(args) > len(plan.positional):
        raise TypeError(f"{where} takes {len(plan.positional) + 1} positional arguments but {len(args) + 1} were given")
    values = dict(zip(plan.positional, args))
    for name, value in kwargs.items():
        if name not in plan.names:
            raise TypeError(f"{where} got an unexpected keyword argument {name!r}")
        if name in values:
            raise TypeError(f"{where} got multiple values for argument {name!r}")
        values[name] = value
    for name in plan.names:
        if name not in values:
            if name in plan.defaults:
                values[name] = plan.defaults[name]
            elif name in plan.factories:
                values[name] = plan.factories[name]()
            else:
                missing = [n for n in plan.names if n not in values and n not in plan.defaults
                           and n not in plan.factories]
                raise TypeError(f"{where} missing {len(missing)} required argument{'s' if len(missing) > 1 else ''}: "
                                + ", ".join(repr(n) for n in missing))
    for name in plan.names:
        object.__setattr__(self, name, values[name])
    for name, default, factory in plan.fixed:
        object.__setattr__(self, name, factory() if default is dataclasses.MISSING else default)
    if plan.post:
        self.__post_init__()


class _Factory:
    def __repr__(self):
        return "<factory>"  # how dataclass's signature shows a default factory


class _Signature:
    """The class's ``__signature__`` (what ``inspect.signature`` reports): dataclass's ``__init__``'s,
    built when first asked for (``inspect`` is imported then)."""

    def __get__(self, obj, owner):
        import inspect

        plan = owner.__record_init__
        fields = owner.__dataclass_fields__
        params = []
        for name in plan.names:
            default = plan.defaults.get(name, _Factory() if name in plan.factories else inspect.Parameter.empty)
            kind = inspect.Parameter.KEYWORD_ONLY if name not in plan.positional else inspect.Parameter.POSITIONAL_OR_KEYWORD
            params.append(inspect.Parameter(name, kind, default=default, annotation=fields[name].type))
        return inspect.Signature(params, return_annotation=None)


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
        out = dataclasses.dataclass(c, init=inherits, frozen=inherits, repr=False, eq=False, **options)
        fs = dataclasses.fields(out)
        if not inherits:
            if len(fs) != len(out.__dataclass_fields__) and any(  # an InitVar: dataclass's own __init__
                    "InitVar" in str(f.type) for f in out.__dataclass_fields__.values()):
                raise TypeError(f"record {c.__qualname__}: InitVar fields need @dataclass(frozen=True)")
            out.__record_init__ = _Init(out, fs)
            out.__init__ = _init
            out.__signature__ = _Signature()
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
        params.init = params.repr = params.eq = params.frozen = True
        return out

    return wrap if cls is None else wrap(cls)
