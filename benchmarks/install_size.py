"""Benchmark: the size of an install, each distribution's share (issue 47: `physcam[fast]` under 300 MB).

Builds the wheel from this tree, makes a new virtual environment without pip (`python -m venv
--without-pip`) in a scratch folder, installs the wheel with the given extras there with this
environment's pip (`pip --python`, constraints.txt's versions; pip byte-compiles, as a user's pip
does) and prints, per installed distribution, the bytes of the files its `RECORD` lists (MB = 1e6),
then where the bulk sits inside (bytecode, test suites, static libraries nobody loads). The venv's own
pip and setuptools are not in the figure (`python -m venv` adds 22.3 MB of them on Python 3.11, pip
alone on 3.12 and later): they are printed apart with `--venv-tools`.

It also says whether the install has physcam's compiled tracing kernel (the C extension built into a
platform wheel: the fast path without numba, issue 47's install row) and what "auto" traces with there
(``python -m physcam.trace.kernels`` run in the venv).

    .venv/bin/python benchmarks/install_size.py --extras fast --scratch /tmp/r8-size/bench
    .venv/bin/python benchmarks/install_size.py --extras '' --scratch /tmp/r21-size   # the core alone
    .venv/bin/python benchmarks/install_size.py --measure /tmp/r8-size/fast     # an existing venv
"""

from __future__ import annotations

import argparse
import csv
import importlib.metadata as md
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GOAL_MB = 300.0


def _mb(paths) -> float:
    return sum(p.stat().st_size for p in paths if p.is_file() and not p.is_symlink()) / 1e6


def site_packages(venv: Path) -> Path:
    return next(venv.glob("lib/python3*/site-packages"))


def distribution_sizes(site: Path) -> list[tuple[float, str]]:
    """(MB, "name version") for each distribution in ``site``, from its RECORD, largest first."""
    seen, rows = set(), []
    for dist in md.distributions(path=[str(site)]):
        files = set()
        for row in csv.reader((dist.read_text("RECORD") or "").splitlines()):
            path = (site / row[0]).resolve()
            if path not in seen:
                files.add(path)
        seen |= files
        rows.append((_mb(files), f"{dist.metadata['Name']} {dist.version}"))
    return sorted(rows, reverse=True)


def bulk(site: Path) -> list[tuple[str, float]]:
    """The parts of an install that no physcam command loads, or that the installer made."""
    tests = [f for d in site.glob("**/tests") if d.is_dir() for f in d.rglob("*")]
    return [("bytecode (__pycache__, compiled by the installer)", _mb(site.rglob("*.pyc"))),
            ("test suites (*/tests, bytecode included)", _mb(tests)),
            ("static libraries and headers (finufft's FFTW: lib64/, include/)",
             _mb([*site.glob("lib64/**/*"), *site.glob("include/**/*")])),
            ("numpy's OpenBLAS and gfortran (numpy.libs)", _mb(site.glob("numpy.libs/*"))),
            ("llvmlite's LLVM (libllvmlite.so)", _mb(site.glob("llvmlite/binding/*.so"))),
            ("matplotlib's fonts (mpl-data/fonts)", _mb(site.glob("matplotlib/mpl-data/fonts/**/*")))]


def fast_path(venv: Path, site: Path) -> str:
    """The compiled C kernel in the install (its file and size) and the kernels it reports."""
    built = sorted(site.glob("physcam/trace/kernels/_ckernel*"))
    built = [p for p in built if p.suffix in (".so", ".pyd")]
    what = (f"compiled C kernel: {built[0].name} ({_mb(built) * 1e3:.0f} kB)" if built
            else "compiled C kernel: none (not built: the numpy kernel traces)")
    p = subprocess.run([str(venv / "bin" / "python"), "-m", "physcam.trace.kernels"], capture_output=True, text=True,
                       cwd=str(venv))
    return what + "\n" + (p.stdout.strip() if p.returncode == 0 else f"(python -m physcam.trace.kernels: {p.stderr})")


def install(extras: str, scratch: Path) -> Path:
    dist = scratch / "dist"
    subprocess.run([sys.executable, "-m", "build", "--wheel", "-o", str(dist), str(ROOT)], check=True,
                   capture_output=True)
    wheel = max(dist.glob("physcam-*.whl"), key=lambda p: p.stat().st_mtime)
    venv = scratch / f"venv-{extras or 'core'}"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", "--clear", str(venv)], check=True)
    spec = f"physcam[{extras}] @ {wheel.as_uri()}" if extras else f"physcam @ {wheel.as_uri()}"
    subprocess.run([sys.executable, "-m", "pip", "--python", str(venv / "bin" / "python"), "install",
                    "--quiet", "-c", str(ROOT / "constraints.txt"), spec], check=True)
    return venv


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--extras", default="fast", help="extras to install ('' for the core alone)")
    ap.add_argument("--scratch", type=Path, help="folder for the wheel and the venv (default: a temporary one)")
    ap.add_argument("--measure", type=Path, help="measure this existing venv instead of installing")
    ap.add_argument("--venv-tools", action="store_true", help="also measure what `python -m venv` itself installs")
    args = ap.parse_args(argv)
    venv = args.measure or install(args.extras, args.scratch or Path(tempfile.mkdtemp(prefix="physcam-size-")))
    site = site_packages(venv)
    rows = distribution_sizes(site)
    total = sum(mb for mb, _ in rows)
    print(f"{venv} ({len(rows)} distributions)\n\n| distribution | MB |\n| --- | --- |")
    for mb, name in rows:
        print(f"| {name} | {mb:.1f} |")
    print(f"| all | **{total:.1f}** |\n")
    for what, mb in bulk(site):
        print(f"{what}: {mb:.1f} MB")
    print(fast_path(venv, site))
    if args.venv_tools:
        with tempfile.TemporaryDirectory() as tmp:
            subprocess.run([sys.executable, "-m", "venv", tmp], check=True)
            tools = sum(mb for mb, _ in distribution_sizes(site_packages(Path(tmp))))
        print(f"`python -m venv`'s own pip (and setuptools): {tools:.1f} MB; with them {total + tools:.1f} MB")
    print(f"goal < {GOAL_MB:.0f} MB: {'met' if total < GOAL_MB else 'not met'} ({total:.1f} MB)")


if __name__ == "__main__":
    main()
