"""Frozen records that cost less to define: what ``@dataclass(frozen=True)`` makes, without compiling
code for each class or importing :mod:`dataclasses` (issue 43).

``dataclasses.dataclass`` writes the source of every generated method and compiles it when the class is
defined, about 1 ms a class on the shared 2-core machine: 38 ms of the 100 ms a ``physcam report --lens``
took for the 30 records on its path, and importing :mod:`dataclasses` (with :mod:`inspect`, :mod:`ast`,
:mod:`dis`, :mod:`tokenize`) 8 ms more. :func:`record` makes the same class with shared functions,
compiled once into this module's bytecode, that do what the generated ones do (CPython 3.11's
``dataclasses._init_fn``, ``_repr_fn``, ``_cmp_fn``, ``_hash_add``, ``_frozen_get_del_attr``):

- ``__init__`` takes the same parameters (defaults, :func:`field` factories, keyword-only fields,
  ``init=False`` fields, ``__post_init__``); ``inspect.signature`` of the class is dataclass's;
- the repr is ``Name(field=value!r, ...)`` of the fields with ``repr=True``; equality compares the tuples
  of the fields with ``compare=True`` between instances of the very same class (anything else:
  ``NotImplemented``); the hash is that tuple's;
- assigning or deleting an attribute raises ``dataclasses.FrozenInstanceError`` once the field is set.

The standard library's view is built when first asked for: ``__dataclass_fields__`` and
``__dataclass_params__`` (so ``dataclasses.fields``, ``replace``, ``asdict`` and ``is_dataclass`` work, and
``FrozenInstanceError``), importing :mod:`dataclasses` then. On the report's path, :func:`replace`,
:func:`asdict` and :func:`field_names` answer without it.
"""

from __future__ import annotations

from operator import attrgetter

__all__ = ["record", "field", "replace", "asdict", "field_names"]


class _Missing:
    def __repr__(self):
        return "MISSING"


#: No default (dataclasses.MISSING's role here).
MISSING = _Missing()


class _Field:
    """One field of a record: what ``dataclasses.field`` takes, and its name and annotation."""

    __slots__ = ("name", "type", "default", "default_factory", "init", "repr", "hash", "compare", "kw_only")

    def __init__(self, default=MISSING, default_factory=MISSING, init=True, repr=True, hash=None, compare=True,
                 kw_only=False):
        if default is not MISSING and default_factory is not MISSING:
            raise ValueError("cannot specify both default and default_factory")
        self.name, self.type = None, None
        self.default, self.default_factory = default, default_factory
        self.init, self.repr, self.hash, self.compare, self.kw_only = init, repr, hash, compare, kw_only


def field(*, default=MISSING, default_factory=MISSING, init=True, repr=True, hash=None, compare=True,
          kw_only=False):
    """``dataclasses.field`` for a :func:`record`'s class body (the same keywords, less ``metadata``)."""
    return _Field(default, default_factory, init, repr, hash, compare, kw_only)


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


def _frozen(message: str):
    from dataclasses import FrozenInstanceError

    return FrozenInstanceError(message)


def _is_set(obj, name: str) -> bool:
    d = getattr(obj, "__dict__", None)
    return name in d if d is not None else hasattr(obj, name)  # (slots: an unset slot has no value)


def _setattr(self, name, value):
    if name not in type(self).__record_init__.every or _is_set(self, name):
        raise _frozen(f"cannot assign to field {name!r}")
    object.__setattr__(self, name, value)  # unpickling (or copy) setting a field the first time


def _delattr(self, name):
    raise _frozen(f"cannot delete field {name!r}")


class _Init:
    """How a record's shared ``__init__`` fills its fields: the parameters in order (positional ones
    first, keyword-only after, as dataclass orders them), their defaults and default factories, the
    fields set without a parameter, and whether ``__post_init__`` follows."""

    __slots__ = ("fields", "every", "positional", "names", "name_set", "defaults", "factories", "fixed", "post",
                 "cls", "direct")

    def __init__(self, cls, fs):
        self.fields = fs
        self.every = tuple(f.name for f in fs)
        params = [f for f in fs if f.init]
        self.positional = tuple(f.name for f in params if not f.kw_only)
        self.names = self.positional + tuple(f.name for f in params if f.kw_only)
        self.name_set = frozenset(self.names)
        self.defaults = {f.name: f.default for f in params if f.default is not MISSING}
        self.factories = {f.name: f.default_factory for f in params if f.default_factory is not MISSING}
        self.fixed = tuple((f.name, f.default, f.default_factory) for f in fs if not f.init
                           and (f.default is not MISSING or f.default_factory is not MISSING))
        self.post = hasattr(cls, "__post_init__")
        self.cls, self.direct = cls, _fields_in_dict(cls, self.every)


def _fields_in_dict(cls, names) -> bool:
    """Whether an instance of ``cls`` keeps each field in its ``__dict__``: no class of it has
    ``__slots__`` and no field's name is a descriptor that sets (``object.__setattr__`` would call it)."""
    if any("__slots__" in k.__dict__ for k in cls.__mro__[:-1]):
        return False
    for name in names:
        owner = next((k for k in cls.__mro__ if name in k.__dict__), None)
        if owner is not None and hasattr(type(owner.__dict__[name]), "__set__"):
            return False
    return True


def _init(self, *args, **kwargs):
    """dataclass's ``__init__`` for any record: the same parameters, defaults, errors and ``__post_init__``.
    Arguments that fit go straight in (a lens report builds eight records: issue 47); any that do not
    go through :func:`_init_checked`, which says what is wrong as dataclass does."""
    plan = type(self).__record_init__
    if len(args) > len(plan.positional) or not plan.name_set.issuperset(kwargs):
        return _init_checked(self, *args, **kwargs)
    values = dict(zip(plan.positional, args)) if args else {}
    if values and not values.keys().isdisjoint(kwargs):
        return _init_checked(self, *args, **kwargs)
    values.update(kwargs)
    filled = []
    for name in plan.names:
        if name in values:
            filled.append((name, values[name]))
        elif name in plan.defaults:
            filled.append((name, plan.defaults[name]))
        elif name in plan.factories:
            filled.append((name, plan.factories[name]()))
        else:
            return _init_checked(self, *args, **kwargs)  # (a required argument missing: its TypeError)
    for name, default, factory in plan.fixed:
        filled.append((name, factory() if default is MISSING else default))
    if plan.direct and type(self) is plan.cls:
        self.__dict__.update(filled)  # what object.__setattr__ does for these fields, in one call
    else:
        for name, value in filled:
            object.__setattr__(self, name, value)
    if plan.post:
        self.__post_init__()


def _init_checked(self, *args, **kwargs):
    """:func:`_init` for arguments that may not fit, each checked in dataclass's order with its TypeError."""
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
        object.__setattr__(self, name, factory() if default is MISSING else default)
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
        types = {f.name: f.type for f in plan.fields}
        params = []
        for name in plan.names:
            default = plan.defaults.get(name, _Factory() if name in plan.factories else inspect.Parameter.empty)
            kind = inspect.Parameter.KEYWORD_ONLY if name not in plan.positional else inspect.Parameter.POSITIONAL_OR_KEYWORD
            params.append(inspect.Parameter(name, kind, default=default, annotation=types[name]))
        return inspect.Signature(params, return_annotation=None)


class _StandardView:
    """``__dataclass_fields__`` or ``__dataclass_params__`` of a record: the standard library's
    objects, made when first asked for (by a throwaway ``dataclasses.make_dataclass`` of the same
    fields, which compiles nothing) and kept on the class."""

    def __init__(self, attribute: str):
        self.attribute = attribute

    def __get__(self, obj, owner):
        import dataclasses

        def std(value):
            return dataclasses.MISSING if value is MISSING else value

        plan = owner.__record_init__
        spec = [(f.name, f.type, dataclasses.field(default=std(f.default), default_factory=std(f.default_factory),
                                                   init=f.init, repr=f.repr, hash=f.hash, compare=f.compare,
                                                   kw_only=f.kw_only)) for f in plan.fields]
        shadow = dataclasses.make_dataclass(owner.__name__, spec, init=False, repr=False, eq=False)
        params = shadow.__dataclass_params__  # what the record is: dataclass(frozen=True)'s
        params.init = params.repr = params.eq = params.frozen = True
        if hasattr(params, "slots"):  # (Python 3.12 and later record it)
            params.slots = "__slots__" in owner.__dict__
        fields = shadow.__dataclass_fields__
        if isinstance(owner.__dict__.get("__dataclass_fields__"), _StandardView):
            type.__setattr__(owner, "__dataclass_fields__", fields)
            type.__setattr__(owner, "__dataclass_params__", params)
        return fields if self.attribute == "__dataclass_fields__" else params


def _is_class_var(annotation) -> bool:
    text = annotation if isinstance(annotation, str) else repr(annotation)
    return text.startswith(("ClassVar", "typing.ClassVar"))


def _fields_of(c) -> list[_Field]:
    """The fields of class ``c``: its bases' records' first (in their order), then its own annotations
    (a field declared again keeps its place), as dataclass collects them."""
    found: dict[str, _Field] = {}
    for base in reversed(c.__mro__[1:]):
        plan = base.__dict__.get("__record_init__")
        if plan is not None:
            found.update((f.name, f) for f in plan.fields)
        elif "__dataclass_fields__" in base.__dict__:
            raise TypeError(f"record {c.__qualname__}: a record's bases are records or plain classes, not dataclasses")
    for name, annotation in c.__dict__.get("__annotations__", {}).items():
        if _is_class_var(annotation):
            continue
        if "InitVar" in str(annotation):
            raise TypeError(f"record {c.__qualname__}: InitVar fields need @dataclass(frozen=True)")
        value = c.__dict__.get(name, MISSING)
        if type(value).__name__ == "Field" and type(value).__module__ == "dataclasses":
            raise TypeError(f"record {c.__qualname__}.{name}: use physcam._record.field, not dataclasses.field")
        f = value if isinstance(value, _Field) else _Field(default=value)
        if f.default is not MISSING and type(f.default).__hash__ is None:
            raise ValueError(f"mutable default {type(f.default)} for field {name} is not allowed: use default_factory")
        f.name, f.type = name, annotation
        found[name] = f
    fs = list(found.values())
    seen_default = False
    for f in fs:  # dataclass's rule: a positional parameter without a default may not follow one with
        if f.init and not f.kw_only:
            if f.default is not MISSING or f.default_factory is not MISSING:
                seen_default = True
            elif seen_default:
                raise TypeError(f"non-default argument {f.name!r} follows default argument")
    return fs


def _with_slots(c, fs):
    """``c`` made again with ``__slots__`` for its own fields (as ``dataclass(slots=True)`` does)."""
    inherited = {s for b in c.__mro__[1:-1] for s in b.__dict__.get("__slots__", ())}
    body = dict(c.__dict__)
    names = tuple(f.name for f in fs if f.name not in inherited)
    for name in names:
        body.pop(name, None)
    body.pop("__dict__", None)
    body.pop("__weakref__", None)
    body["__slots__"] = names
    out = type(c)(c.__name__, c.__bases__, body)
    out.__qualname__ = c.__qualname__
    return out


def record(cls=None, /, *, slots: bool = False):
    """``@record`` or ``@record(slots=True)``: ``@dataclass(frozen=True[, slots=True])`` made with shared
    methods (module notes). A ``__repr__``, ``__eq__`` or ``__hash__`` the class body defines is kept."""

    def wrap(c):
        if not isinstance(c, type):
            raise TypeError(f"record decorates a class, got {type(c).__name__}")
        own = {name for name in ("__repr__", "__eq__", "__hash__") if name in c.__dict__}
        if "__eq__" in own and c.__dict__.get("__hash__", 0) is None:
            own.discard("__hash__")  # set to None by Python for a body with __eq__ alone: dataclass adds one
        for name in ("__setattr__", "__delattr__"):
            if name in c.__dict__:
                raise TypeError(f"Cannot overwrite attribute {name} in class {c.__name__}")
        fs = _fields_of(c)
        if slots:
            c = _with_slots(c, fs)
        else:
            for f in fs:  # class attributes as dataclass leaves them: a plain default stays, a field() goes
                if isinstance(c.__dict__.get(f.name), _Field):
                    if f.default is MISSING:
                        delattr(c, f.name)
                    else:
                        setattr(c, f.name, f.default)
        plan = _Init(c, fs)
        c.__record_init__ = plan
        c.__init__ = _init
        c.__signature__ = _Signature()
        c.__dataclass_fields__ = _StandardView("__dataclass_fields__")
        c.__dataclass_params__ = _StandardView("__dataclass_params__")
        if "__match_args__" not in c.__dict__:
            c.__match_args__ = plan.positional
        c.__record_repr__ = tuple(f.name for f in fs if f.repr)
        c.__record_compare__ = _key(tuple(f.name for f in fs if f.compare))
        c.__record_hash__ = _key(tuple(f.name for f in fs if (f.compare if f.hash is None else f.hash)))
        for name, fn in (("__repr__", _repr), ("__eq__", _eq), ("__hash__", _hash), ("__setattr__", _setattr),
                         ("__delattr__", _delattr)):
            if name not in own:
                setattr(c, name, fn)
        return c

    return wrap if cls is None else wrap(cls)


def field_names(obj) -> tuple[str, ...]:
    """The field names of a record (class or instance), in order (``dataclasses.fields``'s names)."""
    cls = obj if isinstance(obj, type) else type(obj)
    plan = getattr(cls, "__record_init__", None)
    if plan is None:
        raise TypeError(f"field_names() takes a record or its class, got {cls.__name__}")
    return plan.every


def replace(obj, /, **changes):
    """``dataclasses.replace`` for a record (any other dataclass is handed to it): a new instance with
    ``changes``; an ``init=False`` field cannot be changed (ValueError), an unknown name is a TypeError."""
    plan = getattr(type(obj), "__record_init__", None)
    if plan is None:
        import dataclasses

        return dataclasses.replace(obj, **changes)
    cls = type(obj)
    if (plan.direct and cls is plan.cls and not plan.post and cls.__new__ is object.__new__
            and len(plan.names) == len(plan.every) == len(obj.__dict__) and plan.name_set.issuperset(changes)):
        new = object.__new__(cls)  # what cls(**every field) makes, without reading each back (issue 47)
        new.__dict__.update(obj.__dict__)
        new.__dict__.update(changes)
        return new
    for f in plan.fields:
        if not f.init:
            if f.name in changes:
                raise ValueError(f"field {f.name} is declared with init=False, it cannot be specified with replace()")
        elif f.name not in changes:
            changes[f.name] = getattr(obj, f.name)
    return type(obj)(**changes)


_ATOMIC = (type(None), bool, int, float, complex, str, bytes)


def _plain(value):
    """``dataclasses.asdict``'s ``_asdict_inner`` (dict_factory dict)."""
    if hasattr(type(value), "__record_init__"):
        return {name: _plain(getattr(value, name)) for name in type(value).__record_init__.every}
    if isinstance(value, _ATOMIC):
        return value  # (deepcopy gives the same object)
    if hasattr(type(value), "__dataclass_fields__") and not isinstance(value, type):
        import dataclasses

        return dataclasses.asdict(value)
    if isinstance(value, tuple) and hasattr(value, "_fields"):
        return type(value)(*[_plain(v) for v in value])
    if isinstance(value, (list, tuple)):
        return type(value)(_plain(v) for v in value)
    if isinstance(value, dict):
        return type(value)((_plain(k), _plain(v)) for k, v in value.items())
    import copy

    return copy.deepcopy(value)


def asdict(obj) -> dict:
    """``dataclasses.asdict`` for a record: its fields, in order, records and dataclasses inside made
    dicts, lists, tuples and dicts copied through, anything else deep-copied."""
    if not hasattr(type(obj), "__record_init__"):
        raise TypeError("asdict() should be called on record instances")
    return _plain(obj)
