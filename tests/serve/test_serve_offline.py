"""The page with the laptop off: installable (manifest, service worker), and a new setup opened from the
browser's cache by the page's own URL parameters, once the server is stopped, shows the CLI's numbers.

Real Chromium (Debian's, headless) through Playwright, a real `physcam serve` process that the test stops.
"""

from __future__ import annotations

import json
import shutil

import pytest
from _serve_helpers import request, running_server

from physcam.cli import main
from physcam.optics.sensors import camera_name_note

pytestmark = pytest.mark.slow

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
if CHROMIUM is None:
    pytest.skip("Debian's chromium is not installed here (`make test` installs it as root); the browser tests need "
                "it", allow_module_level=True)
sync_api = pytest.importorskip("playwright.sync_api", reason="playwright (the test extra) is not installed")

SUMMARY = {"out-near": "near_from_film_mm", "out-far": "far_from_film_mm", "out-total": "total_mm",
           "out-hyperfocal": "hyperfocal_from_film_mm"}


def cli_report(capsys, *argv):
    capsys.readouterr()
    assert main(["report", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def metric(mm):
    return "∞" if mm is None else (f"{mm / 10:.1f} cm" if abs(mm) < 1000 else f"{mm / 1000:.2f} m")


def shown(pg) -> dict:
    return pg.evaluate("(ids) => Object.fromEntries(ids.map((id) => { const e = document.getElementById(id);"
                       " return [id, [e.dataset.mm, e.textContent]]; }))", list(SUMMARY))


def assert_numbers(pg, doc):
    for el, key in SUMMARY.items():
        mm, text = shown(pg)[el]
        want = doc["dof"][key]
        if want is None:
            assert mm == "inf" and text == "∞", el
        else:
            assert float(mm) == pytest.approx(want, rel=1e-9), el
            assert text == metric(want), el


def test_manifest_and_worker_are_served():
    with running_server() as (_, port, _proc):
        status, headers, body = request(port, "/manifest.webmanifest")
        m = json.loads(body)
        assert status == 200 and m["start_url"] == "/" and m["display"] == "standalone"
        assert {"192x192", "512x512"} <= {i["sizes"] for i in m["icons"]}
        for icon in m["icons"]:
            assert request(port, icon["src"])[0] == 200
        status, headers, body = request(port, "/sw.js")
        assert status == 200 and b"caches" in body and "javascript" in headers.get("content-type", "")
        assert request(port, "/static/onset.js")[0] == 200


def test_a_new_setup_opens_from_the_cache_with_the_server_stopped(capsys):
    """Setups opened by the page's own URL parameters, then issue 46's done-when as a puller does it on the phone
    (the_done_when_path): both with the laptop's server stopped, each number `physcam report`'s."""
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox", "--disable-dev-shm-usage"])
        try:
            ctx = b.new_context(viewport={"width": 390, "height": 844}, is_mobile=True, has_touch=True)
            pg = ctx.new_page()
            pg.set_default_timeout(30_000)
            errors: list[str] = []
            pg.on("pageerror", lambda e: errors.append(str(e)))
            with running_server() as (url, _port, proc):
                pg.goto(url)
                pg.wait_for_selector("body[data-ready='1'][data-worker='ready']")
                # the worker controls the page and holds the page, its scripts and the camera table
                pg.wait_for_function("async () => navigator.serviceWorker.controller !== null"
                                     " && !!(await caches.match('/api/sensors')) && !!(await caches.match('/'))"
                                     " && !!(await caches.match('/static/onset.js'))")
            assert proc.poll() is not None  # the laptop is off
            for query, argv in ((("focal=35&fstop=4&focus=2m&sensor=S35"),
                                 ("--focal", "35", "--fstop", "4", "--focus", "2m", "--sensor", "S35")),
                                (("focal=50&fstop=2.8&focus=3m&sensor=FX6%20FF%204K%2017%3A9"),
                                 ("--focal", "50", "--fstop", "2.8", "--focus", "3m", "--sensor", "FX6 FF 4K 17:9")),
                                (("focal=50&fstop=2.8&focus=3m&sensor=ALEXA%2035"),  # a bare camera name: the note
                                 ("--focal", "50", "--fstop", "2.8", "--focus", "3m", "--sensor", "ALEXA 35"))):
                pg.goto(f"{url}?{query}")
                pg.wait_for_selector("body[data-ready='1'][data-source='page'][data-offline='1']")
                doc = cli_report(capsys, *argv)
                assert_numbers(pg, doc)
                assert pg.locator("#sensor").input_value() == doc["sensor"]["key"]
                said = camera_name_note(argv[-1])  # the CLI's note of which format a camera name is, or ""
                assert not said or (said in doc["notes"] and said in pg.locator("#notes li").all_text_contents())
            the_done_when_path(pg, url, capsys)
            ctx.close()
        finally:
            b.close()
    assert not errors, errors



def test_a_report_opened_in_a_tab_does_not_become_the_offline_page(capsys):
    """The page links its report as JSON (#json-link). The worker kept whatever a navigation answered as "/":
    one tap on the link, and with the server stopped every setup opened the raw JSON instead of the page (a
    review found it). Now only "/" is kept as the page: after the tap, a setup still opens offline and shows
    `physcam report`'s numbers."""
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox", "--disable-dev-shm-usage"])
        try:
            ctx = b.new_context()
            pg = ctx.new_page()
            pg.set_default_timeout(30_000)
            with running_server() as (url, _port, proc):
                pg.goto(f"{url}?focal=35&fstop=4&focus=2m&sensor=S35")
                pg.wait_for_selector("body[data-ready='1'][data-worker='ready']")
                pg.wait_for_function("async () => navigator.serviceWorker.controller !== null"
                                     " && !!(await caches.match('/')) && !!(await caches.match('/static/onset.js'))")
                pg.wait_for_selector("#json-link[href*='/api/report']")
                pg.click("#json-link")
                pg.wait_for_function("() => document.body && document.body.textContent.includes('physcam.lens_report')")
            assert proc.poll() is not None  # the laptop is off
            pg.goto(f"{url}?focal=50&fstop=2.8&focus=3m&sensor=S35")
            pg.wait_for_selector("body[data-ready='1'][data-source='page'][data-offline='1']")
            assert_numbers(pg, cli_report(capsys, "--focal", "50", "--fstop", "2.8", "--focus", "3m", "--sensor", "S35"))
            ctx.close()
        finally:
            b.close()


def the_done_when_path(pg, url, capsys):
    """Issue 46's done-when, as a puller does it with the laptop off: a 390 x 844 phone opens the page from its
    cache, picks the camera "Sony FX6" then its format "FF 4K 17:9", a lens of their set (typed on the phone) and a
    stop, and reads near, far, depth of field, the frame at the subject and the split-focus answer. Every number
    is `physcam report`'s for the same setup (the split focus: `physcam report --near --far --fstop`, the focus
    solved, and its split_focus.fstop_needed)."""
    setup = ("--focal", "50", "--fstop", "2.8", "--sensor", "FX6 FF 4K 17:9", "--coc", "cine")
    pg.goto(url)
    pg.wait_for_selector("body[data-ready='1']")
    pg.click("#coc-first button[data-coc='cine']")  # the first-use question: the puller's 0.025 mm
    pg.select_option("#camera", "Sony FX6")
    pg.select_option("#sensor", "sony-fx6-ff-4k-17-9")
    assert pg.locator("#sensor option:checked").text_content().startswith("Sony FX6 FF 4K 17:9 — 35.6 × 18.77 mm")
    pg.click("#lens-set-edit summary")
    pg.fill("#lens-set-text", "25 T2 9in\n50 T1.4 18in # hero\n85 T1.4 3ft\n")
    pg.select_option("#set-lens", "1")  # the 50 of the set
    pg.fill("#fstop", "2.8")
    pg.fill("#focus", "3m")
    doc = cli_report(capsys, *setup, "--focus", "3m")
    pg.wait_for_function("(v) => Math.abs(Number(document.getElementById('out-near').dataset.mm) - v) <= 1e-9 * v",
                         arg=doc["dof"]["near_from_film_mm"])
    assert pg.get_attribute("body", "data-source") == "page" and pg.get_attribute("body", "data-offline") == "1"
    assert pg.locator("#sensor").input_value() == doc["sensor"]["key"] == "sony-fx6-ff-4k-17-9"
    assert_numbers(pg, doc)  # near, far, depth of field, hyperfocal
    for side in ("width", "height"):
        got = float(pg.get_attribute("#out-frame", f"data-{side}"))
        assert got == pytest.approx(doc["frame_at_focus"][f"{side}_mm"], rel=1e-9), side
    pg.fill("#split-near", "2.5m")
    pg.fill("#split-far", "4m")
    pg.wait_for_selector("#split-answer[data-focus]")
    split = cli_report(capsys, *setup, "--near", "2.5m", "--far", "4m")
    assert float(pg.get_attribute("#split-answer", "data-focus")) == pytest.approx(split["focus_from_film_mm"], rel=1e-9)
    need = split["split_focus"]["fstop_needed"]
    assert float(pg.get_attribute("#split-answer", "data-fstop")) == pytest.approx(need, rel=1e-9)
    assert f"f/{need:.1f}" in pg.text_content("#split-answer")
