"""The `physcam serve` page in a real browser: Debian's Chromium, headless, driven by Playwright.

`make test` installs `chromium` when it is missing (as root, on CI's fresh Debian machine); where
there is no Chromium these tests skip and say why. Playwright is pointed at the system browser
(`executable_path`): it never downloads one of its own.

Every number the page shows is checked against the CLI's --json for the same setup, and the
near limit also against the thin-lens closed form worked by hand (tests/_thin_lens.py).
"""

from __future__ import annotations

import json
import math
import os
import shutil
import struct
from pathlib import Path

import pytest
from _serve_helpers import running_server
from _thin_lens import image_distance_at_mark

from physcam.cli import main
from physcam.units import format_feet_inches

pytestmark = pytest.mark.slow

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
if CHROMIUM is None:
    pytest.skip("Debian's chromium is not installed here (`make test` installs it when run as root: "
                "apt-get install chromium); the browser tests need it", allow_module_level=True)
sync_api = pytest.importorskip("playwright.sync_api", reason="playwright (the test extra) is not installed")

DOCS_SCREENSHOT = Path(__file__).resolve().parents[2] / "docs" / "img" / "serve_phone.png"


@pytest.fixture(scope="module")
def server():
    with running_server() as (url, port, proc):
        yield url
        log = "".join(proc.stderr_lines)
        assert "Traceback" not in log and "internal error" not in log, log[-3000:]


@pytest.fixture(scope="module")
def browser():
    with sync_api.sync_playwright() as p:
        # root (CI) needs --no-sandbox; a container's small /dev/shm needs the other flag
        b = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox", "--disable-dev-shm-usage"])
        yield b
        b.close()


@pytest.fixture
def page(browser):
    ctx = browser.new_context(viewport={"width": 375, "height": 812}, device_scale_factor=1, is_mobile=True,
                              has_touch=True)
    pg = ctx.new_page()
    pg.set_default_timeout(30_000)
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    yield pg
    ctx.close()
    assert not errors, errors


def open_page(pg, url):
    pg.goto(url)
    pg.wait_for_selector("body[data-ready='1']")


def cli_report(capsys, *argv):
    capsys.readouterr()
    assert main(["report", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def wait_mm(pg, element_id, mm):
    """Wait until the element shows the length ``mm`` (its data-mm; "inf" for None)."""
    pg.wait_for_function("([id, v]) => { const e = document.getElementById(id);"
                         " return v === null ? e.dataset.mm === 'inf' : Number(e.dataset.mm) === v; }",
                         arg=[element_id, mm])


def wait_chart_for_setup(pg):
    """Wait until the DOF chart on show, and the numbers it carries, are those of the page's current
    setup (the report link's query), loaded."""
    pg.wait_for_function("() => { const i = document.getElementById('dof-chart');"
                         " const api = document.getElementById('json-link').getAttribute('href')"
                         ".replace('/api/report?', '');"
                         # the units ride on the chart's src alone (app.js chart())
                         " const ft = document.getElementById('units-imperial').getAttribute('aria-pressed') === 'true';"
                         " return i.dataset.api === api && i.getAttribute('src') === '/api/dof.svg?' + api"
                         " + (ft ? '&units=ft' : '') && i.complete && i.naturalWidth > 0; }")


def metric(mm):
    """How the page writes a length in metric (docs/serve.md): cm with one decimal under 1 m, else m."""
    return "∞" if mm is None else (f"{mm / 10:.1f} cm" if abs(mm) < 1000 else f"{mm / 1000:.2f} m")


def imperial(mm):
    """... and in imperial: inches with one decimal under a foot, else feet and inches (units.py)."""
    return "∞" if mm is None else (f'{mm / 25.4:.1f}"' if abs(mm) < 304.8 else format_feet_inches(mm))


SETUP = ("--focal", "35", "--sensor", "alexa35-og", "--fstop", "2", "--focus", "2.5m")


def type_setup(pg):
    pg.fill("#focal", "35")
    pg.fill("#sensor-search", "alexa 35")  # the search narrows the picker; its first match is chosen
    pg.fill("#fstop", "2")
    pg.fill("#focus", "2.5m")  # a bare number would be millimetres, as on the command line (docs/serve.md)


def test_typed_setup_shows_the_cli_numbers(page, server, capsys):
    open_page(page, server)
    type_setup(page)
    d = cli_report(capsys, *SETUP)
    dof = d["dof"]
    wait_mm(page, "out-near", dof["near_from_film_mm"])
    assert page.input_value("#sensor") == "alexa35-og"
    assert float(page.get_attribute("#out-far", "data-mm")) == dof["far_from_film_mm"]
    assert float(page.get_attribute("#out-hyperfocal", "data-mm")) == dof["hyperfocal_from_film_mm"]
    assert float(page.get_attribute("#out-total", "data-mm")) == dof["total_mm"]
    for el, mm in (("out-near", dof["near_from_film_mm"]), ("out-far", dof["far_from_film_mm"]),
                   ("out-total", dof["total_mm"])):
        assert page.text_content(f"#{el}") == metric(mm)
    # the thin-lens closed form worked by hand: s + s' = D from the film, H = f^2 / (N c) + f from H1
    f, n, mark = 35.0, 2.0, 2500.0
    c = math.hypot(27.99, 19.22) / 1500  # ALEXA 35 open gate, d/1500
    s_img = image_distance_at_mark(f, mark)
    s = mark - s_img
    hyper = f * f / (n * c) + f
    assert dof["near_from_film_mm"] == pytest.approx(s * (hyper - f) / (hyper + s - 2 * f) + s_img, rel=1e-9)
    f_txt = page.text_content("#out-fov")
    fov = d["fov_deg"]["focus"]
    assert f_txt == f"{fov['horizontal']:.1f}° / {fov['vertical']:.1f}° / {fov['diagonal']:.1f}°"
    assert page.text_content("#out-pupil").startswith(f"{d['entrance_pupil_from_film_mm']:.1f} mm")
    # the table of focus marks: the 3 m row is the CLI's report focused at 3 m
    at3 = cli_report(capsys, *SETUP[:-1], "3m")["dof"]
    page.wait_for_function("v => { const r = document.querySelector('#marks tr[data-focus=\"3m\"]');"
                           " return r && Number(r.cells[1].dataset.mm) === v; }", arg=at3["near_from_film_mm"])
    row = page.locator('#marks tr[data-focus="3m"]')
    assert row.locator("td").nth(1).text_content() == metric(at3["near_from_film_mm"])
    assert row.locator("td").nth(2).text_content() == metric(at3["far_from_film_mm"])


def test_imperial_switch(page, server, capsys):
    open_page(page, server)
    type_setup(page)
    near = cli_report(capsys, *SETUP)["dof"]["near_from_film_mm"]
    wait_mm(page, "out-near", near)
    page.click("#units-imperial")
    page.wait_for_function("() => document.getElementById('out-near').textContent.includes(\"'\")")
    assert page.text_content("#out-near") == imperial(near) == format_feet_inches(near)
    assert float(page.get_attribute("#out-near", "data-mm")) == near  # 2.5m keeps meaning metres
    # the DOF chart is drawn in feet too (physcam serve's /api/dof.svg?...&units=ft)
    page.wait_for_function("() => (document.getElementById('dof-chart').getAttribute('src') || '')"
                           ".includes('units=ft')")
    assert page.input_value("#focus") == "2.5m"
    page.wait_for_function("() => { const td = document.querySelector('#marks tbody td');"
                           " return td !== null && td.textContent === \"2'\"; }")
    # a bare number now means feet: 10 -> 10 ft
    page.fill("#focus", "10")
    d = cli_report(capsys, *SETUP[:-1], "10ft")
    wait_mm(page, "out-near", d["dof"]["near_from_film_mm"])
    assert page.text_content("#out-far") == imperial(d["dof"]["far_from_film_mm"])


def test_shared_url_reproduces_the_setup(page, browser, server, capsys):
    open_page(page, server)
    type_setup(page)
    page.click("#units-imperial")
    page.select_option("#coc", "cine")
    page.select_option("#squeeze", "1.5")
    d = cli_report(capsys, *SETUP, "--coc", "cine", "--squeeze", "1.5")
    wait_mm(page, "out-near", d["dof"]["near_from_film_mm"])
    page.wait_for_selector("#out-horizontal:not([hidden])")  # the squeeze's answer is in too
    shared = page.url
    assert page.input_value("#share-url") == shared
    ctx = browser.new_context(viewport={"width": 375, "height": 812})
    other = ctx.new_page()
    try:
        open_page(other, shared)
        wait_mm(other, "out-near", d["dof"]["near_from_film_mm"])
        for sel in ("#focal", "#sensor", "#fstop", "#focus", "#coc", "#squeeze"):
            assert other.input_value(sel) == page.input_value(sel), sel
        assert other.get_attribute("#units-imperial", "aria-pressed") == "true"
        for el in ("#out-near", "#out-far", "#out-total", "#out-hyperfocal", "#out-horizontal", "#out-fov"):
            assert other.text_content(el) == page.text_content(el), el
        h = d["dof_horizontal"]
        assert other.text_content("#out-horizontal") == (f"{imperial(h['near_from_film_mm'])} / "
                                                         f"{imperial(h['far_from_film_mm'])}")
    finally:
        ctx.close()


def test_impossible_input_shows_its_message_and_the_page_keeps_working(page, server, capsys):
    open_page(page, server)
    type_setup(page)
    page.fill("#fstop", "0.3")
    page.wait_for_selector("#message:not([hidden])")
    assert "out of range" in page.text_content("#message")
    assert "stale" in page.get_attribute("#summary", "class")
    page.fill("#focus", "3 parsecs")
    page.wait_for_function("() => document.getElementById('message').textContent.startsWith('focus: unknown unit')")
    page.fill("#focus", "2.5m")
    page.fill("#fstop", "4")
    d = cli_report(capsys, *SETUP[:-3], "4", "--focus", "2.5m")
    wait_mm(page, "out-near", d["dof"]["near_from_film_mm"])
    assert page.is_hidden("#message")
    assert "stale" not in page.get_attribute("#summary", "class")


def test_inversions_on_the_page(page, server, capsys):
    open_page(page, server)
    # effective f-stop from a measured near/far (the report's own example in `physcam report --help`)
    page.fill("#focal", "35")
    page.fill("#focus", "10ft")
    page.click("#solve-fstop")
    assert page.is_hidden("#field-fstop")
    page.fill("#near", "8ft")
    page.fill("#far", "14ft")
    page.select_option("#coc", "cine")
    page.fill("#tstop", "T2.8")
    d = cli_report(capsys, "--focal", "35", "--focus", "10ft", "--near", "8ft", "--far", "14ft", "--coc", "cine",
                   "--tstop", "2.8")
    n = d["solved"]["fstop"]
    # wait for the f-stop itself: the near limit shown is the measured 8 ft whatever the CoC, so the
    # answer from before the cine CoC and the T-stop already satisfies a wait on it (f/5.03, not f/4.17)
    want = f"f/{float(f'{n:.2f}'):g} (solved from near/far) · T2.8"  # the T-stop too: it moves no f-stop
    page.wait_for_function("w => document.getElementById('out-fstop').textContent.startsWith(w)", arg=want)
    assert float(page.get_attribute("#out-near", "data-mm")) == d["dof"]["near_from_film_mm"]
    # focus from a bracket
    page.click("#solve-focus")
    page.fill("#fstop", "4")
    page.fill("#near", "2.5m")
    page.fill("#far", "4m")
    page.select_option("#coc", "d/1500")
    page.fill("#tstop", "")
    d = cli_report(capsys, "--focal", "35", "--near", "2.5m", "--far", "4m", "--fstop", "4")
    wait_mm(page, "out-focus", d["solved"]["focus_from_film_mm"])
    assert page.text_content("#out-focus") == metric(d["focus_from_film_mm"]) + " (solved from near/far)"
    # split focus with the stop given (issue 39): the top boxes show f/4's own limits and, beside them, the stop
    # the asked 2.5 m - 4 m needs at this CoC (not a CoC inflated until f/4 seems to hold them)
    sf = d["split_focus"]
    wait_mm(page, "out-near", d["dof"]["near_from_film_mm"])
    assert d["dof"]["near_from_film_mm"] > 2500.0 and not sf["holds"]
    page.wait_for_selector("#split-card:not([hidden])")
    assert page.text_content("#label-near") == "near at f/4"
    need = float(f"{sf['fstop_needed']:.1f}")  # as the page writes it: one decimal, no trailing zero
    assert page.text_content("#out-split") == f"f/{need:g} holds 2.50 m – 4.00 m (f/4 holds less)"


def test_one_rule_for_a_bare_number_and_the_words(page, server, capsys):
    """Issue 39: a bare focus is millimetres here as on the command line, and one too close says "did you
    mean 3m?"; the magnification reads 1 : 58.0 for the inverted image, never "1 : -58.0"."""
    open_page(page, server)
    type_setup(page)
    page.fill("#focus", "3")
    page.wait_for_function("() => document.getElementById('message').textContent.includes('did you mean 3m?')")
    page.fill("#focus", "3m")
    d = cli_report(capsys, *SETUP[:-1], "3m")
    wait_mm(page, "out-near", d["dof"]["near_from_film_mm"])
    m = d["magnification"]
    assert m < 0
    assert page.text_content("#out-mag") == f"1 : {1 / abs(m):.1f}  ({m:.4f}×, inverted image)"


def test_a_server_whose_config_says_feet_reads_bare_numbers_in_feet(browser, tmp_path, capsys):
    cfg = tmp_path / "config.toml"
    cfg.write_text('units = "ft"\n')
    with running_server(env={"PHYSCAM_CONFIG": str(cfg)}) as (url, port, proc):
        ctx = browser.new_context(viewport={"width": 375, "height": 812})
        pg = ctx.new_page()
        try:
            open_page(pg, url)
            assert pg.get_attribute("#units-imperial", "aria-pressed") == "true"
            pg.fill("#focal", "35")
            pg.fill("#fstop", "2")
            pg.fill("#focus", "10")  # feet, as `physcam report --focus 10` reads it with this config
            d = cli_report(capsys, "--focal", "35", "--fstop", "2", "--focus", "10ft")
            wait_mm(pg, "out-near", d["dof"]["near_from_film_mm"])
        finally:
            ctx.close()


def test_library_lens_and_its_diagram(page, server, capsys):
    open_page(page, server)
    page.click("#lensmode-library")
    page.wait_for_function("() => document.getElementById('lens').options.length > 5")
    page.select_option("#lens", "dgauss_50mm")
    page.fill("#fstop", "2.8")
    page.fill("#focus", "2m")
    d = cli_report(capsys, "--lens", "dgauss_50mm", "--fstop", "2.8", "--focus", "2m")
    wait_mm(page, "out-near", d["dof"]["near_from_film_mm"])
    assert "prescription" in page.text_content("#out-pupil")
    page.wait_for_function("() => { const i = document.getElementById('diagram');"
                           " return i.complete && i.naturalWidth > 0 && i.src.includes('dgauss_50mm'); }")


def _png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


def test_phone_screenshot_and_touch_targets(page, server, tmp_path):
    open_page(page, server)
    page.wait_for_function("() => { const i = document.getElementById('dof-chart');"
                           " return i.complete && i.naturalWidth > 0; }")
    page.wait_for_selector("#marks tbody tr")
    # phone first: nothing wider than the 375 px screen, every control at least 44 px tall (Apple HIG)
    assert page.evaluate("document.documentElement.scrollWidth") <= 375
    small = page.evaluate("""() => [...document.querySelectorAll('button, input, select')]
        .filter((e) => e.offsetParent !== null)
        .map((e) => [e.id, e.getBoundingClientRect().height])
        .filter(([, h]) => h < 44)""")
    assert not small, small
    shot = tmp_path / "serve_phone.png"
    page.screenshot(path=str(shot))
    assert _png_size(shot) == (375, 812)
    if os.environ.get("PHYSCAM_WRITE_DOCS_SCREENSHOT") == "1":  # refresh the picture in docs/serve.md
        from physcam.io import atomic_write

        atomic_write(DOCS_SCREENSHOT, shot.read_bytes(), force=True)


DOCS_CHART_SCREENSHOT = DOCS_SCREENSHOT.with_name("serve_phone_dof_chart.png")


def test_dof_chart_fits_the_phone_and_marks_the_cursor(page, server, capsys, tmp_path):
    """The chart fits the 375 px screen (no side scroll, the picture inside its section), and the
    mark under a finger reads the near and far limits of the CLI's report at that focus mark."""
    open_page(page, server)
    type_setup(page)
    wait_mm(page, "out-near", cli_report(capsys, *SETUP)["dof"]["near_from_film_mm"])
    # the numbers come first and the chart a moment later (SETTLE_MS): wait for the chart of this
    # setup, not the one still showing from a half-typed one (a CI run read f/2 off that: 3.95 m)
    wait_chart_for_setup(page)
    page.wait_for_function("() => document.getElementById('dof-readout') && window.getComputedStyle("
                           "document.getElementById('dof-chart')).display !== 'none'")
    page.locator("#dof-wrap").scroll_into_view_if_needed()
    box = page.locator("#dof-chart").bounding_box()
    assert box["x"] >= 0 and box["x"] + box["width"] <= 375
    assert page.evaluate("document.documentElement.scrollWidth") <= 375
    # the SVG's own numbers say where its axes are: point at the middle of the x axis
    meta = page.evaluate("""async () => {
        const t = await (await fetch(document.getElementById('dof-chart').getAttribute('src'))).text();
        const d = new DOMParser().parseFromString(t, 'image/svg+xml');
        return JSON.parse(d.getElementsByTagNameNS('http://purl.org/dc/elements/1.1/', 'description')[0].textContent);
    }""")
    x0, y0, w, h = meta["axes"]
    fx = x0 + 0.3 * w
    page.wait_for_function("() => document.getElementById('dof-chart').getBoundingClientRect().width > 0")
    page.mouse.move(box["x"] + fx * box["width"], box["y"] + (1 - y0 - h / 2) * box["height"])
    page.wait_for_function("() => document.getElementById('dof-readout').dataset.mm !== undefined")
    mark = float(page.get_attribute("#dof-readout", "data-mm"))
    lo, hi = meta["x_mm"]
    assert mark == pytest.approx(lo * (hi / lo) ** 0.3, rel=0.01)  # the log axis, read back
    assert page.is_visible("#dof-cursor")
    text = page.text_content("#dof-readout")
    # f/2 at that mark, from the CLI's report itself: the chart interpolates between its rows (2 %)
    d = cli_report(capsys, *SETUP[:-1], f"{mark:.0f}mm")["dof"]
    part = next(p for p in text.split(" · ") if p.startswith("f/2:"))
    near_txt = part.split(": ")[1].split(" – ")[0]
    assert near_txt.endswith(" m") or near_txt.endswith(" cm")
    near = float(near_txt.split()[0]) * (1000.0 if near_txt.endswith(" m") else 10.0)
    assert near == pytest.approx(d["near_from_film_mm"], rel=0.02, abs=6.0)
    shot = tmp_path / "chart.png"
    page.locator("#dof-wrap").screenshot(path=str(shot))
    assert _png_size(shot)[0] <= 375
    if os.environ.get("PHYSCAM_WRITE_DOCS_SCREENSHOT") == "1":  # refresh the picture in docs/serve.md
        from physcam.io import atomic_write

        page.screenshot(path=str(shot))
        atomic_write(DOCS_CHART_SCREENSHOT, shot.read_bytes(), force=True)


def test_an_anamorphic_format_brings_its_desqueeze_and_both_limits(page, server):
    """Issue 49 item 4: picking a format the camera table gives a 2x desqueeze sets the squeeze, and the
    page says the horizontal limits (the oval blur takes c / 0.5 across the frame) and the desqueezed
    field, worked by hand from the thin lens; a spherical format puts the squeeze back, a squeeze the
    user chose stays."""
    open_page(page, server)
    page.fill("#focal", "50")
    page.fill("#fstop", "2.8")
    page.fill("#focus", "3m")
    page.select_option("#coc", "cine")
    page.select_option("#sensor", "arri-alexa-35-3-3k-6-5")  # 20.22 x 16.95 mm, desqueeze 2 in cameras.csv
    assert page.input_value("#squeeze") == "2" and "camera table" in page.text_content("#squeeze-hint")
    f, n, mark = 50.0, 2.8, 3000.0
    s_img = image_distance_at_mark(f, mark)
    s = mark - s_img
    hyper = f * f / (n * 0.05) + f  # c = 0.025 mm / blur aspect 0.5
    near_h, far_h = s * (hyper - f) / (hyper + s - 2 * f) + s_img, s * (hyper - f) / (hyper - s) + s_img
    page.wait_for_selector("#out-horizontal:not([hidden])")
    assert page.text_content("#out-horizontal") == f"{metric(near_h)} / {metric(far_h)}"  # 2.59 m / 3.57 m
    h_deg = math.degrees(2 * math.atan(2 * 20.22 / (2 * s_img)))
    v_deg = math.degrees(2 * math.atan(16.95 / (2 * s_img)))
    assert page.text_content("#out-fov").startswith(f"{h_deg:.1f}° / {v_deg:.1f}° / ")  # 43.4° / 18.9°
    page.select_option("#sensor", "alexa35-og")  # spherical: the squeeze the format set goes
    assert page.input_value("#squeeze") == "1" and page.is_hidden("#squeeze-hint")
    page.wait_for_selector("#out-horizontal", state="hidden")
    page.select_option("#sensor", "arri-alexa-35-3-3k-6-5")
    page.select_option("#squeeze", "1.5")  # the user's own
    page.select_option("#sensor", "alexa35-og")
    assert page.input_value("#squeeze") == "1.5"
