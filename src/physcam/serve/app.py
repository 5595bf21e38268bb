"""The ASGI application of ``physcam serve``: routes, validation, limits, caching.

Routes (GET or HEAD only; every answer is JSON, SVG or the page):

=====================================  =============================================================
``/``                                  the page (``static/index.html``, ``app.js``, ``onset.js``, ``app.css``)
``/sw.js``, ``/manifest.webmanifest``  the installable web app: service worker (offline) and manifest
``/api/report?focal=50&fstop=2.8...``  ``physcam report ... --json``
``/api/focus-table?...&marks=1m,2m``   ``physcam report ... --json`` once per focus mark
``/api/dof.svg?...``                   ``physcam report ... --plot dof.svg``, drawn in memory
``/api/sensors[?name=S35]``            ``physcam sensors [NAME] --json``'s ``sensors`` list
``/api/lenses``                        ``physcam lenses --json``'s ``lenses`` list
``/api/lens/{name}?focus=2m...``       ``physcam lens show NAME ... --json``
``/api/lens/{name}/diagram.svg?...``   ``physcam lens diagram NAME ... -o diagram.svg``
``/api/health``                        ``{"ok": true, "version": ..., "units": "m" or "ft", "slow": {...}}``
=====================================  =============================================================

Query parameters are the CLI flags without their dashes (``sensor-width=24.89``); which ones an
endpoint takes comes from the backend (the CLI's own parsers). Safety, all in
:class:`Limits`: a bounded URL, a bounded number and length of parameters, printable values only,
no request body, a token bucket per client address (429 with ``Retry-After``), the slow work
shared between client addresses in turn with bounded queues (worker.py: an address's first slow
request always taken; 429 for one address's share, 503 in all; a job dropped at its turn
when every client asking it has hung up, counted in ``/api/health``'s "slow"), and one JSON line
``{"error": "..."}`` for every refusal (422 for bad input), never a traceback. An unexpected exception answers 500 with its class name and is
logged as one line; the server keeps serving.
"""

from __future__ import annotations

import asyncio
import gc
import json
import sys
import time
from collections import OrderedDict
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from importlib import resources
from urllib.parse import parse_qsl

from .. import __version__
from ..errors import PhysCamError, WrongTypeError
from .worker import FairWorker, Full

def _holds_control(value: str) -> bool:
    """Whether a query value holds what no written line may (controls, format characters such as the bidi
    overrides, surrogates, line and paragraph separators: ``physcam.export._codetext.UNSAFE_CATEGORIES``). A
    space of any width (a no-break space from a phone's keyboard, "3\u00a0m") is text the command line reads too
    (``str.isprintable`` refused it)."""
    if value.isprintable():
        return False
    import unicodedata

    from ..export._codetext import UNSAFE_CATEGORIES

    return any(unicodedata.category(c) in UNSAFE_CATEGORIES for c in value)

__all__ = ["Backend", "Limits", "create_app", "settle_heap", "STATIC_FILES"]

#: The page's files (package data, ``physcam/serve/static``) and their media types.
STATIC_FILES = {
    "index.html": "text/html; charset=utf-8",
    "app.js": "text/javascript; charset=utf-8",
    "onset.js": "text/javascript; charset=utf-8",
    "tools.js": "text/javascript; charset=utf-8",
    "app.css": "text/css; charset=utf-8",
    "icon.svg": "image/svg+xml",
    "icon-192.png": "image/png",
    "icon-512.png": "image/png",
    "sw.js": "text/javascript; charset=utf-8",
    "manifest.webmanifest": "application/manifest+json",
}
#: Files served at the root, not under /static/: the service worker (its scope is the folder it is
#: served from, so the whole page) and the web-app manifest.
ROOT_FILES = ("sw.js", "manifest.webmanifest")

#: Headers on every answer: no framing, no sniffing, only this server's own scripts and styles.
SECURITY_HEADERS = [
    (b"x-content-type-options", b"nosniff"),
    (b"referrer-policy", b"no-referrer"),
    (b"x-frame-options", b"DENY"),
    (b"content-security-policy",
     b"default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self'; connect-src 'self'; "
     b"manifest-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'"),
]


@dataclass(frozen=True)
class Backend:
    """What the server answers with. Each function takes the validated query (name -> text, names
    as the CLI's flags without dashes) and raises a :class:`~physcam.errors.PhysCamError` with a
    one-line message for input it refuses. ``parameters`` names, per endpoint ("report",
    "sensors", "lens", "diagram"), the query names it accepts. ``physcam.cli.serve.cli_backend``
    builds the one physcam uses from the CLI's own functions."""

    report: Callable[[Mapping[str, str]], dict]
    dof_svg: Callable[[Mapping[str, str]], bytes]
    sensors: Callable[[Mapping[str, str]], list]
    lenses: Callable[[], list]
    lens: Callable[[str, Mapping[str, str]], dict]
    diagram_svg: Callable[[str, Mapping[str, str]], bytes]
    parameters: Mapping[str, frozenset[str]]
    #: the unit system a page starts in when its address does not say: "m", or "ft" (the user config's
    #: ``units``): a bare focus, near or far is then feet on the page as on the command line
    units: str = "m"


@dataclass(frozen=True)
class Limits:
    """The server's bounds (docs/serve.md, "What it refuses"). Per client address: ``rate``
    requests per second (a token bucket of ``burst``), ``client_queue`` slow requests (lenses,
    charts) pending for the worker, ``client_connections`` open connections. In all: ``queue`` slow
    requests (an address's first is taken beyond it: worker.py), ``connections`` connections (and
    addresses with slow work pending). Per request: a head (request line and headers) of at
    most ``head_bytes``, complete within ``head_timeout`` seconds of the connection opening or of
    the previous answer; a connection idle ``keep_alive`` seconds between requests is closed."""

    rate: float = 60.0
    burst: int = 120
    max_url: int = 2048
    max_params: int = 32
    max_value: int = 64
    max_marks: int = 16
    queue: int = 32
    cache_bytes: int = 32 * 1024 * 1024
    clients: int = 4096
    client_queue: int = 8  # the fields from here on were added later: keyword use, old positions kept
    connections: int = 256
    client_connections: int = 32
    head_bytes: int = 16 * 1024
    head_timeout: float = 5.0
    keep_alive: float = 5.0

    def __post_init__(self):
        import math

        for name in ("rate", "burst", "max_url", "max_params", "max_value", "max_marks", "queue", "client_queue",
                     "cache_bytes", "clients", "connections", "client_connections", "head_bytes", "head_timeout",
                     "keep_alive"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
                raise WrongTypeError(f"Limits.{name} must be a positive number, got {v!r}")
        for name in ("queue", "client_queue", "connections", "client_connections", "head_bytes"):
            if not isinstance(getattr(self, name), int):
                raise WrongTypeError(f"Limits.{name} must be a whole number, got {getattr(self, name)!r}")


class Refused(Exception):
    """An answer other than 200, with its status and one line of reason."""

    def __init__(self, status: int, reason: str, headers: list | None = None):
        super().__init__(reason)
        self.status, self.reason, self.headers = status, one_line(reason), headers or []


def one_line(text) -> str:
    """The first line of ``text``, at most 300 characters."""
    lines = str(text).strip().splitlines()
    line = lines[0] if lines else "refused"
    return line if len(line) <= 300 else line[:297] + "..."


def client_address(scope) -> str:
    """The client's IP address (the socket's peer: no proxy headers are trusted), "?" when unknown."""
    client = scope.get("client")
    return client[0] if client else "?"


def _error_body(reason: str) -> bytes:
    return json.dumps({"error": reason}, ensure_ascii=False).encode()


async def _send(send, status: int, body: bytes, media: str, headers=(), head: bool = False):
    hdrs = [(b"content-type", media.encode()), (b"content-length", str(len(body)).encode()),
            (b"cache-control", b"no-store"), *headers]
    await send({"type": "http.response.start", "status": status, "headers": hdrs})
    await send({"type": "http.response.body", "body": b"" if head else body})


class _TokenBuckets:
    """One token bucket per client address, at most ``clients`` of them (the idlest go first)."""

    def __init__(self, rate: float, burst: int, clients: int):
        self.rate, self.burst, self.clients = float(rate), float(burst), int(clients)
        self._b: OrderedDict[str, tuple[float, float]] = OrderedDict()

    def take(self, who: str) -> float:
        """0 when ``who`` may go now, else the seconds until a token is there."""
        now = time.monotonic()
        tokens, last = self._b.pop(who, (self.burst, now))
        tokens = min(self.burst, tokens + (now - last) * self.rate)
        wait = 0.0
        if tokens >= 1.0:
            tokens -= 1.0
        else:
            wait = (1.0 - tokens) / self.rate
        self._b[who] = (tokens, now)
        while len(self._b) > self.clients:
            self._b.popitem(last=False)
        return wait


class _Cache:
    """Answers by (route, arguments), least recently used first out, bounded in bytes."""

    def __init__(self, budget: int):
        self.budget, self.size = int(budget), 0
        self._d: OrderedDict = OrderedDict()

    def get(self, key):
        hit = self._d.get(key)
        if hit is not None:
            self._d.move_to_end(key)
        return hit

    def put(self, key, value):
        n = len(value[1]) + 200
        if n > self.budget // 4:
            return
        old = self._d.pop(key, None)
        if old is not None:
            self.size -= len(old[1]) + 200
        self._d[key] = value
        self.size += n
        while self.size > self.budget:
            _, v = self._d.popitem(last=False)
            self.size -= len(v[1]) + 200


class _Guard:
    """Pure ASGI middleware in front of the routes: method, URL and body limits, the rate limit,
    security headers, and a one-line 500 for anything unexpected (the server keeps serving)."""

    def __init__(self, app, limits: Limits, log):
        self.app, self.limits, self.log = app, limits, log
        self.buckets = _TokenBuckets(limits.rate, limits.burst, limits.clients)

    async def __call__(self, scope, receive, send):
        if scope["type"] == "lifespan":
            return await self.app(scope, receive, send)
        if scope["type"] != "http":
            return  # no websockets: the connection closes
        started = False

        async def guarded_send(message):
            nonlocal started
            if message["type"] == "http.response.start":
                started = True
                message = dict(message)
                message["headers"] = list(message.get("headers", [])) + SECURITY_HEADERS
            await send(message)

        head = scope.get("method") == "HEAD"
        try:
            self._check(scope)
            await self.app(scope, receive, guarded_send)
        except _HungUp:
            pass  # nobody to answer
        except Refused as r:
            if not started:
                await _send(guarded_send, r.status, _error_body(r.reason), "application/json", r.headers, head)
        except Exception as exc:  # noqa: BLE001 - a bug must not take the server down nor show a traceback
            where = f"{scope.get('method')} {scope.get('path')}"
            self.log(f"physcam serve: internal error on {where}: {type(exc).__name__}: {one_line(exc)}")
            if not started:
                await _send(guarded_send, 500, _error_body(f"internal error ({type(exc).__name__}); the server "
                                                           "keeps running"), "application/json", (), head)

    def _check(self, scope):
        lim = self.limits
        if scope.get("method") not in ("GET", "HEAD"):
            raise Refused(405, f"method {scope.get('method')} is not allowed: this server answers GET only",
                          [(b"allow", b"GET, HEAD")])
        if len(scope.get("raw_path") or b"") + len(scope.get("query_string") or b"") > lim.max_url:
            raise Refused(414, f"the URL is longer than {lim.max_url} characters")
        for k, v in scope.get("headers", []):
            if k == b"transfer-encoding" or (k == b"content-length" and v.strip() not in (b"", b"0")):
                raise Refused(413, "this server takes no request body")
        wait = self.buckets.take(client_address(scope))
        if wait > 0:
            raise Refused(429, f"too many requests from this address (limit {lim.rate:g} per second); "
                          f"wait {wait:.2f} s", [(b"retry-after", str(max(1, round(wait + 0.5))).encode())])


class _App:
    """The routes' work: query validation, the cache, fast work inline and slow work on one thread."""

    def __init__(self, backend: Backend, limits: Limits):
        self.backend, self.limits = backend, limits
        self.cache = _Cache(limits.cache_bytes)
        self.running: dict = {}  # cache key -> the _Job of its slow answer being computed
        # One worker thread (numba's tracer and matplotlib are not to be entered from two threads at
        # once), shared between client addresses in turn (worker.py); an address's first slow
        # request is always taken, up to one address per connection the server accepts.
        self.worker = FairWorker(limits.client_queue, limits.queue, addresses=limits.connections)
        self.static = {}
        root = resources.files(__package__) / "static"
        for name, media in STATIC_FILES.items():
            self.static[name] = (media, (root / name).read_bytes())

    # --- the query --------------------------------------------------------------------
    def query(self, scope, endpoint: str, extra: tuple[str, ...] = ()) -> dict[str, str]:
        lim = self.limits
        raw = scope.get("query_string") or b""
        try:
            text = raw.decode("ascii")
            pairs = parse_qsl(text, keep_blank_values=True, strict_parsing=False, encoding="utf-8",
                              errors="strict", max_num_fields=lim.max_params)
        except UnicodeDecodeError:
            raise Refused(422, "the query is not valid UTF-8 text") from None
        except ValueError:
            raise Refused(422, f"more than {lim.max_params} query parameters") from None
        allowed = self.backend.parameters.get(endpoint, frozenset()) | set(extra)
        out: dict[str, str] = {}
        for name, value in pairs:
            if name not in allowed:
                shown = name if len(name) <= 40 and name.isprintable() else name[:40].encode("unicode_escape").decode()
                names = ", ".join(sorted(allowed)) or "none"
                raise Refused(422, f"unknown parameter {shown!r}; this endpoint takes: {names}")
            if name in out:
                raise Refused(422, f"parameter {name!r} is given twice")
            if len(value) > lim.max_value:
                raise Refused(422, f"parameter {name!r} is longer than {lim.max_value} characters")
            if _holds_control(value):
                raise Refused(422, f"parameter {name!r} holds a control character")
            out[name] = value
        return out

    # --- answers ---------------------------------------------------------------------------
    async def answer(self, request, key, fn, *, heavy: bool, media: str):
        """Compute ``fn()`` (inline when light, on the worker in the client's turn when heavy),
        cached by ``key``; a :class:`PhysCamError` becomes 422 with its first line."""
        hit = self.cache.get(key)
        if hit is None and heavy:
            hit = await self._slow(request.scope, request.receive, key, fn, media)
        elif hit is None:
            hit = _computed(fn, media)
            self.cache.put(key, hit)
        status, body = hit
        if status != 200:
            raise Refused(status, body.decode())
        return body

    async def _slow(self, scope, receive, key, fn, media):
        """The worker's answer for ``key``, shared by every request asking it while it is computed
        (issue 47: each connection asking one setup at once queued its own copy and filled its
        address's queue). A request whose client hangs up stops waiting (:class:`_HungUp`); when its
        turn comes, a job nobody waits for any more is dropped (round 13: 80 retrying clients had the
        worker draw charts for requests long gone), while a client that timed out and asks again
        joins it in its place. A request already hung up queues nothing."""
        hang_up = asyncio.ensure_future(_hung_up(receive))
        try:
            await asyncio.sleep(0)  # hang_up reads what is already there: a closed connection ends it now
            while not hang_up.done():
                job = self._join(scope, key, fn, media)
                try:  # (asyncio.wait cancels neither: a waiter that goes away cancels nothing shared)
                    await asyncio.wait((job.future, hang_up), return_when=asyncio.FIRST_COMPLETED)
                finally:
                    job.waiters -= 1
                if job.future.done() and not job.future.cancelled():
                    return job.future.result()
                # else hung up, or the job was dropped as this request joined it: asked again
            raise _HungUp()
        finally:
            hang_up.cancel()

    def _join(self, scope, key, fn, media) -> _Job:
        """The job computing ``key`` (a new one on the worker, in the client's turn, when none is or
        the last was dropped), with this request counted among its waiters."""
        job = self.running.get(key)
        if job is not None and not job.future.cancelled():
            job.waiters += 1
            return job
        job = _Job()  # counted before it is queued: the worker may ask wanted() at once
        try:
            work = self.worker.submit(client_address(scope), lambda: _computed(fn, media),
                                      wanted=lambda: job.waiters > 0)
        except Full as full:
            raise Refused(503 if full.everyone else 429,
                          f"{'the server is busy with' if full.everyone else 'this address has'} "
                          f"{full.limit} slow requests (lenses, charts) waiting; try again",
                          [(b"retry-after", b"1")]) from None
        job.future = asyncio.wrap_future(work)
        self.running[key] = job
        job.future.add_done_callback(lambda f, key=key, job=job: self._done(key, job))
        return job

    def _done(self, key, job) -> None:
        """A slow answer is in: cached, and no longer running."""
        if self.running.get(key) is job:
            del self.running[key]
        if not job.future.cancelled() and job.future.exception() is None:
            self.cache.put(key, job.future.result())


class _HungUp(Exception):
    """The client hung up before its answer was ready: nothing is sent."""


class _Job:
    """A slow answer being computed: its asyncio future and the number of requests waiting for it
    (read by the worker's thread when its turn comes: none, and it is dropped)."""

    __slots__ = ("future", "waiters")

    def __init__(self):
        self.future, self.waiters = None, 1


async def _hung_up(receive) -> None:
    """Returns when the client hangs up (ASGI's ``http.disconnect``: a server answers ``receive()``
    after the request's last part only then); waits for ever where the server cannot tell."""
    while True:
        message = await receive()
        if message["type"] == "http.disconnect":
            return
        if message["type"] == "http.request" and not message.get("more_body", False):
            break
    if (await receive())["type"] == "http.disconnect":
        return
    await asyncio.get_running_loop().create_future()  # not an ASGI server that tells


def settle_heap() -> None:
    """Collect the garbage, then move every object left out of the cycle collector's way (``gc.freeze``).

    A full collection visits every object the collector tracks, and the modules a server imports
    (numpy, matplotlib, the lens library: about 90,000 objects) stay for good: in ``physcam
    serve`` each full collection took 25-105 ms of CPU with the GIL held, a stall every request
    waited out (issue 47, docs/performance.md). Frozen, those objects are never visited again, so
    a full collection costs only what was made since (a chart's 5,560 objects of garbage: 2 ms).
    Called before serving and after an answer whose computation imported code (the first chart,
    the first diagram): a few times in a server's life. What is alive at that moment stays alive
    (a frozen cycle is never freed): the requests in flight then, a bounded few kilobytes.
    """
    gc.collect()
    gc.freeze()


def _computed(fn, media):
    """(200, body bytes) or (422, reason bytes); the heap settled (:func:`settle_heap`) when
    ``fn`` imported code (modules are long-lived)."""
    modules = len(sys.modules)
    try:
        obj = fn()
    except PhysCamError as exc:
        return 422, one_line(exc).encode()
    finally:
        if len(sys.modules) > modules:
            settle_heap()
    if media == "application/json":
        return 200, json.dumps(obj, ensure_ascii=False, allow_nan=False, separators=(",", ":")).encode()
    return 200, obj


def _no_store(body: bytes, media: str):
    """A computed answer: never cached by the browser."""
    from starlette.responses import Response

    return Response(body, media_type=media, headers={"cache-control": "no-store"})


def _static_page(core: _App, name: str):
    """The endpoint serving the bundled page file ``name`` (revalidated by the browser)."""
    from starlette.responses import Response

    media, body = core.static[name]

    async def endpoint(request):
        return Response(body, media_type=media, headers={"cache-control": "no-cache"})

    return endpoint


def _report_endpoints(core: _App, backend: Backend, limits: Limits) -> dict:
    """The on-set report, the table across focus marks and the DOF chart, by route path."""

    def heavy_report(q) -> bool:
        return "lens" in q

    async def report(request):
        q = core.query(request.scope, "report")
        body = await core.answer(request, ("report", tuple(sorted(q.items()))), lambda: backend.report(q),
                                 heavy=heavy_report(q), media="application/json")
        return _no_store(body, "application/json")

    async def focus_table(request):
        q = core.query(request.scope, "report", extra=("marks",))
        marks = [m.strip() for m in q.pop("marks", "").split(",") if m.strip()]
        if not marks:
            raise Refused(422, "give the focus marks, e.g. marks=1m,2m,3m (or 3ft,5ft,10ft)")
        if len(marks) > limits.max_marks:
            raise Refused(422, f"at most {limits.max_marks} focus marks, got {len(marks)}")

        def table():
            rows = []
            for m in marks:
                try:
                    rows.append({"focus": m, "report": backend.report({**q, "focus": m})})
                except PhysCamError as exc:
                    rows.append({"focus": m, "error": one_line(exc)})
            return rows

        key = ("focus-table", tuple(marks), tuple(sorted(q.items())))
        body = await core.answer(request, key, table, heavy=heavy_report(q), media="application/json")
        return _no_store(body, "application/json")

    async def dof_svg(request):
        q = core.query(request.scope, "report")
        body = await core.answer(request, ("dof.svg", tuple(sorted(q.items()))), lambda: backend.dof_svg(q),
                                 heavy=True, media="image/svg+xml")
        return _no_store(body, "image/svg+xml")

    return {"/api/report": report, "/api/focus-table": focus_table, "/api/dof.svg": dof_svg}


def _catalogue_endpoints(core: _App, backend: Backend, limits: Limits) -> dict:
    """The sensor and lens catalogues, one lens's data and its diagram, by route path."""

    async def sensors(request):
        q = core.query(request.scope, "sensors")
        body = await core.answer(request, ("sensors", tuple(sorted(q.items()))), lambda: backend.sensors(q),
                                 heavy=False, media="application/json")
        return _no_store(body, "application/json")

    async def lenses(request):
        core.query(request.scope, "lenses")
        body = await core.answer(request, ("lenses",), backend.lenses, heavy=True, media="application/json")
        return _no_store(body, "application/json")

    def _name(request) -> str:
        name = request.path_params["name"]
        if len(name) > limits.max_value or not name.isprintable():
            raise Refused(422, "a lens name is at most 64 printable characters (see /api/lenses)")
        return name

    async def lens(request):
        name = _name(request)
        q = core.query(request.scope, "lens")
        body = await core.answer(request, ("lens", name, tuple(sorted(q.items()))), lambda: backend.lens(name, q),
                                 heavy=True, media="application/json")
        return _no_store(body, "application/json")

    async def diagram(request):
        name = _name(request)
        q = core.query(request.scope, "diagram")
        body = await core.answer(request, ("diagram", name, tuple(sorted(q.items()))),
                                 lambda: backend.diagram_svg(name, q), heavy=True, media="image/svg+xml")
        return _no_store(body, "image/svg+xml")

    return {"/api/sensors": sensors, "/api/lenses": lenses, "/api/lens/{name}": lens,
            "/api/lens/{name}/diagram.svg": diagram}


async def _http_error(request, exc):
    """Starlette's own 404 and 405 as the API's one-line JSON refusals."""
    reason = {404: f"no such page: {request.url.path[:80]} (the API is under /api/, see docs/serve.md)",
              405: "method not allowed: this server answers GET only"}.get(exc.status_code, str(exc.detail))
    raise Refused(exc.status_code, reason)


def create_app(backend: Backend, limits: Limits | None = None, *, log=None):
    """The ASGI application serving ``backend`` within ``limits`` (default :class:`Limits`).

    ``log`` takes one line per unexpected error (default: standard error).
    """
    from starlette.applications import Starlette
    from starlette.exceptions import HTTPException
    from starlette.middleware import Middleware
    from starlette.responses import Response
    from starlette.routing import Route

    if not isinstance(backend, Backend):
        raise WrongTypeError(f"backend must be a physcam.serve.Backend, got {type(backend).__name__}")
    # numpy now, on this one thread: the report path no longer imports it (issue 43), and requests run
    # on several threads; two of them importing it first at once can see it half initialised (Python
    # 3.11's import-deadlock avoidance: "partially initialized module 'numpy' has no attribute 'errstate'")
    import numpy  # noqa: F401
    limits = Limits() if limits is None else limits
    if not isinstance(limits, Limits):
        raise WrongTypeError(f"limits must be a physcam.serve.Limits, got {type(limits).__name__}")
    log = log or (lambda line: print(line, file=sys.stderr, flush=True))
    core = _App(backend, limits)

    async def health(request):
        core.query(request.scope, "health")
        return _no_store(json.dumps({"ok": True, "version": __version__, "units": backend.units,
                                     "slow": core.worker.stats()}).encode(), "application/json")

    async def favicon(request):
        return Response(status_code=204)

    api = {**_report_endpoints(core, backend, limits), **_catalogue_endpoints(core, backend, limits)}
    routes = [  # (no two paths overlap: the order is the router's trials, the report first, issue 47)
        *(Route(path, api[path]) for path in ("/api/report", "/api/focus-table", "/api/dof.svg", "/api/sensors",
                                              "/api/lenses", "/api/lens/{name}", "/api/lens/{name}/diagram.svg")),
        Route("/api/health", health),
        Route("/", _static_page(core, "index.html")),
        *(Route(f"/{name}" if name in ROOT_FILES else f"/static/{name}", _static_page(core, name))
          for name in STATIC_FILES if name != "index.html"),
        Route("/favicon.ico", favicon),
    ]
    app = Starlette(routes=routes, exception_handlers={HTTPException: _http_error},
                    middleware=[Middleware(_Guard, limits=limits, log=log)])
    app.state.core = core
    return app
