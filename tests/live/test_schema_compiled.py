"""The compiled schema (fastjsonschema, as draft 7) says yes to exactly the samples jsonschema's draft
2020-12 validator says yes to: the official examples and thousands of their mutations (hypothesis: values
replaced by JSON values of every type, keys removed and added, at every depth), and a schema with a
keyword whose meaning changed between the drafts is left to jsonschema alone."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from physcam.live.sample import _SAME_IN_DRAFT_7, _fast_is_valid, _schema_keywords, _validator, schema

pytest.importorskip("fastjsonschema")

EXAMPLES = [json.loads(p.read_text()) for p in sorted((Path(__file__).parent / "data").glob("*_example.json"))]

#: JSON values of every type, near the schema's edges: integers and the same numbers as floats (2 and 2.0:
#: "integer" admits both in draft 2020-12), negatives, zero, huge, short and long strings, nesting
SCALARS = st.one_of(
    st.none(), st.booleans(), st.integers(-3, 3), st.integers(-2**63, 2**63),
    st.sampled_from([0.0, -0.0, 1.0, 2.0, 0.5, -1.5, 1e-9, 1e300, 24.0, 23.976, 119.0, 120.0, 65535.0]),
    st.floats(allow_nan=False, allow_infinity=False),
    st.text(max_size=3), st.sampled_from(["", "a", "00:00:00:00", "mm", "urn:uuid:" + "0" * 36, "x" * 1023,
                                          "x" * 1024, "x" * 1025]))
VALUES = st.recursive(SCALARS, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                       st.dictionaries(st.text(max_size=6), inner, max_size=3)),
                      max_leaves=6)


def _paths(node, here=()):
    """Every path to a value in ``node``: dict keys and list indexes."""
    yield here
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, here + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, here + (i,))


def _mutate(sample, data):
    """Replace, remove or add at a few drawn paths of ``sample`` (a deep copy)."""
    s = copy.deepcopy(sample)
    for _ in range(data.draw(st.integers(1, 3))):
        paths = [p for p in _paths(s) if p]
        if not paths:
            break
        path = data.draw(st.sampled_from(paths))
        parent = _get(s, path[:-1])
        how = data.draw(st.sampled_from(["replace", "replace", "remove", "add"]))
        if how == "replace":
            parent[path[-1]] = data.draw(VALUES)
        elif how == "remove":
            del parent[path[-1]]
        elif isinstance(parent, dict):
            parent[data.draw(st.text(max_size=8))] = data.draw(VALUES)
        else:
            parent.append(data.draw(VALUES))
    return s


def test_the_examples_are_valid_to_both():
    fast, full = _fast_is_valid(), _validator()
    assert fast is not None
    for sample in EXAMPLES:
        assert fast(sample) and full.is_valid(sample)


@settings(max_examples=300)
@given(st.data())
def test_the_compiled_schema_agrees_with_jsonschema_on_mutated_samples(data):
    sample = _mutate(data.draw(st.sampled_from(EXAMPLES)), data)
    assert _fast_is_valid()(sample) == _validator().is_valid(sample)


@settings(max_examples=200)
@given(st.data(), st.sampled_from(["type", "minimum", "exclusiveMinimum", "pattern", "required"]))
def test_near_misses_of_one_rule_agree(data, rule):
    """Values at a rule's edge: an integer field given its float twin, a bound given itself and its
    neighbours, a pattern's string one character off."""
    sample = copy.deepcopy(data.draw(st.sampled_from(EXAMPLES)))
    paths = [p for p in _paths(sample) if p and isinstance(_get(sample, p), (int, float, str))
             and not isinstance(_get(sample, p), bool)]
    path = data.draw(st.sampled_from(paths))
    v = _get(sample, path)
    if isinstance(v, str):
        new = data.draw(st.sampled_from([v[:-1], v + "0", v.upper(), " " + v, v.replace(":", ";")]))
    else:
        new = data.draw(st.sampled_from([float(v), int(v), v + 1, v - 1, -v, v * 1.0000001, 0, 0.0]))
    _set(sample, path, new)
    assert _fast_is_valid()(sample) == _validator().is_valid(sample)


def _get(node, path):
    for k in path:
        node = node[k]
    return node


def _set(node, path, value):
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value


def test_the_schema_uses_only_keywords_of_the_same_meaning_in_draft_7():
    """OpenTrackIO 1.0.1's keywords, counted by hand from the file: the compiled path serves it."""
    assert _schema_keywords(schema()) == {
        "$id", "$schema", "type", "description", "minimum", "maximum", "properties", "additionalProperties",
        "required", "minLength", "maxLength", "units", "items", "pattern", "exclusiveMinimum", "minItems",
        "enum", "anyOf", "maxItems", "uniqueItems"}
    assert _schema_keywords(schema()) <= _SAME_IN_DRAFT_7
    assert "prefixItems" not in _SAME_IN_DRAFT_7 and "$ref" not in _SAME_IN_DRAFT_7
