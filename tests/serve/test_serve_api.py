"""`physcam serve` over real HTTP: the API answers the CLI's own --json documents, refuses bad input
with 422 and one line (never a traceback, never a 5xx), keeps its limits, and stays up under fuzzing."""

from __future__ import annotations

import json
import socket
import time
import xml.etree.ElementTree as ET
from urllib.parse import quote, urlencode

import pytest
from _serve_helpers import get_json, request, running_server
from hypothesis import given, settings
from hypothesis import strategies as st

import physcam
from physcam.cli import main
from physcam.errors import InputError
from physcam.serve import bind_socket, lan_addresses, qr_text


@pytest.fixture(scope="module")
def server():
    with running_server("--rate-limit", "100000") as (url, port, proc):
        yield port, proc


def cli_json(capsys, argv):
    capsys.readouterr()
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def flags(params: dict) -> list[str]:
    return [f"--{k}={v}" for k, v in params.items()]


REPORTS = [
    {"focal": "50", "fstop": "2.8", "focus": "3m", "sensor": "S35"},
    {"focal": "35", "focus": "10ft", "near": "8ft", "far": "14ft", "coc": "0.025", "tstop": "2.8"},  # f-stop solved
    {"focal": "50", "near": "2.5m", "far": "4m", "fstop": "4", "sensor": "S35"},  # focus solved from the bracket
    {"focal": "40", "fstop": "2", "focus": "10'6\"", "squeeze": "2", "sensor": "anamorphic-35"},
    {"focal": "50", "fstop": "2", "focus": "2m", "model": "technical", "h1": "62", "h2": "51.3", "pupil": "92"},
    {"focal": "24", "fstop": "8", "focus": "100m", "sensor-width": "36", "sensor-height": "24", "coc": "d/1000"},
    {"lens": "dgauss_50mm", "fstop": "2.8", "focus": "2m"},
    {"focal": "50", "fstop": "2.8", "focus": "10’6”"},  # an iPhone's smart quotes (422 before round 22)
    {"focal": "35", "fstop": "4", "focus": "10′ 6″", "near": "8’", "far": "14’"},  # primes
]


@pytest.mark.parametrize("params", REPORTS, ids=lambda p: "&".join(f"{k}={v}" for k, v in p.items()))
def test_report_is_the_cli_json(server, capsys, params):
    port, _ = server
    status, got = get_json(port, "/api/report?" + urlencode(params))
    assert status == 200, got
    assert got == cli_json(capsys, ["report", *flags(params)])


#: Values of the page's practical report (and a few it refuses), for the property tests below.
PRACTICAL = {
    "focal": st.sampled_from(["18", "25", "35", "50", "85.5", "135", "0", "-5", "abc", "2in"]),
    "fstop": st.sampled_from(["1.4", "2", "2.8", "4", "5.6", "11", "0.3", "x"]),
    "focus": st.one_of(st.integers(300, 60000).map(lambda mm: f"{mm}mm"),
                       st.sampled_from(["2.5m", "10ft", "10'6\"", "hyperfocal", "infinity", "3000", "-2m", "1e9"])),
    "sensor": st.sampled_from(["S35", "ALEXA 35", "FF", "VENICE 2", "Super 16", "anamorphic-35", "nope"]),
    "coc": st.sampled_from(["0.025", "d/1500", "d/1000", "cine", "25um", "bogus"]),
    "squeeze": st.sampled_from(["1", "1.33", "2", "0"]),
    "tstop": st.sampled_from(["2.1", "4.2"]),
    "near": st.sampled_from(["2m", "8ft", "2500"]),
    "far": st.sampled_from(["4m", "inf", "14ft"]),
    "units": st.sampled_from(["m", "ft", "yards"]),
    "model": st.sampled_from(["practical", "technical"]),
    "shutter-angle": st.sampled_from(["180", "172.8", "-1"]),
}
practical_queries = st.fixed_dictionaries(
    {"focal": PRACTICAL["focal"], "fstop": PRACTICAL["fstop"]},
    optional={k: v for k, v in PRACTICAL.items() if k not in ("focal", "fstop")})


def test_distinct_reports_are_the_cli_json(server, capsys):
    """Random setups as the page sends them per keystroke: the server answers the CLI's --json, and
    refuses (422, one line) what the CLI refuses (exit 2)."""
    port, _ = server

    @settings(max_examples=40, deadline=None, database=None)
    @given(practical_queries)
    def same(params):
        status, got = get_json(port, "/api/report?" + urlencode(params))
        capsys.readouterr()
        code = main(["report", *flags(params), "--json"])
        out = capsys.readouterr()
        if code == 0:
            assert status == 200 and got == json.loads(out.out), (params, got)
        else:
            assert code == 2 and status == 422 and "\n" not in got["error"], (params, got, out.err)

    same()


def test_the_servers_query_parser_is_argparses():
    """cli.serve's parser of a report query (argparse's conversions without its scan, issue 47) gives
    parse_args's namespace, and its refusal word for word."""
    from physcam.cli import build_parser
    from physcam.cli.serve import _leaf, _options, _QueryParser

    parser = _leaf(build_parser(["report"]), "report")
    quick = _QueryParser(parser)

    def outcome(parse):
        try:
            return vars(parse())
        except InputError as exc:
            return str(exc)

    @settings(max_examples=80, deadline=None, database=None)
    @given(practical_queries)
    def same(params):
        assert outcome(lambda: quick.parse(params)) == outcome(lambda: parser.parse_args(_options(params)))

    same()


def test_typographic_feet_and_inches_are_read(server):
    """GET /api/report?focus=10%E2%80%996%E2%80%9D (10’6”, as a phone types 10'6") marks 10 ft 6 in = 3200.4 mm
    (by hand: 126 in x 25.4 mm); it was a 422 "cannot read focus distance"."""
    port, _ = server
    status, got = get_json(port, "/api/report?focal=50&fstop=2.8&focus=10%E2%80%996%E2%80%9D")
    assert status == 200, got
    assert got["focus_from_film_mm"] == pytest.approx(3200.4, rel=1e-12)


def test_far_at_infinity_is_null(server):
    status, d = get_json(port := server[0], "/api/report?focal=24&fstop=8&focus=100m&sensor=FF")
    assert status == 200 and d["dof"]["far_from_film_mm"] is None and d["dof"]["far_is_infinite"] is True
    assert port


def test_lists_and_lens_are_the_cli_json(server, capsys):
    port, _ = server
    # the lists are the rows of the CLI's documents (physcam sensors|lenses --json: {"sensors": [...]})
    assert get_json(port, "/api/sensors") == (200, cli_json(capsys, ["sensors"])["sensors"])
    assert get_json(port, "/api/sensors?name=" + quote("ALEXA 35")) == (
        200, cli_json(capsys, ["sensors", "ALEXA 35"])["sensors"])
    assert get_json(port, "/api/lenses") == (200, cli_json(capsys, ["lenses"])["lenses"])
    assert get_json(port, "/api/lens/dgauss_50mm?focus=2m&fstop=2.8") == (
        200, cli_json(capsys, ["lens", "show", "dgauss_50mm", "--focus", "2m", "--fstop", "2.8"]))
    # an alias names the same bundled lens
    assert get_json(port, "/api/lens/dgauss.50mm?focus=2m&fstop=2.8")[1]["lens"] == "Double Gauss 50mm f/2 (pbrt dgauss.50mm)"


def test_focus_table_is_the_cli_json_per_mark(server, capsys):
    port, _ = server
    base = {"focal": "50", "fstop": "2.8", "sensor": "S35"}
    status, rows = get_json(port, "/api/focus-table?" + urlencode({**base, "marks": "1m,10ft,20mm"}))
    assert status == 200
    assert [r["focus"] for r in rows] == ["1m", "10ft", "20mm"]
    assert rows[0]["report"] == cli_json(capsys, ["report", *flags({**base, "focus": "1m"})])
    assert rows[1]["report"] == cli_json(capsys, ["report", *flags({**base, "focus": "10ft"})])
    # a thin lens cannot focus closer than 4f from the film (s + s' = D has no real root below it)
    assert "report" not in rows[2] and "200 mm from the film plane" in rows[2]["error"]


@pytest.mark.parametrize("path", ["/api/dof.svg?focal=50&fstop=2.8&focus=3m&squeeze=2",
                                  "/api/dof.svg?focal=24&fstop=8&focus=100m",
                                  "/api/lens/dgauss_50mm/diagram.svg?fstop=4&focus=2m",
                                  "/api/lens/navarro_anamorphic_2x/diagram.svg?axis=x"])
def test_svg(server, path):
    status, headers, body = request(server[0], path)
    assert status == 200, body[:300]
    assert headers["content-type"].startswith("image/svg+xml")
    assert ET.fromstring(body).tag == "{http://www.w3.org/2000/svg}svg"


def test_page_and_its_files_ship_in_the_package(server):
    port, _ = server
    status, headers, body = request(port, "/")
    assert status == 200 and headers["content-type"].startswith("text/html")
    page = body.decode()
    assert "/static/app.js" in page and "/static/app.css" in page
    assert "http://" not in page and "https://" not in page  # no CDN: nothing from elsewhere
    for f in ("/static/app.js", "/static/app.css", "/static/icon.svg"):
        status, _, body = request(port, f)
        assert status == 200 and body
        if not f.endswith(".svg"):  # (an SVG names its XML namespace by URL, which loads nothing)
            assert b"http://" not in body and b"https://" not in body
    assert "script-src 'self'" in headers["content-security-policy"]
    assert headers["x-content-type-options"] == "nosniff"
    assert request(port, "/", method="HEAD")[0] == 200


LONG = "5" * 100
REFUSALS = [
    ("/api/report?focal=abc&fstop=2&focus=3m", 422, "focal: cannot read focal length 'abc'"),
    ("/api/report?focal=50&fstop=0.3&focus=3m", 422, "out of range"),
    ("/api/report?focal=50&fstop=2&focus=3m&bogus=1", 422, "unknown parameter 'bogus'"),
    ("/api/report?focal=50&fstop=2&focus=3m&plot=x.svg", 422, "unknown parameter 'plot'"),
    ("/api/report?focal=50&focal=51&fstop=2&focus=3m", 422, "given twice"),
    (f"/api/report?focal={LONG}", 422, "longer than 64"),
    ("/api/report?focal=50%0a&fstop=2", 422, "control character"),
    ("/api/report?" + "&".join(f"x{i}=1" for i in range(40)), 422, "more than 32"),
    ("/api/report?lens=..%2F..%2Fetc%2Fpasswd&focus=3m", 422, "bundled lenses"),
    ("/api/report?lens=%2Fdev%2Fnull&focus=3m", 422, "bundled lenses"),
    ("/api/report?focal=50&fstop=2&near=4m&far=3m", 422, "must be closer"),
    ("/api/report?focal=%ff", 422, "UTF-8"),
    ("/api/focus-table?focal=50&fstop=2&marks=" + ",".join(["1m"] * 20), 422, "at most 16"),
    ("/api/focus-table?focal=50&fstop=2", 422, "give the focus marks"),
    ("/api/sensors?name=nope", 422, "unknown sensor"),
    ("/api/lens/nope?focus=2m", 422, "no bundled lens"),
    ("/api/lens/dgauss_50mm/diagram.svg?output=%2Ftmp%2Fx.svg", 422, "unknown parameter 'output'"),
    ("/api/lens/dgauss_50mm?focus=-3m", 422, "focus"),
    ("/nope", 404, "no such page"),
    ("/api/report/../../etc/passwd", 404, "no such page"),
    ("/api/report?" + "a" * 3000, 414, "longer than 2048"),
]


@pytest.mark.parametrize("path, status, fragment", REFUSALS, ids=[r[0][:60] for r in REFUSALS])
def test_refusals_are_one_json_line(server, path, status, fragment):
    got, headers, body = request(server[0], path)
    assert got == status, body
    assert headers["content-type"].startswith("application/json")
    err = json.loads(body)["error"]
    assert fragment in err and "\n" not in err and "Traceback" not in err


def test_a_space_of_any_width_is_text_not_a_control_character(server, capsys):
    """A no-break space (a phone keyboard's, "3\u00a0m") was refused as a control character, though the command
    line reads it; the server answers as `physcam report` does. A line break, a bidi override and a NUL are
    still refused."""
    port, _ = server
    status, got = get_json(port, "/api/report?focal=50&fstop=2.8&focus=3%C2%A0m")
    assert status == 200, got
    assert got == cli_json(capsys, ["report", "--focal", "50", "--fstop", "2.8", "--focus", "3\u00a0m"])
    for bad in ("%0a", "%E2%80%AE", "%00", "%E2%80%A8"):
        got, _, body = request(port, f"/api/report?focal=50&fstop=2.8&focus=3m{bad}")
        assert got == 422 and "control character" in json.loads(body)["error"], (bad, body)


def test_methods_and_bodies_are_refused(server):
    port, _ = server
    status, headers, body = request(port, "/api/report?focal=50", method="POST", body=b"x=1")
    assert status == 405 and headers["allow"] == "GET, HEAD" and "GET only" in json.loads(body)["error"]
    status, _, body = request(port, "/api/health", body=b"0123456789")  # a GET with a body
    assert status == 413 and "no request body" in json.loads(body)["error"]
    # raw bytes that are not even ASCII in the request line: refused by the HTTP layer, server stays up
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(b"GET /api/report?focal=\xff\xfe HTTP/1.1\r\nHost: x\r\n\r\n")
        assert s.recv(100).split(b" ")[1] in (b"400", b"422")
    status, health = get_json(port, "/api/health")
    assert status == 200 and health == {"ok": True, "version": physcam.__version__,
                                        "units": "m",  # the page's default: the user config's units (none here)
                                        "slow": health["slow"]}
    assert set(health["slow"]) == {"done", "dropped", "pending"}  # the worker's jobs (round 13)
    assert all(isinstance(v, int) and v >= 0 for v in health["slow"].values())


NAMES = ["focal", "fstop", "tstop", "focus", "sensor", "sensor-width", "sensor-height", "squeeze", "coc", "near",
         "far", "model", "h1", "h2", "pupil", "reference", "flange", "sensor-front", "lens-length", "pupil-fraction",
         "meters-per-unit", "shutter-angle", "shift-x", "shift-y", "lens", "marks", "name", "axis", "field",
         "wavelength", "focus-method", "bogus", "json", "plot", ""]
VALUES = ["0", "-1", "1", "2.8", "50", "1e308", "-1e308", "5e-324", "1e12", "nan", "inf", "-inf", "", "abc", "3m",
          "10ft", "10'6\"", "0.001mm", "100000", "-0", "S35", "ALEXA", "dgauss_50mm", "navarro_anamorphic_2x",
          "../../etc/passwd", "technical", "flange", "x", "y", "d/1500", "cine", "1m,2m,3m", "∞", "日本", "%",
          "\u202e", "a" * 80]
ENDPOINTS = ["/api/report", "/api/focus-table", "/api/dof.svg", "/api/sensors", "/api/lens/dgauss_50mm",
             "/api/lens/fisheye_10mm/diagram.svg", "/api/lenses", "/api/health", "/api/lens/%00"]


@pytest.mark.slow
def test_fuzzed_queries_never_break_the_server(server):
    port, proc = server

    @settings(max_examples=150, database=None)
    @given(st.sampled_from(ENDPOINTS),
           st.lists(st.tuples(st.sampled_from(NAMES), st.sampled_from(VALUES)), max_size=6))
    def one(endpoint, pairs):
        path = endpoint + ("?" + urlencode(pairs) if pairs else "")
        status, headers, body = request(port, path)
        assert status in (200, 404, 414, 422), (path, status, body[:300])
        if status != 200:
            err = json.loads(body)["error"]
            assert "\n" not in err and "Traceback" not in err

    one()
    assert proc.poll() is None
    assert get_json(port, "/api/health")[0] == 200
    log = "".join(proc.stderr_lines)
    assert "Traceback" not in log and "internal error" not in log, log[-3000:]


def test_rate_limit_answers_429_then_recovers():
    with running_server("--rate-limit", "5") as (_, port, proc):
        statuses = [request(port, "/api/health") for _ in range(30)]
        assert {s for s, _, _ in statuses} <= {200, 429}
        refused = [(h, b) for s, h, b in statuses if s == 429]
        assert refused, "30 requests at once from one address must exceed a 5/s limit (bursts of 10)"
        assert int(refused[0][0]["retry-after"]) >= 1
        assert "too many requests" in json.loads(refused[0][1])["error"]
        time.sleep(1.5)
        assert request(port, "/api/health")[0] == 200


def _decode_terminal_qr(text: str):
    """Decode a QR code drawn in Unicode half blocks (segno's compact terminal output) with OpenCV's
    detector: full block = two light modules, upper half = light above dark, lower half = the reverse."""
    import cv2
    import numpy as np

    rows = [line for line in text.splitlines() if line]
    width = max(len(r) for r in rows)
    img = np.zeros((2 * len(rows), width), np.uint8)
    for r, line in enumerate(rows):
        for c, ch in enumerate(line.ljust(width, "█")):
            img[2 * r, c] = 255 if ch in "█▀" else 0
            img[2 * r + 1, c] = 255 if ch in "█▄" else 0
    # OpenCV's detector misses a valid code at some sizes (http://192.0.2.2:34499/ at 8 px a module with
    # 4 modules of padding, found at 4 and 6 px and with 8 modules): the first answer of a few sizes and
    # both of its detectors. Any answer is a decode of the drawn modules, compared whole with the URL.
    for pad, scale in ((4, 8), (8, 8), (4, 5), (12, 10)):
        big = cv2.resize(np.pad(img, pad, constant_values=255), None, fx=scale, fy=scale,
                         interpolation=cv2.INTER_NEAREST)
        for detector in (cv2.QRCodeDetector(), cv2.QRCodeDetectorAruco()):
            data, _, _ = detector.detectAndDecode(big)
            if data:
                return data
    return ""


def test_qr_code_decodes_to_the_url():
    for url in ("http://192.168.1.20:8765/", "http://10.0.0.7:41234/", "http://192.0.2.2:34499/"):
        assert _decode_terminal_qr(qr_text(url)) == url


def test_lan_addresses_are_this_machines():
    for addr in lan_addresses():
        assert not addr.startswith("127.")
        bind_socket(addr, 0).close()  # only an address of this machine can be bound


def test_port_in_use_is_one_line(capsys):
    s = bind_socket("127.0.0.1", 0)
    try:
        port = s.getsockname()[1]
        with pytest.raises(InputError, match="in use"):
            bind_socket("127.0.0.1", port)
        capsys.readouterr()
        assert main(["serve", "--port", str(port), "--check"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("physcam: error: cannot listen")
    finally:
        s.close()


def test_check_on_every_interface_prints_a_qr_for_phones(capsys):
    assert main(["serve", "--host", "0.0.0.0", "--port", "0", "--check"]) == 0
    out = capsys.readouterr().out
    assert "check: the page and /api/report answer" in out
    lines = out.splitlines()
    opener = [i for i, line in enumerate(lines) if line.startswith("on a phone on this network open ")]
    if not lan_addresses():
        assert "no network address found" in out
        return
    i = opener[0]
    url = lines[i].split("open ", 1)[1].split()[0]
    end = next(j for j in range(i + 1, len(lines)) if not set(lines[j]) <= set("█▀▄ "))
    assert _decode_terminal_qr("\n".join(lines[i + 1:end])) == url


def test_ctrl_c_stops_the_server_cleanly():
    import signal

    with running_server() as (_, port, proc):
        assert request(port, "/api/health")[0] == 200
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=30) == 0
        assert "Traceback" not in "".join(proc.stderr_lines)
