"""What commands print: versioned JSON documents, tables for people, CSV for spreadsheets.

- **JSON** (``--json``): :func:`document` wraps a command's payload with ``schema``
  (``physcam.NAME``), ``version`` and ``units``; a JSON Schema for every document ships in
  ``physcam/cli/schemas/NAME.schema.json`` (:func:`schema_file`), and
  ``tests/cli/test_cli_contract.py`` validates each command's output against it.
- **Tables**: :class:`Table` renders as a rich table at a terminal and as plain, complete,
  aligned text when piped or redirected (never cut at 80 columns).
- **CSV** (``--csv``): :func:`print_csv` writes the rows of the JSON document (numbers at full
  precision, an empty cell for null, lists joined with ``;``), so CSV and JSON agree cell by cell;
  under ``--units ft`` its scene distances are decimal feet in columns named ``*_ft``
  (:func:`csv_in_units`, the one rule for every command's CSV, docs/cli.md "Units").
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

__all__ = ["document", "emit_json", "schema_file", "SCHEMA_DIR", "Table", "print_table", "print_csv",
           "csv_text", "csv_in_units", "scene_distance_column", "add_output_options", "LENGTH_UNITS", "save_plot"]

SCHEMA_DIR = Path(__file__).resolve().parent / "schemas"
#: The units most documents use: lengths in mm, angles in degrees.
LENGTH_UNITS = {"length": "mm", "angle": "degree"}


def document(name: str, payload: dict, *, version: int = 1, units: dict | None = None) -> dict:
    """``payload`` as a versioned document: ``{"schema": "physcam.NAME", "version", "units", ...}``.

    ``units`` says the unit of each kind of number in the payload (default :data:`LENGTH_UNITS`).
    Raise a new ``version`` when a key changes meaning or goes; adding keys keeps it.
    """
    if not isinstance(payload, dict):
        raise TypeError(f"a document's payload is a dict, got {type(payload).__name__}")
    clash = {"schema", "version", "units"} & set(payload)
    if clash:
        raise ValueError(f"the payload of {name} already has {sorted(clash)}: rename them")
    return {"schema": f"physcam.{name}", "version": int(version),
            "units": dict(LENGTH_UNITS if units is None else units), **payload}


def schema_file(schema: str) -> Path:
    """The JSON Schema file of a document's ``schema`` name (``physcam.NAME``)."""
    name = schema.removeprefix("physcam.")
    return SCHEMA_DIR / f"{name}.schema.json"


def emit_json(doc: dict) -> None:
    """Print a :func:`document` (or a document with the same envelope) as JSON on stdout."""
    from ._common import print_json

    if not (isinstance(doc, dict) and {"schema", "version", "units"} <= set(doc)):
        raise ValueError("emit_json prints documents: build one with physcam.cli._output.document")
    print_json(doc)


def add_output_options(p, *, json: bool = True, csv: bool = False, what: str = "the result") -> None:
    """``--json`` (and ``--csv``) with the same help everywhere."""
    if json:
        p.add_argument("--json", action="store_true",
                       help=f"print {what} as JSON (versioned: schema, version, units; lengths in mm)")
    if csv:
        p.add_argument("--csv", action="store_true",
                       help="print the table as CSV (the JSON rows: full precision, empty cell for none)")


# ---- tables -----------------------------------------------------------------------------------
class Table:
    """A table of text cells: rich at a terminal, plain aligned text otherwise."""

    def __init__(self, title: str | None = None, columns=(), *, justify=None):
        self.title = title
        self.columns = [str(c) for c in columns]
        self.justify = list(justify) if justify is not None else ["left"] * len(self.columns)
        self.rows: list[list[str]] = []

    def add_column(self, header: str, justify: str = "left") -> None:
        self.columns.append(str(header))
        self.justify.append(justify)

    def add_row(self, *cells) -> None:
        if len(cells) != len(self.columns):
            raise ValueError(f"a row of {len(cells)} cells in a table of {len(self.columns)} columns")
        self.rows.append(["" if c is None else str(c) for c in cells])

    def rich(self):
        from rich.table import Table as RichTable

        t = RichTable(title=self.title, show_header=True, header_style="bold")
        for c, j in zip(self.columns, self.justify):
            t.add_column(c, justify=j, overflow="fold")
        for r in self.rows:
            t.add_row(*r)
        return t

    def plain(self) -> str:
        """Aligned columns separated by two spaces, every cell whole; the title on the first line."""
        cols = len(self.columns)
        widths = [max([len(self.columns[i])] + [len(r[i]) for r in self.rows]) for i in range(cols)]

        def line(cells):
            out = []
            for i, c in enumerate(cells):
                last = i == cols - 1
                if self.justify[i] == "right":
                    out.append(c.rjust(widths[i]))
                else:
                    out.append(c if last else c.ljust(widths[i]))
            return "  ".join(out).rstrip()

        lines = [self.title] if self.title else []
        lines.append(line(self.columns))
        lines += [line(r) for r in self.rows]
        return "\n".join(lines) + "\n"


def print_table(table: Table) -> None:
    """At a terminal a rich table; piped or redirected, :meth:`Table.plain` (complete, no box)."""
    if sys.stdout.isatty():
        from ._common import console

        console().print(table.rich())
    else:
        sys.stdout.write(table.plain())


# ---- CSV --------------------------------------------------------------------------------------
def _cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(float(v)) if math.isfinite(v) else ""
    if isinstance(v, (list, tuple)):
        return ";".join(_cell(x) for x in v)
    return str(v)


def _scalar(v) -> bool:
    if isinstance(v, (list, tuple)):
        return all(_scalar(x) and not isinstance(x, (list, tuple)) for x in v)
    return v is None or isinstance(v, (str, int, float, bool))


def csv_text(rows, columns=None) -> str:
    """Rows (dicts) as CSV text: ``columns`` (default: every key whose values are scalars or lists of
    scalars, in order of first appearance), numbers at full precision (``repr``), an empty cell for
    None, lists joined with ``;``."""
    import csv
    import io

    rows = list(rows)
    if columns is None:
        columns = []
        for r in rows:
            for k, v in r.items():
                if k not in columns and _scalar(v):
                    columns.append(k)
        columns = [k for k in columns if all(_scalar(r.get(k)) for r in rows)]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for r in rows:
        w.writerow([_cell(r.get(k)) for k in columns])
    return buf.getvalue()


#: Words of a column's name (before ``_from_...`` and ``_mm``) that make it a distance in the scene: a focus
#: mark, a limit or the depth of the depth of field, a subject's or a light's distance, a close focus.
_SCENE_WORDS = frozenset({"focus", "near", "far", "hyperfocal", "total", "depth", "closest", "subject", "light",
                          "sharpest", "object", "distance"})
#: ...and the words that keep a length inside the camera, in mm whatever the units (docs/cli.md: focal length,
#: principal planes, pupil, CoC, sensor): the back focus, a focal length, the image and the film side, the
#: lens's track, a z coordinate along the axis.
_CAMERA_WORDS = frozenset({"back", "focal", "flange", "image", "film", "track", "z"})


def scene_distance_column(name: str) -> bool:
    """Whether a CSV column ``name`` (a JSON key) is a scene distance, which ``--units ft`` gives in feet:
    ``focus_from_film_mm``, ``near_from_film_mm``, ``dof_total_mm``, ``closest_focus_mm``, ``total_mm``,
    ``bokeh_light_from_film_mm`` are; ``entrance_pupil_from_film_mm``, ``efl_mm``, ``back_focus_mm``,
    ``focal_length_mm``, ``image_height_mm`` are not (what the commands' tables print with
    :func:`physcam.units.format_distance`, and what they print in mm)."""
    if not name.endswith("_mm"):
        return False
    words = name[:-3].split("_from_")[0].split("_")
    return bool(_SCENE_WORDS.intersection(words)) and not _CAMERA_WORDS.intersection(words)


def csv_in_units(rows, units: str = "m") -> list[dict]:
    """``rows`` (the JSON document's, in mm) as ``--csv`` writes them under ``units``: as they are in metres; in
    feet (``ft``) every :func:`scene_distance_column` in decimal feet (the millimetres / 304.8, the
    international foot) under its name with ``_ft`` for ``_mm``, every other column as it is."""
    rows = list(rows)
    if units != "ft":
        return rows
    out = []
    for r in rows:
        q = {}
        for k, v in r.items():
            if scene_distance_column(k):
                q[k[:-3] + "_ft"] = _feet(v)
            else:
                q[k] = v
        out.append(q)
    return out


def _feet(v):
    """Millimetres (a number, or a list of them; None stays None) in decimal feet."""
    if isinstance(v, (list, tuple)):
        return [_feet(x) for x in v]
    return v / 304.8 if isinstance(v, (int, float)) and not isinstance(v, bool) else v


def print_csv(rows, columns=None, *, units: str = "m") -> None:
    """Write :func:`csv_text` of ``rows`` in ``units`` (:func:`csv_in_units`) to stdout."""
    rows = csv_in_units(rows, units)
    if columns is not None and units == "ft":
        columns = [k[:-3] + "_ft" if scene_distance_column(k) else k for k in columns]
    sys.stdout.write(csv_text(rows, columns))


# ---- plots ------------------------------------------------------------------------------------
def save_plot(result, path, *, force: bool = False, context: str = "", units: str | None = None):
    """Save an analysis result's figure (``result.plot(None)``) with ``context`` (the shot: f-stop,
    focus, sensor) as a line under it, so a plot says what it is of. ``units`` (m or ft) reaches
    every plot that draws scene distances (its ``plot`` takes ``units``); image-side millimetres
    (film coordinates, spot sizes, lp/mm) stay metric."""
    import inspect

    from ..figures import CONTEXT_RECT, context_line, figure_style, save_figure

    takes_units = units is not None and "units" in inspect.signature(result.plot).parameters
    with figure_style():  # the context line too is physcam's (this module loads no figure code for `report`)
        fig = result.plot(None, units=units) if takes_units else result.plot(None)
        if context:
            context_line(fig, context)
            fig.tight_layout(rect=CONTEXT_RECT)
        return save_figure(fig, path, force=force)
