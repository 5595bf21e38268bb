"""physcam._record.record against the standard library's own frozen dataclass: the same fields, values,
repr, equality, hash and frozen-ness, class by class (issue 43: records cost less to define)."""

import dataclasses
import inspect
import pickle

import pytest
from hypothesis import given, settings, strategies as st

from physcam._record import asdict, field, field_names, record, replace
from physcam.lens.prescription import Medium, Surface
from physcam.optics.sensors import Sensor


def _pair(**options):
    """The same class body made by dataclass(frozen=True) (the oracle) and by record."""

    def body(field):
        class Row:
            """A row."""

            a: float
            b: str = "x"
            c: tuple = ()
            d: float | None = field(default=None, compare=False)
            e: int = field(default=0, repr=False)
            f: list = field(default_factory=list, compare=False)
            g: int = field(default=7, kw_only=True)
            h: int = field(default=3, init=False)

            def __post_init__(self):
                object.__setattr__(self, "f", [*self.f, self.e])

        return Row

    return dataclasses.dataclass(frozen=True, **options)(body(dataclasses.field)), record(**options)(body(field))


values = st.builds(lambda a, b, c, d, e: dict(a=a, b=b, c=c, d=d, e=e),
                   st.floats(allow_nan=True), st.text(max_size=5), st.tuples(st.integers(), st.integers()),
                   st.none() | st.floats(allow_nan=False), st.integers(-3, 3))


@pytest.mark.parametrize("options", [{}, {"slots": True}])
@settings(max_examples=60, deadline=None)
@given(x=values, y=values)
def test_a_record_behaves_as_the_frozen_dataclass(options, x, y):
    std, rec = _pair(**options)
    sx, sy, rx, ry = std(**x), std(**y), rec(**x), rec(**y)
    assert repr(rx) == repr(sx)
    assert (rx == ry) == (sx == sy) and (rx != ry) == (sx != sy)
    assert (rx == rx) == (sx == sx)  # a NaN field: a tuple compares the very same object as equal
    assert hash(rx) == hash(sx)
    assert rx.__eq__(sx) is NotImplemented and (rx == sx) is False  # another class, as the dataclass's
    assert [f.name for f in dataclasses.fields(rec)] == [f.name for f in dataclasses.fields(std)]
    assert dataclasses.asdict(rx) == dataclasses.asdict(sx) == asdict(rx)
    assert [f.type for f in dataclasses.fields(rec)] == [f.type for f in dataclasses.fields(std)]
    assert field_names(rx) == tuple(f.name for f in dataclasses.fields(std))
    assert dataclasses.replace(rx, b="y") == replace(rx, b="y") == rec(**{**x, "b": "y"})
    assert repr(replace(rx, g=1)) == repr(dataclasses.replace(sx, g=1))
    with pytest.raises(ValueError):
        replace(rx, h=1)  # an init=False field, as dataclasses.replace refuses it
    with pytest.raises(ValueError):
        dataclasses.replace(sx, h=1)
    assert dataclasses.is_dataclass(rec) and dataclasses.is_dataclass(rx)
    assert rec.__match_args__ == std.__match_args__
    assert str(inspect.signature(rec)) == str(inspect.signature(std))  # (each has its own "<factory>" marker)
    for bad_args, bad_kwargs in (((), {}), ((1.0, "b", (), None, 0, 9), {}), ((1.0,), {"a": 2.0}), ((1.0,), {"z": 1})):
        with pytest.raises(TypeError):
            std(*bad_args, **bad_kwargs)
        with pytest.raises(TypeError):
            rec(*bad_args, **bad_kwargs)
    with pytest.raises(dataclasses.FrozenInstanceError):
        rx.a = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        del rx.b
    with pytest.raises(dataclasses.FrozenInstanceError):
        rx.other = 1  # not a field either (CPython 3.11's frozen slots dataclass raises TypeError here instead)
    p, q = rec.__dataclass_params__, std.__dataclass_params__
    assert (p.init, p.repr, p.eq, p.order, p.unsafe_hash, p.frozen) == (q.init, q.repr, q.eq, q.order, q.unsafe_hash,
                                                                        q.frozen)


@record
class Plain:
    a: float
    b: tuple = ()


@record(slots=True)
class Slotted:
    a: float
    b: tuple = ()


@pytest.mark.parametrize("cls", [Plain, Slotted])
def test_a_record_pickles_and_copies(cls):
    import copy

    r = cls(1.5, (2, 3))
    assert pickle.loads(pickle.dumps(r)) == r and copy.deepcopy(r) == r and copy.copy(r) == r
    assert pickle.loads(pickle.dumps(r)) is not r


def test_a_record_over_a_record_is_frozen_and_compares_its_own_fields():
    @record
    class Base:
        a: float

    @record
    class Child(Base):
        b: float = 2.0

    c = Child(1.0)
    assert repr(c).endswith("Child(a=1.0, b=2.0)") and c == Child(1.0, 2.0) and c != Child(1.0, 3.0)
    assert c != Base(1.0) and hash(c) == hash((1.0, 2.0))
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.b = 3.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        Base(1.0).a = 2.0


def test_a_method_the_class_defines_is_kept():
    @record
    class Named:
        name: str
        size: float = 0.0

        def __repr__(self):
            return f"<{self.name}>"

        def __eq__(self, other):
            return isinstance(other, Named) and self.name == other.name

        __hash__ = object.__hash__

    assert repr(Named("a", 1.0)) == "<a>"
    assert Named("a", 1.0) == Named("a", 2.0)
    n = Named("b")
    assert hash(n) == object.__hash__(n)


def test_the_records_on_the_report_path_compare_as_before():
    # built twice from the same numbers, physcam's own records are equal, hash alike and print their fields
    s1 = Surface(radius=50.0, thickness=5.0, medium=Medium(1.5168, 64.17, "N-BK7"), semi_diameter=10.0)
    s2 = Surface(radius=50.0, thickness=5.0, medium=Medium(1.5168, 64.17, "N-BK7"), semi_diameter=10.0)
    assert s1 == s2 and hash(s1) == hash(s2) and s1 is not s2
    assert s1 != dataclasses.replace(s1, thickness=6.0)
    assert repr(s1).startswith("Surface(radius=50.0, thickness=5.0, medium=Medium(nd=1.5168, vd=64.17, glass='N-BK7'")
    assert Sensor("k", "n", 24.89, 18.66) == Sensor("k", "n", 24.89, 18.66)
