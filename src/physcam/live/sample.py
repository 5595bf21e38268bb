"""OpenTrackIO samples: decode (JSON or CBOR) and validate against the shipped 1.0.1 JSON schema.

The schema is SMPTE RIS-OSVP's ``opentrackio-schema-1.0.1.json`` (draft 2020-12), shipped as
``physcam/data/opentrackio-schema-1.0.1.json`` and checked by :mod:`jsonschema`'s
``Draft202012Validator``, a complete implementation of the draft (docs/live.md says why this
library). A valid sample's yes comes from the same schema compiled to Python by :mod:`fastjsonschema`
(its keywords mean the same in draft 7, which fastjsonschema implements: :data:`_SAME_IN_DRAFT_7`;
1-3 ms -> tens of microseconds a sample); any other sample is judged and reported by jsonschema.
Plus one rule the schema cannot state and camdkit's model checks: a timecode's ``frames`` is below
its ``frameRate`` (rounded up). A sample that fails is reported by its JSON path (``$.lens.fStop``) and the schema rule it
broke (``exclusiveMinimum``), the first problem first in document order.

Numbers that JSON cannot carry (NaN, Infinity) and CBOR can are refused too, with their path, and so
are numbers beyond a 64-bit float (JSON's ``1e5000`` reads as infinity; CBOR's decimal fraction
``1e5000`` or a 400-digit bignum, an integer literal of 5,000 digits in either): no NaN or infinity
enters physcam from a stream. CBOR's other numbers (decimal fractions, bigfloats, rationals) are
read as floats; what JSON has no form for (CBOR byte strings, tags, dates, sets, keys that are not
text) is refused with its path. A problem's message is one line of at most 240 characters, and
shows a received value through :func:`shown`: an integer is described by its number of digits,
never converted to text whole (Python refuses that past 4,300 digits).
"""

from __future__ import annotations

import json
import math
import numbers
import sys
from dataclasses import dataclass
from functools import lru_cache

from ..errors import InputError, require_type

__all__ = ["SCHEMA_FILE", "PROTOCOL_VERSION", "SampleError", "SampleProblem", "schema", "sample_problems",
           "validate_sample", "decode_sample", "encode_sample", "json_path", "shown"]

SCHEMA_FILE = "opentrackio-schema-1.0.1.json"
PROTOCOL_VERSION = (1, 0, 1)
#: nesting deeper than this is refused before validation (the schema's deepest path is 6 levels)
MAX_DEPTH = 32


@dataclass(frozen=True)
class SampleProblem:
    """One reason a sample is not valid: where (a JSON path, ``$`` the sample), which rule, and a sentence."""

    path: str
    rule: str
    message: str

    def __str__(self) -> str:
        return f"{self.path}: {self.message} (rule: {self.rule})"

    def to_dict(self) -> dict:
        return {"path": self.path, "rule": self.rule, "message": self.message}


class SampleError(InputError):
    """A sample that does not decode or does not validate; ``problems`` lists every reason, the first
    is in the message."""

    def __init__(self, problems):
        self.problems = tuple(problems)
        first = self.problems[0]
        more = f" (and {len(self.problems) - 1} more)" if len(self.problems) > 1 else ""
        super().__init__(f"invalid OpenTrackIO sample: {first}{more}")


def json_path(parts) -> str:
    """A JSON path from keys and indices: ``("lens", "distortion", 0, "radial")`` -> ``$.lens.distortion[0].radial``."""
    out = "$"
    for p in parts:
        if isinstance(p, int) and not isinstance(p, bool):
            out += f"[{p}]"
        elif isinstance(p, str) and len(p) > 40:  # a received key: named by its start and length
            out += "[" + json.dumps(p[:24])[:-1] + f'..." ({len(p)} characters)]'
        elif isinstance(p, str) and p.isidentifier():
            out += f".{p}"
        else:
            out += "[" + json.dumps(str(p)) + "]"
    return out


def _needs_live(what: str) -> None:
    from ..extras import require_extra

    require_extra("live", f"{what} (physcam live)")


def _cbor2():
    """The cbor2 module; :class:`~physcam.errors.MissingExtraError` naming the live extra when it cannot be
    imported. (Asking for the extra each sample searched the import path for its three packages: 10,000
    CBOR samples spent a second of CPU there.)"""
    try:
        import cbor2
    except ImportError:
        _needs_live("CBOR samples")
        raise
    return cbor2


@lru_cache(maxsize=1)
def schema() -> dict:
    """The OpenTrackIO 1.0.1 JSON schema (a dict; do not modify it)."""
    from importlib.resources import files

    return json.loads(files("physcam.data").joinpath(SCHEMA_FILE).read_text(encoding="utf-8"))


@lru_cache(maxsize=1)
def _validator():
    _needs_live("validating OpenTrackIO samples")
    import jsonschema

    s = schema()
    cls = jsonschema.validators.validator_for(s)
    cls.check_schema(s)
    return cls(s)


#: The schema keywords whose meaning draft 2020-12 and draft 7 share (JSON Schema 2020-12 Validation
#: sections 6-7 and draft-handrews-json-schema-validation-01 section 6), and the annotations either ignores:
#: what the OpenTrackIO 1.0.1 schema uses (``units`` is its own annotation). A schema with any other keyword
#: (``prefixItems``, ``$ref``, ``unevaluatedProperties``, ...) is judged by jsonschema alone.
_SAME_IN_DRAFT_7 = frozenset({
    "type", "properties", "additionalProperties", "required", "items", "minItems", "maxItems", "uniqueItems",
    "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "minLength", "maxLength", "pattern", "enum",
    "const", "anyOf", "allOf", "oneOf", "not", "multipleOf", "minProperties", "maxProperties",
    "description", "title", "units", "$id", "$schema"})


def _schema_keywords(node, out=None) -> set:
    """Every keyword ``node`` (a schema) uses, property names left out."""
    out = set() if out is None else out
    if isinstance(node, dict):
        for k, v in node.items():
            out.add(k)
            if k in ("properties", "patternProperties", "$defs", "definitions") and isinstance(v, dict):
                for sub in v.values():
                    _schema_keywords(sub, out)
            else:
                _schema_keywords(v, out)
    elif isinstance(node, list):
        for v in node:
            _schema_keywords(v, out)
    return out


@lru_cache(maxsize=1)
def _fast_is_valid():
    """The schema compiled by fastjsonschema (as draft 7: :data:`_SAME_IN_DRAFT_7`), as ``sample -> bool``;
    None where the schema uses a keyword outside that set."""
    _needs_live("validating OpenTrackIO samples")  # the live extra brings fastjsonschema
    import fastjsonschema

    s = schema()
    if not _schema_keywords(s) <= _SAME_IN_DRAFT_7:
        return None
    check = fastjsonschema.compile({**s, "$schema": "http://json-schema.org/draft-07/schema#"},
                                   use_default=False, use_formats=False)
    error = fastjsonschema.JsonSchemaException

    def is_valid(sample) -> bool:
        try:
            check(sample)
        except error:
            return False
        return True

    return is_valid


#: the longest integer literal a JSON sample may hold (digits): more is beyond a 64-bit float anyway
#: (its largest value has 309 digits), and Python would refuse to read one past 4,300 digits
_JSON_INT_DIGITS = 309
#: a problem's message is cut to this many characters (a sample holds up to 64 KiB of text)
MAX_MESSAGE_CHARS = 240


class _LongInteger:
    """A JSON integer literal of more digits than any 64-bit float holds, kept as its digit count."""

    __slots__ = ("digits",)

    def __init__(self, digits: int):
        self.digits = digits


def _json_int(text: str):
    digits = len(text) - (text[0] == "-")
    return _LongInteger(digits) if digits > _JSON_INT_DIGITS else int(text)


def _digits(n: int) -> int:
    """Decimal digits of ``n`` from its bit length, never through str() (which Python refuses past
    4,300 digits and which takes quadratic time)."""
    n = abs(n)
    if n < 10:
        return 1
    d = int(n.bit_length() * 0.30102999566398120)  # log10(2)
    return d + 1 if n >= 10**d else d


def shown(value) -> str:
    """A received value as a message shows it, in at most about 60 characters: an integer beyond 20
    digits by its digit count, other numbers and text shortened; never str() of an unbounded integer."""
    from decimal import Decimal
    from fractions import Fraction

    if isinstance(value, bool) or value is None:
        return repr(value)
    if isinstance(value, _LongInteger):
        return f"an integer of {value.digits} digits"
    if isinstance(value, int):
        return str(value) if abs(value) < 10**20 else f"an integer of {_digits(value)} digits"
    if isinstance(value, Fraction):
        return f"the fraction {shown(value.numerator)} / {shown(value.denominator)}"
    if isinstance(value, Decimal):
        sign, digits, exp = value.as_tuple()
        if isinstance(exp, int) and len(digits) > 20:
            return f"a decimal of {len(digits)} digits times 10^{exp}"
        text = str(value)
    elif isinstance(value, (float, str)):
        text = repr(value)
    elif isinstance(value, (bytes, bytearray)):
        return f"a byte string of {len(value)} bytes"
    elif isinstance(getattr(value, "tag", None), int):  # cbor2's CBORTag: a tag it has no reader for
        return f"CBOR tag {shown(value.tag)}"
    else:
        return f"a value of type {type(value).__name__}"
    return text if len(text) <= 60 else f"{text[:40]}... ({len(text)} characters)"


def _number(v, parts):
    """(v as an int or a finite float, None) or (None, the problem): CBOR's decimal fractions,
    bigfloats and rationals become floats; numbers no 64-bit float holds (1e5000, 10**400) are refused."""
    if isinstance(v, int) and not isinstance(v, bool):
        if abs(v) <= _FLOAT_MAX_INT:
            return v, None
        return None, SampleProblem(json_path(parts), "finite", f"{shown(v)} is beyond what a 64-bit float holds")
    try:
        f = float(v)
    except (OverflowError, ValueError, TypeError):
        f = math.inf
    if not math.isfinite(f):
        return None, SampleProblem(json_path(parts), "finite", f"{shown(v)} is not a finite number")
    return f, None


_FLOAT_MAX_INT = int(sys.float_info.max)
#: what a decoded sample may hold besides objects and arrays: JSON's own types
_JSON_SCALARS = (str, int, float, bool, type(None))


def _non_finite(obj, parts, depth=0):
    """The first problem that makes ``obj`` no JSON document of finite numbers, or None: a number that
    is not finite (NaN, inf, or beyond a 64-bit float), nesting beyond MAX_DEPTH, a map key that is not
    text or a value JSON has no form for (CBOR's byte strings, tags, dates, sets, undefined). Numbers
    that are not int or float (CBOR's Decimal and Fraction) are replaced by floats in place. Messages
    show values through :func:`shown`: an integer is never turned into text whole."""
    if depth > MAX_DEPTH:
        return SampleProblem(json_path(parts), "maxDepth", f"nested deeper than {MAX_DEPTH} levels")
    if isinstance(obj, dict):
        for k in obj:
            if not isinstance(k, str):
                return SampleProblem(json_path(parts), "propertyNames",
                                     f"a key that is {shown(k)}, not text (JSON keys are text)")
    items = obj.items() if isinstance(obj, dict) else enumerate(obj) if isinstance(obj, list) else ()
    for k, v in items:
        t = type(v)  # JSON's own scalars, finite, passed at once (an isinstance of the numbers ABC is slow):
        if t is str or t is float and math.isfinite(v) or t is bool or v is None \
                or t is int and -_FLOAT_MAX_INT <= v <= _FLOAT_MAX_INT:  # what the branches below would pass
            continue
        if isinstance(v, (dict, list)):
            bad = _non_finite(v, parts + (k,), depth + 1)
            if bad:
                return bad
        elif isinstance(v, _LongInteger):
            return SampleProblem(json_path(parts + (k,)), "finite", f"{shown(v)} is beyond what a 64-bit float holds")
        elif isinstance(v, numbers.Number) and not isinstance(v, bool) \
                and not (isinstance(v, float) and math.isfinite(v)) \
                and not (isinstance(v, int) and abs(v) <= _FLOAT_MAX_INT):
            value, bad = _number(v, parts + (k,))
            if bad:
                return bad
            obj[k] = value
        elif not isinstance(v, _JSON_SCALARS):
            return SampleProblem(json_path(parts + (k,)), "type", f"{shown(v)}, which JSON has no form for")
    return None


def _order_key(error):
    return tuple((0, p) if isinstance(p, int) else (1, str(p)) for p in error.absolute_path)


def sample_problems(sample) -> list[SampleProblem]:
    """Every reason ``sample`` (a decoded dict) breaks the schema, sorted by path; empty when valid."""
    if not isinstance(sample, dict):
        kind = "int" if isinstance(sample, _LongInteger) else type(sample).__name__
        return [SampleProblem("$", "type", f"a sample is a JSON object, got {kind}")]
    bad = _non_finite(sample, ())
    if bad:
        return [bad]
    fast = _fast_is_valid()  # jsonschema's validator is built only for a sample this refuses (or no fast path):
    if fast is not None and fast(sample):  # importing jsonschema and checking the schema is 0.2 s of a process
        return _timecode_problems(sample)
    v = _validator()
    if fast is None and v.is_valid(sample):
        return _timecode_problems(sample)
    out = []
    for e in sorted(v.iter_errors(sample), key=_order_key):
        # anyOf/oneOf name the branch that came closest; report it where it is more precise
        best = e
        if e.context:
            import jsonschema.exceptions

            best = jsonschema.exceptions.best_match([e]) or e
        out.append(SampleProblem(json_path(best.absolute_path), str(best.validator), _cut(best.message)))
    return out or _timecode_problems(sample)  # jsonschema's word is the last (fastjsonschema said no)


def _cut(message: str) -> str:
    return message if len(message) <= MAX_MESSAGE_CHARS else message[:MAX_MESSAGE_CHARS - 24] + \
        f"... ({len(message)} characters)"


def _timecode_problems(sample) -> list[SampleProblem]:
    """A valid sample's timecode counting a frame its own rate never reaches: frames must be below
    ceil(frameRate) (camdkit's ``Timecode`` model refuses the rest; the schema alone allows 0-119)."""
    tc = sample.get("timing", {}).get("timecode")
    if not tc:
        return []
    num, denom = tc["frameRate"]["num"], tc["frameRate"]["denom"]
    if type(num) is int and type(denom) is int:
        limit = -(-num // denom)  # ceil(num / denom) in integers, without a Fraction made per sample
    else:  # the schema's integers written as floats (30.0): as before
        from fractions import Fraction

        limit = math.ceil(Fraction(num, denom))
    if tc["frames"] >= limit:
        return [SampleProblem("$.timing.timecode.frames", "frameRate",
                              f"frame {tc['frames']} does not exist at {limit} frames a second (0 to {limit - 1})")]
    return []


def validate_sample(sample) -> dict:
    """Return ``sample`` when it is a valid OpenTrackIO 1.0.1 sample, else raise :class:`SampleError`."""
    problems = sample_problems(sample)
    if problems:
        raise SampleError(problems)
    return sample


def _reject_constant(name):
    raise ValueError(f"{name} is not a JSON number")


def decode_sample(payload, encoding: str = "json", *, validate: bool = True) -> dict:
    """Decode one sample from ``payload`` bytes (``encoding`` "json" or "cbor") and validate it.

    Undecodable bytes raise :class:`SampleError` with the path ``$`` and the rule ``json``/``cbor``.
    """
    if not isinstance(payload, (bytes, bytearray, memoryview)):
        require_type("payload", payload, (bytes, bytearray, memoryview))
    if encoding not in ("json", "cbor"):
        raise InputError(f"encoding must be json or cbor, got {encoding!r}")
    cbor2 = _cbor2() if encoding == "cbor" else None  # a missing extra is said as such, not as a malformed sample
    try:
        if encoding == "json":
            obj = json.loads(bytes(payload).decode("utf-8"), parse_constant=_reject_constant, parse_int=_json_int)
        else:
            obj = cbor2.loads(bytes(payload))
    except (ValueError, UnicodeDecodeError, RecursionError) as exc:
        raise SampleError([SampleProblem("$", encoding, f"not {encoding.upper()}: {str(exc)[:120]}")]) from None
    except Exception as exc:  # noqa: BLE001 - cbor2's decoder raises its own classes (CBORDecodeError, ...)
        raise SampleError([SampleProblem("$", encoding, f"not {encoding.upper()}: {str(exc)[:120]}")]) from None
    if validate:
        validate_sample(obj)
    return obj


def encode_sample(sample, encoding: str = "json") -> bytes:
    """``sample`` as compact JSON (UTF-8) or CBOR bytes (no validation; see :func:`validate_sample`)."""
    require_type("sample", sample, dict)
    if encoding == "json":
        try:
            return json.dumps(sample, separators=(",", ":"), allow_nan=False).encode("utf-8")
        except ValueError as exc:
            raise InputError(f"the sample holds a number JSON cannot carry: {exc}") from None
    if encoding == "cbor":
        return _cbor2().dumps(sample)
    raise InputError(f"encoding must be json or cbor, got {encoding!r}")
