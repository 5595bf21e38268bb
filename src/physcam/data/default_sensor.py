"""The one default sensor of physcam (issue 15): the Python API and the command line agree.

:data:`DEFAULT_SENSOR` names the sensor every command and every public function uses when none is
given; its gate, width x height in mm, is looked up in the bundled table ``physcam/data/sensors.csv``
(the row whose key, name or alias is that name, matched as :func:`physcam.optics.sensors.find_sensor`
matches: case, spaces and punctuation ignored). This module sits at the bottom of the layers, so
``optics/``, ``analysis/``, ``characterize/``, ``usd/`` and ``cli/`` all import it.

>>> DEFAULT_SENSOR, DEFAULT_SENSOR_WIDTH_MM, DEFAULT_SENSOR_HEIGHT_MM
('Super 35', 24.89, 18.66)
>>> DEFAULT_SENSOR_LABEL
'Super 35 (24.89 x 18.66 mm)'
"""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path

__all__ = ["DEFAULT_SENSOR", "DEFAULT_SENSOR_WIDTH_MM", "DEFAULT_SENSOR_HEIGHT_MM", "DEFAULT_SENSOR_MM",
           "DEFAULT_SENSOR_HALF_DIAGONAL_MM", "DEFAULT_SENSOR_LABEL"]

#: The sensor used when none is given (and the user config names none): Super 35 4-perf full aperture.
DEFAULT_SENSOR = "Super 35"


def _norm(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "", text.lower())


def _dimensions_mm(name: str) -> tuple[float, float]:
    """(width, height) in mm of the bundled table's sensor called ``name`` (key, name or alias).

    A plain lookup for the layers below ``onset/`` (which has the full :func:`find_sensor`, with
    suggestions); an unknown name is a ``KeyError``."""
    key = _norm(name)
    text = (Path(__file__).resolve().parent / "sensors.csv").read_text(encoding="utf-8")
    for row in csv.DictReader(text.splitlines()):
        labels = [row["key"], row["name"], *row["aliases"].split(";")]
        if key in {_norm(x) for x in labels if x.strip()}:
            return float(row["width_mm"]), float(row["height_mm"])
    raise KeyError(f"no sensor {name!r} in physcam/data/sensors.csv")


#: Width and height (mm) of :data:`DEFAULT_SENSOR`'s gate, from the bundled table.
DEFAULT_SENSOR_MM: tuple[float, float] = _dimensions_mm(DEFAULT_SENSOR)
DEFAULT_SENSOR_WIDTH_MM, DEFAULT_SENSOR_HEIGHT_MM = DEFAULT_SENSOR_MM
#: Half its diagonal (mm): the image height of the frame's corner (the MTF chart's default reach).
DEFAULT_SENSOR_HALF_DIAGONAL_MM = math.hypot(*DEFAULT_SENSOR_MM) / 2.0
#: How docs and docstrings say it: "Super 35 (24.89 x 18.66 mm)".
DEFAULT_SENSOR_LABEL = f"{DEFAULT_SENSOR} ({DEFAULT_SENSOR_WIDTH_MM:g} x {DEFAULT_SENSOR_HEIGHT_MM:g} mm)"
