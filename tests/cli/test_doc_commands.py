"""Doc examples are tests (issue 15): every ``physcam ...`` command of README.md and docs/*.md runs.

A command is a ``$ physcam ...`` line of a fenced block (a ``console`` block; lines after it that
do not start with ``$`` are its output), or a ``physcam ...`` line of a ``sh`` block; a trailing
``\\`` continues it. The commands of one page run in order, in-process (one interpreter, so numba
compiles once), in a temporary folder of their own: files a page writes are there for its later
commands. A ``$ cat FILE`` in a console block shows a file the page reads: its lines are written
to FILE first. A few input files the pages name are provided (INPUTS); a short list of commands
cannot run here, each with its reason (SKIP); a few run bounded (BOUNDED) or with flags that change how, not
what, they compute (CHEAPER). A command whose shown output is a refusal
(``physcam: error: ...``) must refuse: exit 2. **What a page shows a command print is what it prints**
(issue 39): every number of a console block's shown output is compared with the command's, within
one unit in its last digit (tests/cli/_doc_output.py says how, and how a block states another
tolerance or why it cannot be compared).
"""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
from pathlib import Path

import pytest

from physcam.cli import main

pytestmark = pytest.mark.slow

REPO = Path(__file__).resolve().parents[2]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
FENCE = re.compile(r"^\s*```\s*([\w-]*)")

#: Commands that run bounded here (the flags added), and why: what they do at length is tested apart.
BOUNDED = {
    "characterize": (["--dry-run"], "starts a Dask cluster and computes hundreds of cells (minutes); the plan checks "
                                  "the command line, the grid and every lens against it, and "
                                  "tests/characterize/test_characterize.py computes small grids"),
    "serve": (["--check", "--port", "0"], "serves until Ctrl-C; --check binds the address (any free port here), "
                                          "answers the page and one report in-process and exits (tests/serve drives "
                                          "a running server)"),
}
#: Commands run with flags that change how, not what, they compute (added like :data:`BOUNDED`'s), and why.
CHEAPER = {
    "physcam export blender-extension -o dist/ --lens zeiss_distagon_35mm_f4 --lens dgauss_50mm": (
        ["--workers", "1"], "one process instead of one per core: the zip is the same byte for byte whatever the "
        "number (tests/export/test_blender_extension_build.py), the page shows only its name and lens count, and the "
        "session's extension zip is built by two workers (tests/conftest.py); two spawned Pythons, each importing "
        "physcam and loading its JIT kernels for one lens, were 10 of this page's 17 s of CPU"),
}
#: Commands that cannot run in a test, and why.
SKIP = {
    "physcam defocus render.exr --depth ViewLayer.Depth.Z --lens dgauss_50mm --focus 2m --fstop 2.8 --blades 6 -o dof.exr":
        "needs a render with depth (tests/analysis/defocus/test_defocus.py runs physcam defocus on one)",
    "physcam defocus plate.exr --depth plate_depth.exr --depth-kind inverse --lens dgauss_50mm --focus 3m --fstop 4 -o dof.exr":
        "needs a plate with depth (tests/analysis/defocus/test_defocus.py runs physcam defocus on one)",
    "physcam compare blender --lens dgauss_50mm --focus 2m --fstop 2.8 --light 0.7m --blades 6 -o cmp/":
        "needs Blender's bpy (tests/blender/test_compare.py runs it where Blender is installed)",
    "physcam live record --port 55555 --duration 30 take.usda --report take.csv":
        "listens 30 s for a stream (tests/live/test_cli_live.py records one sent by a second process)",
}

#: Commands shown the same on several pages, run once per test session (the first page to run one keeps its
#: exit status and output; every page that shows it compares its shown output with them): each reads only
#: bundled data (a bundled lens, the sensor table) and the session's empty config, nothing of a page's
#: folder nor a page's lens library, and no later command of these pages reads what it writes (a page
#: that reuses the run has not those files). The ST-maps of 4608x3164 px are 12 s of CPU (README.md and
#: docs/distortion.md), the comparison 2 s (README.md and docs/cli.md). Pages that xdist runs on
#: different workers share the run through the session's folder (:func:`_shared_run`).
SHARED = {
    'physcam distortion --lens zeiss_distagon_35mm_f4 --focus 2m --sensor ALEXA 35 --resolution 4608x3164 --stmap out/ '
    '--fit 3de4 --fit brown --fit nuke --fit usd',
    "physcam compare --lens dgauss_50mm --lens sonnar_50mm_f1_5 --lens tessar_50mm_f2_8 --focus 2m --fstop 2.8 --sensor "
    "S35 -o compare.png",
}
#: {command: (exit status, stdout, stderr)} of the :data:`SHARED` commands run so far in this process
_SHARED_RUNS: dict[str, tuple[int, str, str]] = {}


def _shared_run(key: str, argv: list[str], capsys, tmp_path_factory) -> tuple[int, str, str]:
    """(exit status, stdout, stderr) of the :data:`SHARED` command ``key``: run here by the first page of the
    session to reach it, and kept in the session's folder for the pages on other xdist workers (a worker
    reaching it while another runs it waits for that run, under the command's own lock)."""
    import hashlib

    from _session import session_lock

    if key in _SHARED_RUNS:
        return _SHARED_RUNS[key]
    name = "doc-shared-" + hashlib.sha256(key.encode()).hexdigest()[:16]
    with session_lock(tmp_path_factory, name) as folder:
        kept = folder / f"{name}.json"
        if kept.exists():
            rc, out, err = json.loads(kept.read_text())
        else:
            rc = main(argv[1:])
            out, err = capsys.readouterr()
            kept.write_text(json.dumps([rc, out, err]))
    _SHARED_RUNS[key] = rc, out, err
    return rc, out, err


def _broken_sample(d: Path) -> None:
    sample = json.loads((REPO / "tests/live/data/recommended_dynamic_example.json").read_text())
    sample["lens"]["fStop"] = 0
    sample["transforms"][0]["rotation"]["pan"] = "left"  # the two problems docs/live.md shows
    (d / "broken.json").write_text(json.dumps(sample))


def _take(d: Path) -> None:
    assert main(["usd", "animate", str(d / "take.usda"), "--lens", "dgauss_50mm", "--marks", str(d / "pull.csv"),
                 "--sensor", "ALEXA 35"]) == 0


def _journal(d: Path) -> None:
    """The journal a killed `live record scene12.usda` leaves: its header and 24 samples."""
    from physcam.live.camera import camera_samples
    from physcam.live.journal import Journal
    from physcam.optics.sensors import find_sensor

    j = Journal.create(d / "scene12.usda", {"output": "scene12.usda", "report": None, "options": {}})
    for i, s in enumerate(camera_samples(sensor=find_sensor("ALEXA 35"), frames=24, rate=24, focus_mm=2000.0,
                                         fstop=2.8, focal_length_mm=35.0)):
        j.add_sample(s, i, "cbor")
    j.close()


def _render(d: Path) -> None:
    """A small render with depth (R, G, B, Z): docs/defocus.md shows one refused as its own output."""
    import numpy as np
    import OpenEXR

    rgb = np.full((8, 12), 0.5, np.float32)
    with OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION},
                      {"R": rgb, "G": rgb, "B": rgb, "Z": np.full((8, 12), 2000.0, np.float32)}) as f:
        f.write(str(d / "render.exr"))


#: Input files the pages name without showing them (a focus pull, a broken sample, a take, a journal,
#: a render with depth).
INPUTS = [
    lambda d: (d / "pull.csv").write_text("frame,focus,fstop\n1,2m,2.8\n12,2.5m,2.8\n24,3m,4\n"),
    _broken_sample,
    _take,
    _journal,
    _render,
    lambda d: (d / "tests").mkdir() or os.symlink(REPO / "tests" / "data", d / "tests" / "data"),
]


def doc_commands(path: Path):
    """(line number, command text, {file: content}, expected exit) of every command of a page, in order."""
    out, files = [], {}
    lines = path.read_text(encoding="utf-8").splitlines()
    lang, cat, i = None, None, 0
    while i < len(lines):
        line = lines[i]
        m = FENCE.match(line)
        if m:
            lang = None if lang is not None else (m.group(1) or "text")
            cat = None
            i += 1
            continue
        if lang is not None:
            s = line.strip()
            if s.startswith("$ "):
                cat = None
                s = s[2:]
                if s.startswith("cat "):
                    cat = s[4:].strip()
                    files[cat] = []
            elif cat is not None:
                files[cat].append(line)
                s = ""
            elif lang not in ("sh", "shell", "bash"):
                if s.startswith("physcam: error:") and out:  # the shown output of the last command: a refusal
                    out[-1][3] = 2
                s = ""
            if s.startswith("physcam ") or s == "physcam":
                start = i + 1
                while s.endswith("\\") and i + 1 < len(lines):
                    i += 1
                    s = s[:-1].rstrip() + " " + lines[i].strip()
                # a checker that finds a problem exits 1: the page says so on the line, `# exits 1`
                code = re.search(r"#\s*exits (\d)\s*$", s)
                out.append([start, s, {k: "\n".join(v) + "\n" for k, v in files.items()},
                            int(code.group(1)) if code else 0])
        i += 1
    return out


def shown_outputs(path: Path) -> dict:
    """{start line of a ``$ physcam`` command: (its shown output lines, checked, relative tolerance)} of a
    page's console blocks (tests/cli/_doc_output.py)."""
    from _doc_output import block_rule

    lines = path.read_text(encoding="utf-8").splitlines()
    out, lang, rule, current, i = {}, None, (True, None), None, 0
    while i < len(lines):
        line = lines[i]
        m = FENCE.match(line)
        if m:
            if lang is None:
                lang = m.group(1) or "text"
                prev = next((lines[j] for j in range(i - 1, -1, -1) if lines[j].strip()), "")
                rule = block_rule(prev)
            else:
                lang = None
            current = None
        elif lang == "console":
            st = line.strip()
            if st.startswith("$ "):
                current = None
                if st[2:].startswith("physcam"):
                    start = i + 1
                    while lines[i].rstrip().endswith("\\") and i + 1 < len(lines):
                        i += 1
                    current = out.setdefault(start, ([], *rule))[0]
            elif current is not None:
                current.append(line)
        i += 1
    return {k: v for k, v in out.items() if v[0]}


def argv_of(text: str) -> list[str]:
    """The command's words; a comment starts at a ``#`` after a space (``plates/A.####.exr`` is a word)."""
    return shlex.split(re.sub(r"(^|\s)#.*$", "", text))


def test_commands_live_in_fenced_blocks():
    """A `$ physcam` line outside a fenced block would escape this test: keep examples fenced."""
    stray = []
    for page in PAGES:
        inside = False
        for n, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            if FENCE.match(line):
                inside = not inside
            elif not inside and line.strip().startswith("$ physcam"):
                stray.append(f"{page.name}:{n}")
    assert not stray, f"put these examples in a ```console block: {stray}"


def test_the_pages_have_commands():
    found = {p.name: len(doc_commands(p)) for p in PAGES}
    assert found["README.md"] >= 30, found
    assert sum(found.values()) >= 70, found
    known = {" ".join(argv_of(c)) for p in PAGES for _, c, _, _ in doc_commands(p)}
    for cmd in SKIP:
        assert cmd in known, f"SKIP names a command no page has any more: {cmd}"
    for cmd in CHEAPER:
        assert cmd in known, f"CHEAPER names a command no page has any more: {cmd}"
    for cmd in SHARED:
        pages = [p.name for p in PAGES if cmd in {" ".join(argv_of(c)) for _, c, _, _ in doc_commands(p)}]
        assert len(pages) >= 2, f"SHARED names a command fewer than two pages show: {cmd} ({pages})"
    refused = [c for p in PAGES for _, c, _, rc in doc_commands(p) if rc == 2]
    assert "physcam live validate broken.json" in refused


def test_technical_examples_are_physically_consistent(capsys):
    """Every datasheet (technical model) example puts the image of its mark on the film: the report's
    focus error stays below 0.05 mm (issue 15: the README's said 60.6 mm)."""
    cmds = [argv_of(c) for p in PAGES for _, c, _, _ in doc_commands(p)]
    tech = [a for a in cmds if a[1:2] == ["report"] and "technical" in a]
    assert tech
    for argv in tech:
        assert main([*argv[1:], "--json"]) == 0
        d = json.loads(capsys.readouterr().out)
        assert abs(d["focus_error_mm"]) < 0.05, (argv, d["focus_error_mm"])


@pytest.mark.parametrize("page", [p for p in PAGES if doc_commands(p)], ids=lambda p: p.name)
def test_every_command_of_the_page_runs(page, tmp_path, capsys, monkeypatch, tmp_path_factory):
    # pages that show no command (architecture, conventions, ...) have nothing to run: not parametrized
    from _doc_output import compare

    cmds = doc_commands(page)
    shown = shown_outputs(page)
    # a page's `physcam lens add` installs into a lens library of the page's own, not the session's
    monkeypatch.setenv("PHYSCAM_LENS_LIBRARY", str(tmp_path / ".physcam-lenses"))
    for make in INPUTS:
        make(tmp_path)
    old = os.getcwd()
    os.chdir(tmp_path)
    done: set[str] = set()
    failures = []
    try:
        for line, text, files, want in cmds:
            argv = argv_of(text)
            key = " ".join(argv)
            if key in SKIP or key in done:  # the same command twice on a page runs once
                continue
            for name, content in files.items():
                Path(name).parent.mkdir(parents=True, exist_ok=True)
                Path(name).write_text(content)
            for a in argv:  # folders a command writes into (lenses/x.usda)
                if "/" in a and a.endswith((".usda", ".usd", ".usdc")) and not Path(a).exists():
                    Path(a).parent.mkdir(parents=True, exist_ok=True)
            argv = [*argv, *BOUNDED.get(argv[1], ([],))[0], *CHEAPER.get(key, ([],))[0]]
            if key in SHARED:
                rc, out, err = _shared_run(key, argv, capsys, tmp_path_factory)
            else:
                rc = main(argv[1:])
                out, err = capsys.readouterr()
            if rc != want:
                failures.append(f"{page.name}:{line}: `{text}` exited {rc} (want {want}): {err.strip()[-400:]}")
            elif "Traceback" in err:
                failures.append(f"{page.name}:{line}: `{text}` printed a traceback")
            elif line in shown and shown[line][1]:
                lines, _, tol = shown[line]
                problems = compare(lines, out, err, tol)
                failures += [f"{page.name}:{line}: `{text}`: {p}" for p in problems]
                if problems:  # what it did print, to put on the page
                    failures.append(f"    it printed: {(out + err)[:1500]!r}")
            done.add(key)
    finally:
        os.chdir(old)
        shutil.rmtree(tmp_path / "tests", ignore_errors=True)
    assert not failures, "\n".join(failures)
