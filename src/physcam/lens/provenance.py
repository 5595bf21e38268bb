"""Where a lens file's numbers come from: the ``[provenance]`` record of physcam lens TOML.

A prescription's numbers are facts taken from a primary source (a patent's example, a book's
table, a maker's data sheet); the file that carries them has a licence of its own. The record
says which source, who entered the numbers from what and when, what was compared with what to
check them, what had to be assumed, and the file's licence (docs/lens-formats.md, "Provenance")::

    [provenance]
    source = "US 2,673,491 (A. W. Tronnier), example 1"     # the primary source itself
    source_url = "https://patents.google.com/patent/US2673491A/en"
    licence = "CC0-1.0"                  # SPDX identifier of this file; NOASSERTION: unresolved
    transcribed = "2026-05-04"           # ISO date the numbers were entered
    transcribed_by = "physcam contributors"
    transcribed_from = "the primary source"   # or what else the numbers were read from
    primary_source_checked = true        # every number compared with the primary source itself
    checked = "2026-05-04"
    checked_by = "physcam contributors"
    checks = ["EFL: stated 100.0 mm, paraxial 100.02 mm (d line), optiland 100.02 mm", ...]
    assumptions = ["glass: ...", "stop: ...", "semi-diameters: ..."]
    maker_data = ["T-stop: ..., close focus: ... (the maker's page or sheet)"]

``source``, ``licence`` and ``notes`` are :class:`~physcam.lens.prescription.LensMetadata`
fields; every other key lives in ``Prescription.extras`` as ``"provenance.<key>"`` (JSON), where
the readers and writers of other formats carry it unchanged. :func:`provenance_of` gathers them.
"""

from __future__ import annotations

import datetime
import json
import re

from .._record import field_names, record
from ..errors import LensFileError
from .prescription import Prescription, takes_prescription

__all__ = ["Provenance", "provenance_of", "check_provenance_table", "primary_source_claim_gaps", "TEXT_KEYS",
           "DATE_KEYS", "LIST_KEYS", "UNRESOLVED_LICENCE", "ORDER", "PRIMARY_SOURCE_CHECK"]

#: How a ``checks`` line about the primary source itself begins (``"primary source: ..."``).
PRIMARY_SOURCE_CHECK = "primary source:"
#: Words that name a place inside a source: a patent's example, table, claim or column, a book's page or
#: figure, a design file's revision.
#: (patterns compiled by ``re`` on first use: reading a lens never needs them)
_PLACE = (r"\b(example|embodiment|table|claim|column|col\.|fig\.?|figure|p\.|pp\.|page|revision|rev\.|"
          r"beispiel|tabelle)"
          r"\s*(\d+|[IVX]+\b|[A-Z]\b)")
_DECIMAL = r"[-+]?\d+\.\d+"
_COMPARED = r"\b(against|equal|equals|match|matches|agree|agrees|differ|differs)\b"

#: The SPDX value of a file whose licence nobody has established (its numbers came from a file
#: under another licence and were not re-entered from the primary source).
UNRESOLVED_LICENCE = "NOASSERTION"

TEXT_KEYS = ("source", "source_url", "licence", "notes", "transcribed_by", "transcribed_from", "checked_by",
             "original_file", "original_format")
DATE_KEYS = ("transcribed", "checked")
LIST_KEYS = ("checks", "assumptions", "maker_data", "corrections", "aliases")
BOOL_KEYS = ("primary_source_checked",)
#: The order physcam TOML writes the keys in (others follow, sorted).
ORDER = ("source", "source_url", "licence", "transcribed", "transcribed_by", "transcribed_from",
         "primary_source_checked", "checked", "checked_by", "checks", "assumptions", "maker_data", "notes",
         "corrections", "aliases", "original_file", "original_format")


@record
class Provenance:
    """A lens file's provenance (module notes); None or () where the file does not say."""

    source: str | None = None
    source_url: str | None = None
    licence: str | None = None
    notes: str | None = None
    transcribed: str | None = None
    transcribed_by: str | None = None
    transcribed_from: str | None = None
    primary_source_checked: bool | None = None
    checked: str | None = None
    checked_by: str | None = None
    checks: tuple[str, ...] = ()
    assumptions: tuple[str, ...] = ()
    maker_data: tuple[str, ...] = ()
    corrections: tuple[str, ...] = ()
    aliases: tuple[str, ...] = ()
    original_file: str | None = None
    original_format: str | None = None

    @property
    def licence_resolved(self) -> bool:
        """True when the file states a licence other than NOASSERTION."""
        return bool(self.licence) and self.licence != UNRESOLVED_LICENCE

    def summary(self) -> str:
        """One line for people: the source and the licence, and whether the numbers were checked."""
        checked = {True: "checked against it", False: "not checked against it", None: "check not recorded"}
        return (f"{self.source or 'source not given'} ({checked[self.primary_source_checked]}); "
                f"licence {self.licence or 'not given'}")

    def to_dict(self) -> dict:
        out = {}
        for name in field_names(self):
            v = getattr(self, name)
            out[name] = list(v) if isinstance(v, tuple) else v
        return out


@takes_prescription
def provenance_of(prescription: Prescription) -> Provenance:
    """The provenance record of ``prescription`` (its metadata and ``provenance.*`` extras)."""
    m = prescription.metadata
    found = {"source": m.source, "licence": m.licence, "notes": m.notes}
    names = set(field_names(Provenance))
    for k, v in prescription.extras:
        key = k[len("provenance."):] if k.startswith("provenance.") else None
        if key in names and key not in found:
            value = json.loads(v)
            found[key] = tuple(str(x) for x in value) if key in LIST_KEYS and isinstance(value, list) else value
    return Provenance(**found)


def _iso_date(value: str) -> bool:
    try:
        return datetime.date.fromisoformat(value).isoformat() == value
    except ValueError:
        return False


def check_provenance_table(prov: dict, path=None) -> None:
    """Refuse a ``[provenance]`` table whose known keys have the wrong kind of value (file named):
    texts are strings, ``transcribed``/``checked`` ISO dates (YYYY-MM-DD), lists lists of strings,
    ``primary_source_checked`` true or false. Other keys are kept as they are."""
    from ..errors import require_type

    require_type("prov", prov, dict, "the [provenance] table of a lens TOML, as tomllib reads it")
    for key, v in prov.items():
        where = f"[provenance] {key}"
        if key in TEXT_KEYS and not isinstance(v, str):
            raise LensFileError(f"{where} must be a string, got {v!r}", path)
        if key in DATE_KEYS and not (isinstance(v, str) and _iso_date(v)):
            raise LensFileError(f"{where} must be a date as YYYY-MM-DD, got {v!r}", path)
        if key in LIST_KEYS and not (isinstance(v, list) and all(isinstance(x, str) for x in v)):
            raise LensFileError(f"{where} must be a list of strings, got {v!r}", path)
        if key in BOOL_KEYS and not isinstance(v, bool):
            raise LensFileError(f"{where} must be true or false, got {v!r}", path)


def primary_source_claim_gaps(prov: Provenance) -> list[str]:
    """What a record that says ``primary_source_checked = true`` leaves unsaid, one sentence each
    (empty when the claim is backed, or not made): the source must name the place in it (a patent's
    example or table, a book's page, a design's revision), ``checked`` and ``checked_by`` who checked
    and when, and one ``checks`` line starting ``primary source:`` must name that place and the
    numbers compared (a decimal number and ``against``/``equal``/``match``/``differ``). A ``primary
    source: not reached`` line contradicts the claim."""
    from ..errors import require_type

    require_type("prov", prov, Provenance, "physcam.lens.provenance.provenance_of(lens)")
    if prov.primary_source_checked is not True:
        return []
    gaps = []
    if not (prov.source and re.search(_PLACE, prov.source, re.IGNORECASE)):
        gaps.append("the source does not name the example, table or page the numbers were compared with")
    if not (prov.checked and prov.checked_by):
        gaps.append("checked and checked_by do not say when and by whom")
    lines = [c for c in prov.checks if c.lower().startswith(PRIMARY_SOURCE_CHECK)]
    if any("not reached" in c for c in lines):
        gaps.append("a checks line says the primary source was not reached")
    elif not any(re.search(_PLACE, c, re.IGNORECASE) and re.search(_DECIMAL, c) and re.search(_COMPARED, c, re.IGNORECASE)
                 for c in lines):
        gaps.append(f"no checks line '{PRIMARY_SOURCE_CHECK} ...' names the table or example and the numbers compared "
                    "(radii, gaps, nd, Vd, stated EFL and f-number)")
    return gaps
