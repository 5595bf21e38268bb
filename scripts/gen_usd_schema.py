#!/usr/bin/env python3
"""Regenerate physcam's codeless USD schema plugin with usd-core's own usdGenSchema.

    python scripts/gen_usd_schema.py            # rewrite src/physcam/usd/plugin/
    python scripts/gen_usd_schema.py --check    # exit 1 if the checked-in files are stale

Source: src/physcam/usd/schema/schema.usda. Output: plugInfo.json and
generatedSchema.usda in src/physcam/usd/plugin/. usdGenSchema ships with usd-core as
the module ``pxr.Usd.usdGenSchema`` (it needs jinja2); it is run in a child process
because it must set USD_DISABLE_PRIM_DEFINITIONS_FOR_USDGENSCHEMA before pxr loads.
A codeless plugin has no library, so the placeholders usdGenSchema leaves in
plugInfo.json are replaced by paths relative to the plugInfo.json itself.
"""

from __future__ import annotations

import argparse
import difflib
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "src" / "physcam" / "usd" / "schema" / "schema.usda"
PLUGIN = ROOT / "src" / "physcam" / "usd" / "plugin"
OUTPUTS = ("plugInfo.json", "generatedSchema.usda")

_PLACEHOLDERS = {
    '"LibraryPath": "@PLUG_INFO_LIBRARY_PATH@"': '"LibraryPath": ""',
    '"ResourcePath": "@PLUG_INFO_RESOURCE_PATH@"': '"ResourcePath": "."',
    '"Root": "@PLUG_INFO_ROOT@"': '"Root": "."',
}


def generate(out_dir: Path, python: str = sys.executable) -> None:
    """Run usdGenSchema on SCHEMA into ``out_dir`` and make plugInfo.json codeless."""
    out_dir.mkdir(parents=True, exist_ok=True)
    proc = subprocess.run(
        [python, "-m", "pxr.Usd.usdGenSchema", "--quiet", str(SCHEMA), str(out_dir)],
        capture_output=True,
        text=True,
    )
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout + proc.stderr)
        raise SystemExit(f"usdGenSchema failed (exit {proc.returncode})")
    info = out_dir / "plugInfo.json"
    text = info.read_text()
    for old, new in _PLACEHOLDERS.items():
        text = text.replace(old, new)
    # Parse it (after the leading comment lines) to fail early on a broken file.
    json.loads("\n".join(line for line in text.splitlines() if not line.lstrip().startswith("#")))
    info.write_text(text)


def check(python: str = sys.executable) -> list[str]:
    """Regenerate into a temporary folder; return unified diffs against the checked-in files."""
    diffs: list[str] = []
    with tempfile.TemporaryDirectory() as tmp:
        generate(Path(tmp), python)
        for name in OUTPUTS:
            new = (Path(tmp) / name).read_text().splitlines(keepends=True)
            cur_path = PLUGIN / name
            cur = cur_path.read_text().splitlines(keepends=True) if cur_path.exists() else []
            if new != cur:
                diffs.append("".join(difflib.unified_diff(cur, new, f"checked-in/{name}", f"regenerated/{name}")))
    return diffs


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="only compare; exit 1 when the plugin is stale")
    args = ap.parse_args(argv)
    if args.check:
        diffs = check()
        for d in diffs:
            sys.stdout.write(d)
        if diffs:
            print("USD schema plugin is stale: run python scripts/gen_usd_schema.py", file=sys.stderr)
            return 1
        print("USD schema plugin is current")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        generate(Path(tmp))
        PLUGIN.mkdir(parents=True, exist_ok=True)
        for name in OUTPUTS:
            shutil.copyfile(Path(tmp) / name, PLUGIN / name)
            print(f"wrote {(PLUGIN / name).relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
