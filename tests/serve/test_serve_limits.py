"""`physcam serve` against abusive clients, over real sockets to the real process (issue 24 item 11).

One client address abuses the server (127.0.0.2, ...: Linux routes all of 127.0.0.0/8 to the
loopback interface, so a test can be several clients), another (127.0.0.1) uses it normally:
half-sent requests, a flood of slow work and oversized heads from the first must not lock out,
starve or slip past the bounds for the second (docs/serve.md, "Limits per address").
"""

from __future__ import annotations

import asyncio
import http.client
import json
import socket
import sys
import threading
import time
from urllib.parse import urlencode

import pytest
from _serve_helpers import running_server

LINUX = sys.platform.startswith("linux")
needs_loopback_net = pytest.mark.skipif(not LINUX, reason="needs 127.0.0.0/8 on loopback (Linux) for two client "
                                                          "addresses on one machine")
NORMAL, ABUSER = "127.0.0.1", "127.0.0.2"
FLOODERS = 20  # the addresses of test_many_flooding_addresses_do_not_starve_another
HEAD_TIMEOUT = 5.0  # the documented header timeout (Limits.head_timeout)


@pytest.fixture(scope="module")
def server():
    with running_server() as (_, port, proc):  # the default limits, as on set
        yield port, proc


def connect(port, source, timeout=10.0):
    return socket.create_connection(("127.0.0.1", port), timeout=timeout, source_address=(source, 0))


def read_answer(sock):
    """(status, headers, body) of the answer on ``sock``; (None, {}, b"") when it closes without one."""
    r = http.client.HTTPResponse(sock)
    try:
        r.begin()
    except http.client.RemoteDisconnected:
        return None, {}, b""
    return r.status, {k.lower(): v for k, v in r.getheaders()}, r.read()


def get(port, path, source=NORMAL, timeout=10.0):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout, source_address=(source, 0))
    try:
        c.request("GET", path)
        r = c.getresponse()
        return r.status, {k.lower(): v for k, v in r.getheaders()}, r.read()
    finally:
        c.close()


def assert_refusal(status, headers, body, expected):
    assert status == expected, (status, body[:200])
    assert headers["content-type"].startswith("application/json") and headers["connection"] == "close"
    assert body.count(b"\n") == 0 and json.loads(body)["error"]


def _trickle(port, source, out):
    """A head sent one header line each 0.5 s, never finished: when does the server answer?"""
    with connect(port, source) as s:
        t0 = time.monotonic()
        s.sendall(b"GET /api/health HTTP/1.1\r\nHost: x\r\n")
        s.settimeout(0.5)
        for i in range(30):
            try:
                first = s.recv(1)
            except TimeoutError:
                try:
                    s.sendall(f"X-Slow-{i}: {i}\r\n".encode())
                except OSError:
                    pass
                continue
            out["after"] = time.monotonic() - t0
            s.settimeout(5)
            rest = b""
            while chunk := s.recv(4096):
                rest += chunk
            out["answer"] = first + rest
            return


def _silent(port, source, out):
    """A connection that sends nothing: when is it closed, and with what?"""
    with connect(port, source) as s:
        t0 = time.monotonic()
        s.settimeout(15)
        data = b""
        try:
            while chunk := s.recv(4096):
                data += chunk
        except TimeoutError:
            return
        out["after"], out["answer"] = time.monotonic() - t0, data


@needs_loopback_net
def test_half_sent_requests_from_one_address_do_not_lock_out_another(server):
    """300 connections from one address, each with a head never finished: another address is
    answered at once; the first keeps 32 connections (the 33rd on is answered 429 and closed), and
    each of those is answered 408 five seconds after it opened, however slowly it trickles bytes."""
    port, proc = server
    trickled, silent = {}, {}
    threads = [threading.Thread(target=_trickle, args=(port, "127.0.0.3", trickled)),
               threading.Thread(target=_silent, args=(port, "127.0.0.4", silent))]
    for t in threads:
        t.start()
    socks, opened = [], []
    try:
        for _ in range(300):
            s = connect(port, ABUSER)
            s.sendall(b"GET /api/health HTTP/1.1\r\nHost: x\r\nX-Half: ")
            socks.append(s)
            opened.append(time.monotonic())
        for _ in range(20):
            t0 = time.monotonic()
            status, _, body = get(port, "/api/health", timeout=10)
            took = time.monotonic() - t0
            assert status == 200, (status, body)
            assert took < 2.0, f"the normal client waited {took:.2f} s"
        answers = []
        for s, t_open in zip(socks, opened):
            s.settimeout(HEAD_TIMEOUT + 5)
            status, headers, body = read_answer(s)
            answers.append(status)
            if status == 408:
                assert_refusal(status, headers, body, 408)
                waited = time.monotonic() - t_open
                assert HEAD_TIMEOUT - 0.5 < waited < HEAD_TIMEOUT + 2.5, waited
            else:
                assert_refusal(status, headers, body, 429)
        assert answers.count(408) == 32 and answers.count(429) == 268, {a: answers.count(a) for a in set(answers)}
    finally:
        for s in socks:
            s.close()
        for t in threads:
            t.join(30)
    # the clock does not restart when bytes trickle in; a connection that sends nothing is closed unanswered
    assert trickled and trickled["answer"].startswith(b"HTTP/1.1 408 "), trickled
    assert HEAD_TIMEOUT - 0.5 < trickled["after"] < HEAD_TIMEOUT + 2.0, trickled
    assert silent == {"after": pytest.approx(HEAD_TIMEOUT, abs=2.0), "answer": b""}, silent
    assert proc.poll() is None and get(port, "/api/health")[0] == 200


@needs_loopback_net
def test_connections_are_capped_in_all(server):
    """256 open connections in all (32 from each of 8 addresses): the next is answered 503."""
    port, _ = server
    socks = []
    try:
        for k in range(8):
            for _ in range(32):
                socks.append(connect(port, f"127.0.1.{k + 1}"))
        time.sleep(0.3)  # let the server accept them all
        with connect(port, "127.0.2.1") as s:
            s.sendall(b"GET /api/health HTTP/1.1\r\nHost: x\r\n\r\n")
            assert_refusal(*read_answer(s), 503)
    finally:
        for s in socks:
            s.close()
    time.sleep(0.3)
    assert get(port, "/api/health")[0] == 200


def _head(extra_bytes: int) -> bytes:
    head = b"GET /api/health HTTP/1.1\r\nHost: x\r\nX-Big: " + b"a" * extra_bytes + b"\r\n\r\n"
    return head


@pytest.fixture(scope="module", params=["default", "h11"])
def any_parser_server(request, server):
    """The server with its HTTP parser (httptools, installed by the serve extra), and with h11 (what
    serves when httptools is not installed): the same bounds."""
    if request.param == "default":
        yield server
        return
    with running_server(env={"PHYSCAM_HTTP_PARSER": "h11"}) as (_, port, proc):
        yield port, proc


def test_request_head_is_capped_at_16_kib_whole_or_in_pieces(any_parser_server):
    port, _ = any_parser_server
    big = _head(20_000)  # 20 KB of header, in one piece: h11 alone only bounds an incomplete head
    with connect(port, NORMAL) as s:
        s.sendall(big)
        assert_refusal(*read_answer(s), 431)
    with connect(port, NORMAL) as s:  # the same in 1 KB pieces
        for i in range(0, len(big), 1024):
            try:
                s.sendall(big[i:i + 1024])
            except OSError:  # refused part way: the answer is already there
                break
            time.sleep(0.002)
        assert_refusal(*read_answer(s), 431)
    ok = _head(15 * 1024)  # a 15 KiB header: the whole head is under 16 KiB
    assert len(ok) < 16 * 1024
    with connect(port, NORMAL) as s:
        s.sendall(ok)
        status, _, body = read_answer(s)
        assert status == 200 and json.loads(body)["ok"] is True


def test_malformed_http_is_one_json_line(any_parser_server):
    port, _ = any_parser_server
    with connect(port, NORMAL) as s:
        s.sendall(b"GET /api/health HTTP/1.1\r\nHost x no colon\r\n\r\n")
        assert_refusal(*read_answer(s), 400)


def test_pipelined_requests_are_answered_in_order_and_the_next_head_is_capped(any_parser_server):
    """Requests sent back to back in one write are answered in turn; a head over the cap that follows
    a small request in the same write is refused (its bytes are counted from its own start)."""
    port, _ = any_parser_server
    one = b"GET /api/health HTTP/1.1\r\nHost: x\r\n\r\n"

    def answers(s, n):  # (status, body) of n answers read from one stream (http.client would read ahead)
        f, out = s.makefile("rb"), []
        for _ in range(n):
            status = int(f.readline().split()[1])
            headers = dict(line.decode().lower().rstrip().split(": ", 1) for line in iter(f.readline, b"\r\n"))
            out.append((status, f.read(int(headers["content-length"]))))
        return out

    with connect(port, NORMAL) as s:
        s.sendall(one + b"GET /nope HTTP/1.1\r\nHost: x\r\n\r\n" + one)
        assert [status for status, _ in answers(s, 3)] == [200, 404, 200]
    with connect(port, NORMAL) as s:
        s.sendall(one + _head(20_000))
        (first, _), (second, body) = answers(s, 2)
        assert first == 200 and second == 431 and "over 16384 bytes" in json.loads(body)["error"]


# --- sharing the slow work ---------------------------------------------------------------------
def _chart(focus_mm: int) -> str:
    return "/api/dof.svg?" + urlencode({"focal": 50, "fstop": 2.8, "focus": f"{focus_mm}mm", "sensor": "S35"})


async def _flood(port, rate, seconds, statuses, stop, drawn):
    """Distinct charts from ABUSER at ``rate`` per second, open loop, one connection each; ``drawn``
    gets the time (monotonic) each chart answered 200 came back. Once ``stop`` is set the requests
    still waiting hang up (the server drops their charts)."""

    async def one(path):
        w = None
        try:
            r, w = await asyncio.open_connection("127.0.0.1", port, local_addr=(ABUSER, 0))
            w.write(f"GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n".encode())
            line = await asyncio.wait_for(r.readline(), 30)
            statuses.append(int(line.split()[1]) if line else None)
            if statuses[-1] == 200:
                drawn.append(time.monotonic())
        except (TimeoutError, OSError, ValueError, IndexError):
            statuses.append(None)
        finally:
            if w is not None:
                w.close()

    tasks, t0 = [], time.monotonic()
    for i in range(int(rate * seconds)):
        if stop.is_set():
            break
        await asyncio.sleep(max(0.0, t0 + i / rate - time.monotonic()))
        tasks.append(asyncio.ensure_future(one(_chart(3000 + i))))
    while not stop.is_set() and not all(t.done() for t in tasks):
        await asyncio.sleep(0.05)
    for t in tasks:
        t.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)


@needs_loopback_net
def test_a_flood_of_slow_work_from_one_address_does_not_starve_another(server):
    """40 distinct charts per second from one address (the worker draws about 20): a chart asked by
    another address waits for the chart being drawn and about one of the flood's, not the flood's
    queue. Counted in charts, not seconds, so a machine that slows down mid-test cannot fail it: at
    most 4 of the flood's charts come back while the other address waits (first come, first served
    lets the 8 the flood may queue go first: 8-9; before the fair worker: 503, or ~32)."""
    port, proc = server
    assert get(port, _chart(1000))[0] == 200  # the first chart imports matplotlib
    statuses, drawn, stop = [], [], threading.Event()
    flood = threading.Thread(target=lambda: asyncio.run(_flood(port, 40, 5, statuses, stop, drawn)))
    flood.start()
    try:
        time.sleep(2.0)  # the flood has filled whatever queue it can
        waits, passed = [], []
        for k in range(2):
            t0 = time.monotonic()
            status, _, body = get(port, _chart(1200 + k), timeout=30)
            t1 = time.monotonic()
            assert status == 200, (status, body[:200])
            waits.append(round(t1 - t0, 3))
            passed.append(sum(t0 < t <= t1 for t in list(drawn)))
        assert max(passed) <= 4, f"{passed} of the flood's charts came back while another address waited {waits} s"
    finally:
        stop.set()
        flood.join(60)
    # the flood was refused (429, its address's share is full), never a 5xx
    assert set(statuses) <= {200, 429} and 429 in statuses, {s: statuses.count(s) for s in set(statuses)}
    assert proc.poll() is None


async def _closed_loops(port, sources, loops, stop, statuses, drawn):
    """From each address in ``sources``, ``loops`` clients each asking a new distinct chart as soon as
    the last one is answered (after 0.2 s when refused); ``drawn`` gets the time each chart answered
    200 came back. Once ``stop`` is set every client hangs up, its chart no longer wanted (the
    server drops what nobody waits for: test_charts_for_clients_that_hung_up_are_not_drawn)."""

    async def loop(source, first):
        i = 0
        while not stop.is_set():  # (Python 3.11's wait_for can swallow a cancel that meets an answer)
            w = None
            try:
                r, w = await asyncio.open_connection("127.0.0.1", port, local_addr=(source, 0))
                w.write(f"GET {_chart(first + i)} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n".encode())
                line = await asyncio.wait_for(r.readline(), 180)
                status = int(line.split()[1]) if line else None
            except (TimeoutError, OSError, ValueError, IndexError):
                status = None
            finally:
                if w is not None:
                    w.close()
            i += 1
            statuses.append(status)
            if status == 200:
                drawn.append(time.monotonic())
            else:
                await asyncio.sleep(0.2)

    clients = [asyncio.ensure_future(loop(s, 100_000 + 1000 * (loops * k + j))) for k, s in enumerate(sources)
               for j in range(loops)]
    while not stop.is_set():
        await asyncio.sleep(0.05)
    for c in clients:
        c.cancel()
    await asyncio.gather(*clients, return_exceptions=True)


@pytest.mark.slow
@needs_loopback_net
def test_many_flooding_addresses_do_not_starve_another(server):
    """Issue 40 item 14: 20 addresses (127.0.3.1-20), each under its own rate limit, keep three charts
    each asked all the time. A chart from another address (127.0.4.1) is answered, after at most one
    chart of each of the 20 and the one being drawn: 21 by hand from the round robin, plus 3 for
    answers already on their way when the request left. Counted in charts, not seconds. Before,
    the flood held all 32 places of the queue and the other address was answered 503.

    The issue's 40 addresses with two charts each (80 asked) became 20 with three (60 asked) in round
    14: the other address waits for one chart per flooding address, so 20 halve the test's time (41
    charts of 0.3-1 s each on a loaded machine), and 60 charts asked still overfill the 32 places
    plus the one drawn, as 80 did, with no address at its own cap of 8: the same many-addresses
    flood. test_forty_addresses_cannot_fill_the_worker_against_a_41st keeps the issue's 40 on the
    worker itself."""
    port, proc = server
    assert get(port, _chart(1000))[0] == 200  # the first chart imports matplotlib
    sources = [f"127.0.3.{k}" for k in range(1, FLOODERS + 1)]
    statuses, drawn, stop = [], [], threading.Event()
    flood = threading.Thread(target=lambda: asyncio.run(_closed_loops(port, sources, 3, stop, statuses, drawn)))
    flood.start()
    try:
        time.sleep(3.0)  # every flooding address has work queued
        t0 = time.monotonic()
        status, _, body = get(port, _chart(1300), source="127.0.4.1", timeout=300)
        t1 = time.monotonic()
        assert status == 200, (status, body[:200])
        passed = sum(t0 < t <= t1 for t in list(drawn))
        assert passed <= FLOODERS + 1 + 3, \
            f"{passed} of the flood's charts came back while another address waited {t1 - t0:.1f} s"
    finally:
        stop.set()
        flood.join(300)
    # the flood's own answers: charts, its share refused (429, 503), never another 5xx (None: a client gave
    # up waiting on a loaded machine, which says nothing of the server)
    assert 200 in statuses and set(statuses) <= {200, 429, 503, None}, {s: statuses.count(s) for s in set(statuses)}
    assert proc.poll() is None


def test_the_worker_takes_one_job_from_each_address_in_turn():
    """Jobs queued while A0 holds the worker: A1 A2 (A3 refused: A has 3 pending with A0), B1,
    C1 C2, D1 (7 pending in all), E1 (taken: E's first job), C3 refused (a further job with 8
    pending in all). Round robin over the addresses in order of arrival, one job each per turn,
    worked by hand: A1 B1 C1 D1 E1, then A2 C2."""
    from physcam.serve.worker import FairWorker, Full

    done, gate = [], threading.Event()
    w = FairWorker(per_client=3, total=7)
    started = threading.Event()
    futures = [w.submit("A", lambda: (started.set(), gate.wait()))]  # A0 holds the worker until the queue is built
    assert started.wait(10)
    for who, name in [("A", "A1"), ("A", "A2"), ("B", "B1"), ("C", "C1"), ("C", "C2")]:
        futures.append(w.submit(who, lambda n=name: done.append(n)))
    with pytest.raises(Full) as over:  # A has three pending (A0 runs, A1 and A2 wait)
        w.submit("A", lambda: done.append("A3"))
    assert over.value.everyone is False
    futures.append(w.submit("D", lambda: done.append("D1")))  # 7 pending in all
    futures.append(w.submit("E", lambda: done.append("E1")))  # an address's first job is always taken
    with pytest.raises(Full) as full:  # a further job of C, with 8 pending in all
        w.submit("C", lambda: None)
    assert full.value.everyone is True
    gate.set()
    for f in futures:
        f.result(timeout=10)
    assert done == ["A1", "B1", "C1", "D1", "E1", "A2", "C2"]
    assert w.pending() == 0
    w.close()


def test_forty_addresses_cannot_fill_the_worker_against_a_41st():
    """Issue 40 item 14: 40 addresses queue all the slow work they may (the server's own bounds: 8
    each, 32 in all) while one job holds the worker. A 41st address is still taken, and its job
    runs after at most one job of each of the 40 (counted in jobs: 40, worked by hand from the
    round robin); the old worker answered it Full (503) because the 40 held all 32 places."""
    from physcam.serve.worker import FairWorker, Full

    w = FairWorker(per_client=8, total=32)
    gate, started, order = threading.Event(), threading.Event(), []
    futures = [w.submit("hold", lambda: (started.set(), gate.wait()))]
    assert started.wait(10)
    flood = [f"127.0.3.{k}" for k in range(1, 41)]
    taken = {a: 0 for a in flood}
    for _ in range(8):  # each address asks for as much as it may, in turn
        for a in flood:
            try:
                futures.append(w.submit(a, lambda a=a: order.append(a)))
                taken[a] += 1
            except Full:
                pass
    assert all(n >= 1 for n in taken.values())  # every flooding address got its first job in
    late = w.submit("127.0.4.1", lambda: order.append("late"))
    gate.set()
    late.result(timeout=30)
    for f in futures:
        f.result(timeout=30)
    assert order.index("late") <= len(flood), order[:50]
    w.close()


def test_the_worker_bounds_the_addresses_with_work():
    from physcam.serve.worker import FairWorker, Full

    w = FairWorker(per_client=2, total=8, addresses=2)
    gate = threading.Event()
    futures = [w.submit("A", gate.wait), w.submit("B", lambda: None)]
    with pytest.raises(Full) as full:
        w.submit("C", lambda: None)
    assert full.value.everyone is True and full.value.limit == 2
    gate.set()
    for f in futures:
        f.result(timeout=10)
    assert w.submit("C", lambda: 7).result(timeout=10) == 7  # room again once A and B are done
    w.close()


def _slow_stats(port) -> dict:
    """The server's own count of its slow jobs (/api/health): done, dropped, pending."""
    status, _, body = get(port, "/api/health")
    assert status == 200
    return json.loads(body)["slow"]


def _settled_stats(port) -> dict:
    """:func:`_slow_stats` once the worker has nothing pending (at most 30 s)."""
    for _ in range(300):
        stats = _slow_stats(port)
        if stats["pending"] == 0:
            break
        time.sleep(0.1)
    return stats


@needs_loopback_net
def test_charts_for_clients_that_hung_up_are_not_drawn(server):
    """Round 13: one address asks 8 new charts on 8 connections and hangs up at once (a phone that
    gave up, a retrying script's timeout). The worker draws at most the one it had already started
    (counted by the server itself: /api/health's jobs done); the rest are dropped, or never queued
    when the hang-up is seen first, and another address's chart is answered. Before, the worker
    drew all 8 for nobody (9 done with the other's)."""
    port, proc = server
    assert get(port, _chart(1000))[0] == 200  # the first chart imports matplotlib
    before = _settled_stats(port)  # (nothing left of a test before)
    socks = [connect(port, "127.0.5.1") for _ in range(8)]
    for k, s in enumerate(socks):
        s.sendall(f"GET {_chart(7000 + k)} HTTP/1.1\r\nHost: x\r\n\r\n".encode())
    for s in socks:
        s.close()
    status, _, body = get(port, _chart(7100), source="127.0.5.2", timeout=60)
    assert status == 200 and body.startswith(b"<?xml")
    after = _settled_stats(port)  # (the old code: 7 more charts to draw)
    done = after["done"] - before["done"]
    assert after["pending"] == 0 and 1 <= done <= 2, (before, after)
    assert proc.poll() is None


@needs_loopback_net
def test_a_client_that_timed_out_and_asks_again_keeps_its_place(server):
    """Review of round 13: a script whose timeout is shorter than its wait asks the same chart
    again. Its first request is queued behind another address's charts and hangs up; the retry
    joins that job where it stands, and the chart is drawn once for it: nothing dropped. Before
    the fix the hang-up dropped the job at once and the retry went to the back of the queue (under
    a steady flood it never got its chart: 25 tries in 25 s, answered at the second try before
    round 13); here that is one job dropped."""
    port, _ = server
    assert get(port, _chart(1000), timeout=60)[0] == 200  # the first chart imports matplotlib
    before = _settled_stats(port)
    busy = [connect(port, "127.0.6.1", timeout=60) for _ in range(3)]
    for k, s in enumerate(busy):  # another address keeps the worker drawing meanwhile
        s.sendall(f"GET {_chart(8000 + k)} HTTP/1.1\r\nHost: x\r\n\r\n".encode())
    first = connect(port, "127.0.6.2")
    try:
        first.sendall(f"GET {_chart(8100)} HTTP/1.1\r\nHost: x\r\n\r\n".encode())
        for _ in range(200):  # queued (counted pending) before it hangs up
            if _slow_stats(port)["pending"] - before["pending"] >= 4:
                break
            time.sleep(0.01)
    finally:
        first.close()
    status, _, body = get(port, _chart(8100), source="127.0.6.2", timeout=60)
    try:
        assert status == 200 and body.startswith(b"<?xml")
        assert [read_answer(s)[0] for s in busy] == [200] * 3
    finally:
        for s in busy:
            s.close()
    after = _settled_stats(port)
    assert after["dropped"] - before["dropped"] == 0 and after["done"] - before["done"] == 4, (before, after)


def test_the_worker_drops_a_job_nobody_wants_at_its_turn():
    """A job submitted with ``wanted`` is asked at its turn: False, and it is dropped (never run, its
    future cancelled, counted); True, and it runs. Until its turn it keeps its place (A's two places
    stay taken). The counts are settled before the job's waiters wake."""
    from physcam.serve.worker import Full, FairWorker

    w = FairWorker(per_client=2, total=8)
    gate, started, done, want = threading.Event(), threading.Event(), [], {"A1": True, "B1": True}
    hold = w.submit("A", lambda: (started.set(), gate.wait()))
    assert started.wait(10)
    a1 = w.submit("A", lambda: done.append("A1"), wanted=lambda: want["A1"])
    b1 = w.submit("B", lambda: done.append("B1"), wanted=lambda: want["B1"])
    want["A1"] = False  # its client left while it waited
    with pytest.raises(Full):
        w.submit("A", lambda: None)  # A's places are both still taken until A1's turn
    gate.set()
    hold.result(timeout=10)
    b1.result(timeout=10)
    assert w.stats() == {"done": 2, "dropped": 1, "pending": 0}, w.stats()
    assert a1.cancelled() and done == ["B1"]
    w.close()


def test_the_worker_drops_a_cancelled_job_before_it_starts():
    """A job cancelled while it waits leaves its queue at once: it never runs, its address's place
    is free again (per_client 2: A may queue another), the others run in turn, and the worker
    counts it dropped. A job already running cannot be cancelled (concurrent.futures). Before,
    a cancelled job held its place until the worker reached it."""
    from physcam.serve.worker import FairWorker

    w = FairWorker(per_client=2, total=8)
    gate, started, done = threading.Event(), threading.Event(), []
    hold = w.submit("A", lambda: (started.set(), gate.wait()))
    assert started.wait(10)
    a1 = w.submit("A", lambda: done.append("A1"))
    b1 = w.submit("B", lambda: done.append("B1"))
    assert not hold.cancel() and a1.cancel()
    assert w.pending("A") == 1 and w.stats() == {"done": 0, "dropped": 1, "pending": 2}
    a2 = w.submit("A", lambda: done.append("A2"))  # A's second place is free again
    gate.set()
    for f in (hold, b1, a2):
        f.result(timeout=10)
    assert done == ["B1", "A2"] and w.stats() == {"done": 3, "dropped": 1, "pending": 0}
    w.close()


def test_one_question_asked_at_once_by_many_connections_is_computed_once(server):
    """Issue 47: 24 connections of one address ask the same new chart at the same moment (a page
    reloaded on many phones, a benchmark's repeated query). They wait for the one computation
    instead of each queueing its own copy: every answer is 200 and the same chart. Before, each
    request put its own job on the worker, the address's 8 places filled (Limits.client_queue)
    and the rest were answered 429 while the worker drew the same chart over and over."""
    port, proc = server
    path = _chart(4321)
    socks = [connect(port, NORMAL, timeout=60) for _ in range(24)]
    try:
        for s in socks:  # every request sent before any answer is read
            s.sendall(f"GET {path} HTTP/1.1\r\nHost: x\r\n\r\n".encode())
        answers = [read_answer(s) for s in socks]
    finally:
        for s in socks:
            s.close()
    statuses = [a[0] for a in answers]
    assert statuses == [200] * 24, {s: statuses.count(s) for s in set(statuses)}
    assert len({a[2] for a in answers}) == 1 and answers[0][2].startswith(b"<?xml")
    assert proc.poll() is None


_HEAP_SCRIPT = """
import gc, json, sys
from physcam.serve import Backend, asgi_get, create_app

def lens(name, q):  # a first answer that imports code, as the first chart imports matplotlib
    import xml.dom.minidom
    return {"name": name, "parsed": xml.dom.minidom.parseString("<a/>").documentElement.tagName}

def refuse(*args):
    raise AssertionError("not asked")

assert "xml.dom.minidom" not in sys.modules
app = create_app(Backend(report=refuse, dof_svg=refuse, sensors=refuse, lenses=refuse, lens=lens,
                         diagram_svg=refuse, parameters={"lens": frozenset()}))
first = asgi_get(app, "/api/lens/a")  # slow work: the worker thread
frozen = gc.get_freeze_count()
second = asgi_get(app, "/api/lens/b")  # imports nothing
print(json.dumps({"answers": [json.loads(first[2]), json.loads(second[2])], "frozen": frozen,
                  "frozen_after_second": gc.get_freeze_count(), "tracked": len(gc.get_objects())}))
"""


def test_the_code_a_first_answer_imports_is_kept_out_of_the_collectors_full_passes():
    """Issue 47: a full cycle collection visits every object the collector tracks and holds the
    GIL meanwhile, so the modules a server has imported (numpy, matplotlib, the lens library: about
    90,000 objects) stalled every request for 25-105 ms of CPU at each full pass (measured,
    docs/performance.md). After an answer whose computation imported code (in physcam serve: the
    first chart, the first diagram) the heap is settled: a full pass then visits under a tenth of
    the objects the process holds. A second answer, importing nothing, freezes nothing more (a
    settle keeps what is alive at that moment for good, so it must stay rare). Old code: nothing
    frozen, a full pass visits everything."""
    import subprocess

    out = subprocess.run([sys.executable, "-c", _HEAP_SCRIPT], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr[-2000:]
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["answers"] == [{"name": "a", "parsed": "a"}, {"name": "b", "parsed": "a"}]
    assert got["frozen"] > 0 and got["frozen_after_second"] <= got["frozen"]  # frozen objects may still be freed
    assert got["tracked"] < 0.1 * (got["tracked"] + got["frozen"]), got
