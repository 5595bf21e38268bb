"""The page's own solver (serve/static/onset.js) against the CLI on 10,000 random setups.

Each setup is a query as the page sends it to /api/report (the CLI's flags without dashes, values
as typed: "2.5m", "10'6\"", "inf", "hyperfocal", "d/1730", "25um"). The expected answer is the
server's, which is `physcam report --json` (physcam.cli.serve.cli_backend: the CLI's own parser and
document); the page's answer is onset.js's, run by node (or, where node is missing, by the real
Chromium through Playwright). Every number of the page's document must equal the CLI's to 1e-9
relative, every refusal must be a refusal on both sides.
"""

from __future__ import annotations

import json
import math
import random
import shutil
import subprocess
from pathlib import Path

import pytest

from physcam.errors import PhysCamError

STATIC = Path(__file__).resolve().parents[2] / "src" / "physcam" / "serve" / "static"
NODE_HARNESS = Path(__file__).with_name("_onset_node.js")
N_SETUPS = 10_000
RTOL = 1e-9


def run_page_solver(job: dict) -> list:
    """onset.js's answers for ``job`` (sensors and setups): node, or headless Chromium."""
    node = shutil.which("node")
    if node:
        out = subprocess.run([node, str(NODE_HARNESS), str(STATIC)], input=json.dumps(job), capture_output=True,
                             text=True, check=True, timeout=600)
        return json.loads(out.stdout)
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    sync_api = pytest.importorskip("playwright.sync_api", reason="neither node nor playwright is installed")
    if chromium is None:
        pytest.skip("neither node nor chromium is installed: the page's solver cannot run here")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=chromium, args=["--no-sandbox", "--disable-dev-shm-usage"])
        try:
            pg = b.new_page()
            pg.add_script_tag(content=(STATIC / "onset.js").read_text(encoding="utf-8"))
            return pg.evaluate(
                "(job) => { const inf = (x) => (x === 'inf' ? Infinity : x);"
                " const call = (f) => { try { return {ok: true, body: f()}; } catch (e) {"
                " if (e instanceof PhysOnset.ReportError) return {ok: false, body: {error: e.message}}; throw e; } };"
                " return job.calls ? job.calls.map(([n, ...a]) => call(() => PhysOnset[n](...a.map(inf), job.sensors)))"
                " : job.setups.map((q) => PhysOnset.report(q, job.sensors)); }", job)
        finally:
            b.close()


# --- random setups, written as a person types them --------------------------------------------
def _len(rng: random.Random, mm: float) -> str:
    """``mm`` written in one of the ways the page and the CLI read (bare numbers are mm here)."""
    form = rng.randrange(6)
    if form == 0:
        return f"{mm:.6g}"
    if form == 1:
        return f"{mm / 1000:.5g}m"
    if form == 2:
        return f"{mm / 304.8:.5g}ft"
    if form == 3:
        inches = round(mm / 25.4 * 8) / 8
        ft, inch = divmod(inches, 12)
        whole, part = int(inch), round((inch - int(inch)) * 8)
        frac = f" {part}/8" if part else ""
        foot, inch_mark = MARKS[int(mm) % len(MARKS)]  # typed with a phone's marks too (no draw: same setups)
        return f"{int(ft)}{foot} {whole}{frac}{inch_mark}"
    if form == 4:
        return f"{mm / 10:.5g} cm"
    return f"{mm / 25.4:.5g}in"


#: foot and inch marks as typed: ASCII, a phone's smart quotes, primes, a phone's two single quotes for inches
MARKS = [("'", '"'), ("’", "”"), ("′", "″"), ("'", "''"), ("’", "’’"), ("‘", "“")]


def _log_uniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def random_setup(rng: random.Random, sensor_names: list[str]) -> dict:
    q: dict[str, str] = {}
    f = _log_uniform(rng, 8, 400)
    q["focal"] = rng.choice([f"{f:.4g}", f"{f:.4g}mm"])
    if rng.random() < 0.85:
        q["sensor"] = rng.choice(sensor_names)
    else:
        q["sensor-width"], q["sensor-height"] = f"{rng.uniform(5, 60):.3f}", f"{rng.uniform(4, 40):.3f}"
    if rng.random() < 0.35:
        q["coc"] = rng.choice(["d/1500", "d/1000", "d/1730", "cine", "zeiss", "0.025", "0.03", "25um", "0.019mm",
                               "full-frame", "FF", "16mm", "s35", "0.015",
                               f"{rng.uniform(0.005, 0.06):.4f}"])
    if rng.random() < 0.15:
        q["squeeze"] = rng.choice(["1.3", "1.5", "1.8", "2", "1.25"])
    fstop = _log_uniform(rng, 0.9, 32)
    mark = _log_uniform(rng, max(4.2 * f, 250.0), 80_000.0)
    mode = rng.choices(["dof", "hyper", "inf", "fstop", "focus", "split", "one"], [40, 6, 5, 14, 12, 13, 10])[0]
    if mode in ("dof", "hyper", "inf", "split", "one") or rng.random() < 0.3:
        q["fstop"] = f"{fstop:.3g}"
    if mode == "dof":
        q["focus"] = _len(rng, mark)
    elif mode == "hyper":
        q["focus"] = rng.choice(["hyperfocal", "hyper"])
    elif mode == "inf":
        q["focus"] = rng.choice(["inf", "infinity"])
        if rng.random() < 0.5:
            q["near"] = _len(rng, mark)
    else:
        near, far = mark * rng.uniform(0.55, 0.97), mark * rng.uniform(1.03, 3.0)
        far_text = "inf" if rng.random() < 0.15 else _len(rng, far)
        if mode == "fstop":
            q.update(focus=_len(rng, mark), near=_len(rng, near), far=far_text)
        elif mode in ("focus", "split"):
            q.update(near=_len(rng, near), far=far_text)
        else:
            q["near" if rng.random() < 0.6 else "far"] = _len(rng, near if rng.random() < 0.6 else far)
    if rng.random() < 0.2:
        q["tstop"] = f"{fstop * rng.uniform(1.0, 1.3):.3g}"
    if rng.random() < 0.3:  # the page sends its unit system: a bare focus, near or far is then feet or mm
        q["units"] = rng.choice(["m", "ft"])
    _datasheet(rng, q, f)
    return q


def _datasheet(rng, q, f):
    """Sometimes the technical model (datasheet planes, maybe from the flange), a pupil or a tape measure."""
    r = rng.random()
    if r < 0.2:
        q["model"] = "technical"
        flange = rng.random() < 0.3
        base = 52.0 if flange else 0.0
        h2 = f * rng.uniform(0.9, 1.2) - base
        q["h2"] = f"{h2:.4g}"
        q["h1"] = f"{h2 + rng.uniform(-30, 60):.4g}"
        if flange:
            q.update(reference="flange", flange="52")
        if rng.random() < 0.5:
            q["pupil"] = f"{h2 + rng.uniform(-20, 80):.4g}"
    elif r < 0.3:
        length = rng.uniform(40, 200)
        q.update({"sensor-front": f"{length + rng.uniform(30, 120):.4g}", "lens-length": f"{length:.4g}"})
        if rng.random() < 0.5:
            q["pupil-fraction"] = f"{rng.uniform(0.2, 0.6):.2f}"
    elif r < 0.35:
        q["pupil"] = f"{rng.uniform(20, 200):.4g}"


# --- comparison ---------------------------------------------------------------------------------
#: strings the page's document carries that must read as the CLI's (the rest of the text: notes, names)
COMPARED_TEXT = {"model", "coc_convention", "entrance_pupil_source", "reference_plane", "key", "schema"}


#: differences of two nearly equal lengths: compared to RTOL of the length they are the difference of
DIFFERENCE_OF = {"far_error_mm": "far_predicted_from_film_mm"}


def differences(page, cli, path="", scale=None) -> list[str]:
    """Where the page's document differs from the CLI's (numbers to RTOL, or to RTOL of ``scale``; every key
    of the page's document)."""
    if isinstance(page, dict):
        if not isinstance(cli, dict):
            return [f"{path}: page {page!r}, cli {cli!r}"]
        out = []
        if path.endswith(("solved", "measured")) and set(page) != set(cli):
            out.append(f"{path}: keys page {sorted(page)}, cli {sorted(cli)}")
        for k, v in page.items():
            if k in ("notes", "name", "cameras"):
                continue
            if k not in cli:
                out.append(f"{path}.{k}: missing from the CLI's document")
                continue
            ref = cli.get(DIFFERENCE_OF.get(k, ""))
            out += differences(v, cli[k], f"{path}.{k}", None if ref is None else abs(ref))
        return out
    if isinstance(page, list):
        if not isinstance(cli, list) or len(page) != len(cli):
            return [f"{path}: page {page!r}, cli {cli!r}"]
        return [d for i, (a, b) in enumerate(zip(page, cli)) for d in differences(a, b, f"{path}[{i}]")]
    if isinstance(page, bool) or page is None or isinstance(cli, bool) or cli is None:
        return [] if page == cli and type(page) is type(cli) else [f"{path}: page {page!r}, cli {cli!r}"]
    if isinstance(page, (int, float)):
        if not isinstance(cli, (int, float)):
            return [f"{path}: page {page!r}, cli {cli!r}"]
        size = max(abs(page), abs(cli)) if scale is None else scale
        ok = abs(page - cli) <= RTOL * size or abs(page - cli) <= 1e-12
        return [] if ok else [f"{path}: page {page!r}, cli {cli!r}"]
    key = path.rsplit(".", 1)[-1]
    return [] if key not in COMPARED_TEXT or page == cli else [f"{path}: page {page!r}, cli {cli!r}"]


def cli_answers(setups) -> list:
    from physcam.cli.serve import cli_backend

    backend = cli_backend()
    out = []
    for q in setups:
        try:
            out.append({"ok": True, "body": backend.report(q)})
        except PhysCamError as exc:
            out.append({"ok": False, "body": {"error": str(exc)}})
    return out


def sensor_table() -> list:
    from physcam.cli.sensors import sensor_document
    from physcam.optics.sensors import sensors

    return [sensor_document(s) for s in sensors()]


@pytest.mark.slow
def test_page_solver_equals_the_cli_on_10000_random_setups(monkeypatch, tmp_path):
    monkeypatch.setenv("HOME", str(tmp_path))  # no user config: the CLI's defaults, as the page's
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    rng = random.Random(46)
    table = sensor_table()
    names = [rng.choice([s["key"], s["name"], *s["aliases"]]) for s in table]
    setups = [random_setup(rng, names) for _ in range(N_SETUPS)]
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        expected = cli_answers(setups)
    got = run_page_solver({"sensors": table, "setups": setups})
    assert len(got) == N_SETUPS
    bad = []
    for q, page, cli in zip(setups, got, expected):
        if page["ok"] != cli["ok"]:
            bad.append(f"{q}: page {'answers' if page['ok'] else 'refuses: ' + page['body']['error']}, "
                       f"cli {'answers' if cli['ok'] else 'refuses: ' + cli['body']['error']}")
        elif page["ok"]:
            diff = differences(page["body"], cli["body"])
            if diff:
                bad.append(f"{q}: {diff[:3]}")
    answered = sum(a["ok"] for a in expected)
    assert not bad, f"{len(bad)} of {N_SETUPS} setups differ, e.g.\n" + "\n".join(bad[:8])
    # the setups exercise the solver, not its refusals: most are answered
    assert answered > 0.75 * N_SETUPS, answered


# --- the page's other answers: exposure, close-up lenses, split focus ------------------------------
def _agree(page, cli):
    if page["ok"] != cli["ok"]:
        return [f"page {page['body']}, cli {cli['body']}"]
    return differences(page["body"], cli["body"]) if page["ok"] else []


def test_page_exposure_and_diopters_equal_the_library():
    from physcam.onset.diopter import close_up
    from physcam.onset.exposure import ExposureSetting, compensate, stops_between_settings

    rng = random.Random(4646)
    calls, expected = [], []
    for _ in range(1500):
        a = dict(fps=rng.choice([23.976, 24, 25, 48, 120]), shutter_deg=rng.uniform(5, 360), tstop=rng.uniform(0.9, 22),
                 ei=rng.choice([200, 400, 800, 1600, 3200]), nd=rng.choice([0, 0.3, 0.6, 0.9, 1.2, 2.1]))
        b = {k: (v if rng.random() < 0.5 else a[k]) for k, v in
             dict(fps=rng.choice([24, 48, 96, 240]), shutter_deg=rng.uniform(5, 400), tstop=rng.uniform(0.9, 22),
                  ei=rng.choice([400, 800, 1280, 6400]), nd=rng.choice([0, 0.3, 0.9, 1.5])).items()}
        control = rng.choice(["tstop", "nd", "ei", "shutter"])
        calls += [["exposureStops", a, b], ["compensate", a, b, control]]
        for fn in (lambda: stops_between_settings(ExposureSetting(**a), ExposureSetting(**b)),
                   lambda: compensate(ExposureSetting(**a), ExposureSetting(**b), control).to_dict()):
            try:
                expected.append({"ok": True, "body": fn()})
            except PhysCamError as exc:
                expected.append({"ok": False, "body": {"error": str(exc)}})
        f, n, c, p = _log_uniform(rng, 10, 300), _log_uniform(rng, 1, 22), rng.uniform(0.01, 0.04), rng.choice(
            [0.5, 1, 2, 3, 0.25, 4])
        mark = "inf" if rng.random() < 0.3 else _log_uniform(rng, 3 * f, 20000)
        calls.append(["closeUp", f, n, c, mark, p])
        try:
            expected.append({"ok": True, "body": close_up(f, n, c, math.inf if mark == "inf" else mark, p).to_dict()})
        except PhysCamError as exc:
            expected.append({"ok": False, "body": {"error": str(exc)}})
    got = run_page_solver({"calls": calls})
    bad = [f"{call}: {d[:2]}" for call, g, e in zip(calls, got, expected) for d in [_agree(g, e)] if d]
    assert not bad, f"{len(bad)} differ, e.g.\n" + "\n".join(bad[:6])
    assert sum(e["ok"] for e in expected) > 0.7 * len(expected)


def test_page_split_focus_equals_the_library(monkeypatch, tmp_path):
    from physcam.cli.serve import cli_backend  # noqa: F401  (the CLI's parser reads the queries below)
    from physcam.optics.sensors import find_sensor
    from physcam.onset.split_focus import split_focus
    from physcam.units import parse_distance

    monkeypatch.setenv("HOME", str(tmp_path))
    rng = random.Random(39)
    table = sensor_table()
    calls, expected = [], []
    for _ in range(400):
        f = _log_uniform(rng, 12, 200)
        mark = _log_uniform(rng, max(5 * f, 400), 30000)
        q = {"focal": f"{f:.4g}", "sensor": rng.choice(["S35", "ALEXA 35", "FX6 FF 4K 17:9", "VENICE 2"]),
             "near": _len(rng, mark * rng.uniform(0.5, 0.95)), "far": _len(rng, mark * rng.uniform(1.05, 3))}
        if rng.random() < 0.6:
            q["fstop"] = f"{_log_uniform(rng, 1.4, 16):.3g}"
        if rng.random() < 0.4:
            q["coc"] = rng.choice(["cine", "d/1730", "0.02", "full-frame"])
        calls.append(["splitFocus", q])
        try:
            from physcam.optics.coc import parse_coc

            sf = split_focus(sensor=find_sensor(q["sensor"]), focal_length_mm=float(q["focal"]),
                             near_mm=parse_distance(q["near"]), far_mm=parse_distance(q["far"]),
                             fstop=float(q["fstop"]) if "fstop" in q else None, coc=parse_coc(q.get("coc")))
            expected.append({"ok": True, "body": sf.to_dict()})
        except PhysCamError as exc:
            expected.append({"ok": False, "body": {"error": str(exc)}})
    got = run_page_solver({"sensors": table, "calls": calls})
    bad = [f"{call}: {d[:2]}" for call, g, e in zip(calls, got, expected) for d in [_agree(g, e)] if d]
    assert not bad, f"{len(bad)} differ, e.g.\n" + "\n".join(bad[:6])
    assert sum(e["ok"] for e in expected) > 0.7 * len(expected)


#: names an AC types for a camera: full-sensor names, formats by another name of the camera, a camera alone
CAMERA_NAMES = ("ALEXA 35", "ALEXA Mini", "Mini LF", "VENICE 2", "KOMODO 4K 17:9", "BMPCC 6K 16:9", "Komodo",
                "BMPCC 6K", "FX6")


def test_page_and_server_take_a_camera_name_alike():
    """The page's findSensor (onset.js, on the sensor table the server sends) and the library's find_sensor give the
    same format for every camera name, or both refuse (a camera alone: the library lists its formats)."""
    from physcam.optics.sensors import find_sensor

    table = sensor_table()
    got = run_page_solver({"sensors": table, "calls": [["findSensor", table, n] for n in CAMERA_NAMES]})
    for name, g in zip(CAMERA_NAMES, got):
        try:
            s = find_sensor(name)
        except PhysCamError:
            assert not g["ok"], (name, g)
            continue
        assert g["ok"] and g["body"]["key"] == s.key, (name, g)


def test_page_says_which_format_a_bare_camera_name_is_as_the_cli(monkeypatch, tmp_path):
    """A bare camera name ("ALEXA 35") is its camera's full sensor: the page's own report carries the CLI's note
    (physcam.optics.sensors.camera_name_note, first-day walkthrough round 9: the offline page left it out). Every
    label of every sensor row gets the library's note (or none) from the page's cameraNameNote, and the page's
    report for "ALEXA 35" carries it as the server's (`physcam report --json`) does."""
    from physcam.optics.sensors import camera_name_note

    monkeypatch.setenv("HOME", str(tmp_path))  # no user config: the CLI's defaults, as the page's
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    table = sensor_table()
    labels = sorted({lab for s in table for lab in (s["key"], s["name"], *s["aliases"])})
    got = run_page_solver({"sensors": table, "calls": [["cameraNameNote", n] for n in labels]})
    want = [camera_name_note(n) for n in labels]
    assert sum(bool(w) for w in want) >= 10  # the camera names the table gives a meaning
    assert [g["body"] for g in got] == want
    q = {"focal": "50", "fstop": "2.8", "focus": "3m", "sensor": "ALEXA 35"}
    page, cli = run_page_solver({"sensors": table, "setups": [q]})[0], cli_answers([q])[0]
    assert page["ok"] and cli["ok"]
    note = camera_name_note("ALEXA 35")
    assert note in cli["body"]["notes"] and note in page["body"]["notes"]
    assert page["body"]["notes"][-1] == note  # after the report's own notes, as the CLI adds it


def test_page_reads_typographic_marks_as_the_server():
    """10’6” (an iPhone's smart quotes), 10′6″ (primes), 6’’ (two single quotes): the page's parseDistance gives
    the millimetres worked by hand (tests/test_units_typographic_marks.py: 10 ft 6 in = 126 x 25.4 = 3200.4 mm)
    and the page's report equals the server's (`physcam report --json`) for focus, near and far typed so; both
    refused the marks before round 22 (the page with "cannot read focus distance")."""
    from _typed_distances import TYPED

    got = run_page_solver({"calls": [["parseDistance", text] for text, _ in TYPED]})
    assert [g["ok"] for g in got] == [True] * len(TYPED), got
    assert [g["body"] for g in got] == pytest.approx([mm for _, mm in TYPED], rel=1e-12)
    setups = [{"focal": "50", "fstop": "2.8", "focus": "10’6”"}, {"focal": "35", "fstop": "4", "focus": "10′ 6″"},
              {"focal": "50", "near": "8’", "far": "14’ 6”", "units": "ft"},
              {"focal": "50", "fstop": "2", "focus": "9’ 10 1/8”", "near": "9’ 6’’"},
              {"focal": "50", "fstop": "2", "focus": "x’"}]
    table = sensor_table()
    page, cli = run_page_solver({"sensors": table, "setups": setups}), cli_answers(setups)
    assert [p["ok"] for p in page] == [c["ok"] for c in cli] == [True, True, True, True, False]
    for q, a, b in zip(setups, page, cli):
        assert not _agree(a, b), (q, _agree(a, b))
    assert cli[0]["body"]["focus_from_film_mm"] == pytest.approx(3200.4, rel=1e-12)


def test_page_keeps_the_libraries_coc_and_focal_bounds():
    """The one range of a circle of confusion (0.001 to 1 mm, physcam.optics.coc.require_coc) and of a focal length
    (1 mm to 100 m, physcam.optics.thinlens.require_focal_length): the page refuses where the server refuses and
    answers the edges as it does (round 22: coc=1e-300 gave a 300-digit hyperfocal, focal=0.001 "0.0 mm")."""
    base = {"fstop": "2", "focus": "3m", "sensor": "S35"}
    setups = [dict(base, focal="50", coc=c) for c in ("1e-300", "5m", "0.0009", "1.001", "0.001", "1", "1um", "1mm")]
    setups += [dict(base, focal=f, focus="inf") for f in ("0.001", "0.999", "1", "1e5", "1.1e5")]
    want = [False, False, False, False, True, True, True, True, False, False, True, True, False]
    page, cli = run_page_solver({"sensors": sensor_table(), "setups": setups}), cli_answers(setups)
    assert [c["ok"] for c in cli] == want, [c["body"] for c in cli]
    assert [p["ok"] for p in page] == want, [p["body"] for p in page]
    for a, b in zip(page, cli):
        assert not _agree(a, b)
    calls = [["closeUp", 0.5, 4, 0.025, 1000, 1], ["closeUp", 50, 4, 5000, 1000, 1], ["closeUp", 1, 4, 0.001, 1000, 1]]
    assert [g["ok"] for g in run_page_solver({"calls": calls})] == [False, False, True]
