"""docs/api.md is what scripts/gen_api_reference.py writes from the current docstrings (issue 26)."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_api_reference_is_current():
    p = subprocess.run([sys.executable, str(ROOT / "scripts" / "gen_api_reference.py"), "--check"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
