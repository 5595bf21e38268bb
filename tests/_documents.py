"""Checking physcam's --json documents against the JSON Schemas shipped in physcam/cli/schemas."""

from __future__ import annotations

import json
from functools import lru_cache

import jsonschema

from physcam.cli._output import SCHEMA_DIR, schema_file


@lru_cache(maxsize=None)
def validator(schema_name: str):
    path = schema_file(schema_name)
    assert path.is_file(), f"{schema_name}: no schema file {path.name} in {SCHEMA_DIR}"
    schema = json.loads(path.read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def check_document(doc) -> str:
    """Assert ``doc`` carries schema, version and units and validates against its shipped schema;
    return its schema name."""
    assert isinstance(doc, dict), f"a document is a JSON object, got {type(doc).__name__}"
    for key in ("schema", "version", "units"):
        assert key in doc, f"the document lacks {key!r}: {sorted(doc)[:12]}"
    assert isinstance(doc["units"], dict) and all(isinstance(v, str) for v in doc["units"].values())
    errors = sorted(validator(doc["schema"]).iter_errors(doc), key=lambda e: list(e.path))
    assert not errors, f"{doc['schema']}: " + "; ".join(
        f"{'/'.join(map(str, e.path)) or '(top)'}: {e.message[:200]}" for e in errors[:5])
    return doc["schema"]
