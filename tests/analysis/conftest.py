"""tests/analysis/ mirrors src/physcam/analysis/ (one folder per package); the oracles the packages'
tests share (_forward_chief, _image_quality, _snell, _charts, _analysis_lenses) stay here, importable
from every folder below."""

import sys
from pathlib import Path

HERE = str(Path(__file__).resolve().parent)
if HERE not in sys.path:
    sys.path.insert(0, HERE)
