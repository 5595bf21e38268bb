"""Screenshots of the `physcam serve` page for docs/serve.md: a phone (390 x 844) and a tablet
(1024 x 768), each in the dark (night) and the light theme, on one setup a focus puller would type
(Sony FX6 FF 4K 17:9, 50 mm at f/2.8 on 3 m, split focus 2.5 - 4 m, 24 -> 48 fps).

    python scripts/serve_screenshots.py        # writes docs/img/serve_{phone,tablet}_{dark,light}.png

Runs a real `physcam serve` on a free loopback port and Debian's Chromium through Playwright.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "serve"))

from _serve_helpers import running_server  # noqa: E402
from playwright.sync_api import sync_playwright  # noqa: E402

SETUP = "?focal=50&fstop=2.8&focus=3m&sensor=sony-fx6-ff-4k-17-9&coc=cine"


def main() -> int:
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    out = ROOT / "docs" / "img"
    with running_server() as (url, _port, _proc), sync_playwright() as p:
        b = p.chromium.launch(executable_path=chromium, args=["--no-sandbox", "--disable-dev-shm-usage"])
        for device, (w, h), mobile in (("phone", (390, 844), True), ("tablet", (1024, 768), False)):
            for theme in ("dark", "light"):
                ctx = b.new_context(viewport={"width": w, "height": h}, device_scale_factor=2 if mobile else 1,
                                    is_mobile=mobile, has_touch=mobile)
                pg = ctx.new_page()
                pg.add_init_script(f"localStorage.setItem('physcam-theme', '{theme}');"
                                   "localStorage.setItem('physcam-coc', 'cine');")
                pg.goto(url + SETUP)
                pg.wait_for_selector("body[data-ready='1']")
                pg.fill("#split-near", "2.5m")
                pg.fill("#split-far", "4m")
                pg.fill("#ex-to-fps", "48")
                pg.wait_for_selector("#split-answer[data-focus]")
                pg.wait_for_timeout(800)  # the chart and the table settle
                pg.evaluate("() => { document.activeElement.blur(); window.scrollTo(0, 0); }")
                pg.wait_for_timeout(200)
                path = out / f"serve_{device}_{theme}.png"
                pg.screenshot(path=str(path))
                print(f"wrote {path.relative_to(ROOT)}")
                if device == "phone" and theme == "dark":  # the answers beyond depth of field, further down
                    pg.evaluate("() => window.scrollTo(0, document.getElementById('split-section').getBoundingClientRect().top"
                                " + window.scrollY - document.getElementById('top').offsetHeight - 8)")
                    pg.wait_for_timeout(200)
                    path = out / "serve_phone_tools_dark.png"
                    pg.screenshot(path=str(path))
                    print(f"wrote {path.relative_to(ROOT)}")
                ctx.close()
        b.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
