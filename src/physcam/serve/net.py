"""Sockets, addresses and the terminal QR code of ``physcam serve``; uvicorn runs the app.

The command binds its socket itself (:func:`bind_socket`) before uvicorn starts, so a port in use
or an address that is not this machine's is one line of error, and ``--port 0`` gives a free
port whose number is printed. With a wildcard host (``0.0.0.0`` or ``::``) the addresses of this
machine's network interfaces (:func:`lan_addresses`) are printed with a QR code
(:func:`qr_text`, drawn by ``segno``) that a phone's camera opens.
"""

from __future__ import annotations

import ipaddress
import socket
from typing import TYPE_CHECKING

from ..errors import InputError, WrongTypeError

if TYPE_CHECKING:
    from .app import Limits

__all__ = ["bind_socket", "lan_addresses", "qr_text", "run_server", "asgi_get", "url_for"]


def bind_socket(host: str, port: int) -> socket.socket:
    """A listening TCP socket on ``host``:``port`` (0 = any free port); :class:`InputError` with one
    line when the address cannot be used."""
    if not isinstance(host, str):
        raise WrongTypeError(f"host must be text such as '127.0.0.1' or '0.0.0.0', got {type(host).__name__}")
    if isinstance(port, bool) or not isinstance(port, int):
        raise WrongTypeError(f"port must be an integer, got {type(port).__name__}")
    if not 0 <= port <= 65535:
        raise InputError(f"port must lie between 0 and 65535, got {port}")
    name = "127.0.0.1" if host.strip().lower() == "localhost" else host.strip()
    try:
        ipaddress.ip_address(name)  # an address, never a name to look up (no DNS on a set's network)
        infos = socket.getaddrinfo(name, port, type=socket.SOCK_STREAM,
                                   flags=socket.AI_PASSIVE | socket.AI_NUMERICHOST)
    except (ValueError, socket.gaierror, UnicodeError):
        raise InputError(f"host must be an IP address such as 127.0.0.1 (this machine only) or 0.0.0.0 "
                         f"(every network interface), got {host!r}") from None
    family, kind, proto, _, addr = infos[0]
    sock = socket.socket(family, kind, proto)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if family == socket.AF_INET6:
            sock.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 0)
        sock.bind(addr)
        sock.listen(128)
    except OSError as exc:
        sock.close()
        import errno

        why = {errno.EADDRINUSE: "the port is in use (another server?); give another with --port, or --port 0",
               errno.EACCES: "permission denied (ports below 1024 need root); use e.g. --port 8765",
               errno.EADDRNOTAVAIL: "that address is not one of this machine's"}.get(exc.errno, exc.strerror)
        raise InputError(f"cannot listen on {host}:{port}: {why}") from None
    sock.set_inheritable(True)
    return sock


def _is_wildcard(host: str) -> bool:
    try:
        return ipaddress.ip_address(host).is_unspecified
    except ValueError:
        return False


def url_for(sock: socket.socket, scheme: str = "http") -> list[str]:
    """The URLs a browser opens for the server on ``sock``: the bound address, or for a wildcard
    address every interface address (LAN first, loopback last); ``scheme`` "https" with a certificate."""
    if not isinstance(sock, socket.socket):
        raise WrongTypeError(f"sock must be a socket, got {type(sock).__name__}")
    if scheme not in ("http", "https"):
        raise WrongTypeError(f"scheme must be 'http' or 'https', got {scheme!r}")
    host, port = sock.getsockname()[:2]
    hosts = lan_addresses() + ["127.0.0.1"] if _is_wildcard(host) else [host]
    return [f"{scheme}://[{h}]:{port}/" if ":" in h else f"{scheme}://{h}:{port}/" for h in hosts]


def lan_addresses() -> list[str]:
    """This machine's IPv4 addresses other than loopback, read from its interfaces (Linux ioctl
    SIOCGIFADDR; elsewhere the addresses the host name resolves to). Sends nothing on the network."""
    found: list[str] = []
    try:
        import fcntl
        import struct

        for _, name in socket.if_nameindex():
            s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            try:
                raw = fcntl.ioctl(s.fileno(), 0x8915, struct.pack("256s", name.encode()[:15]))  # SIOCGIFADDR
                found.append(socket.inet_ntoa(raw[20:24]))
            except OSError:
                pass
            finally:
                s.close()
    except (ImportError, OSError, AttributeError):
        try:
            found = [i[4][0] for i in socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET)]
        except OSError:
            found = []
    out = []
    for a in found:
        if not ipaddress.ip_address(a).is_loopback and a not in out:
            out.append(a)
    return out


def qr_text(url: str) -> str:
    """``url`` as a QR code in Unicode half blocks for a terminal (dark text on light, quiet zone
    included), drawn by segno."""
    if not isinstance(url, str):
        raise WrongTypeError(f"url must be text, got {type(url).__name__}")
    if not url or len(url) > 200:
        raise InputError("a QR code here holds a URL of 1 to 200 characters")
    import io

    import segno

    buf = io.StringIO()
    segno.make(url, error="m", micro=False).terminal(out=buf, compact=True)
    return buf.getvalue()


def run_server(app, sock: socket.socket, *, log_requests: bool = False, limits: Limits | None = None,
               certfile=None, keyfile=None) -> None:
    """Serve ``app`` on the listening ``sock`` with uvicorn until interrupted (Ctrl-C, SIGTERM),
    each connection bounded by ``limits`` (default :class:`~physcam.serve.app.Limits`): the head
    cap, the header timeout and the connection caps of :mod:`physcam.serve.protocol`. With
    ``certfile`` and ``keyfile`` (PEM) it speaks HTTPS: a secure context, so phones on the network can
    install the page's offline copy (docs/serve.md)."""
    from .app import Limits, settle_heap

    if not callable(app):
        raise WrongTypeError(f"app must be an ASGI application, got {type(app).__name__}")
    if not isinstance(sock, socket.socket):
        raise WrongTypeError(f"sock must be a listening socket, got {type(sock).__name__}")
    limits = Limits() if limits is None else limits
    if not isinstance(limits, Limits):
        raise WrongTypeError(f"limits must be a physcam.serve.Limits, got {type(limits).__name__}")
    import os

    import uvicorn

    from .protocol import protocol_class

    # the HTTP parser: httptools when installed, else h11; PHYSCAM_HTTP_PARSER=h11 chooses h11 (tests run both)
    http = protocol_class(limits, os.environ.get("PHYSCAM_HTTP_PARSER") or None)
    config = uvicorn.Config(
        app, http=http, loop="asyncio", lifespan="off", ws="none", interface="asgi3",
        log_level="warning", access_log=bool(log_requests), server_header=False, proxy_headers=False,
        timeout_keep_alive=limits.keep_alive, limit_concurrency=None, backlog=128,
        h11_max_incomplete_event_size=limits.head_bytes,
        ssl_certfile=None if certfile is None else str(certfile), ssl_keyfile=None if keyfile is None else str(keyfile),
    )
    settle_heap()  # what start-up made (modules, the app, the lens library) is never collected again
    uvicorn.Server(config).run(sockets=[sock])


def asgi_get(app, path: str) -> tuple[int, dict, bytes]:
    """GET ``path`` (with its query) from the ASGI ``app`` in this process, without a socket:
    (status, headers, body). ``physcam serve --check`` uses it."""
    if not callable(app):
        raise WrongTypeError(f"app must be an ASGI application, got {type(app).__name__}")
    if not isinstance(path, str) or not path.startswith("/"):
        raise WrongTypeError(f"path must be text starting with '/', got {path!r}")
    import asyncio

    p, _, q = path.partition("?")
    scope = {"type": "http", "asgi": {"version": "3.0"}, "http_version": "1.1", "method": "GET", "scheme": "http",
             "path": p, "raw_path": p.encode(), "query_string": q.encode(), "root_path": "",
             "headers": [(b"host", b"localhost")], "client": ("127.0.0.1", 0), "server": ("127.0.0.1", 0)}
    out = {"status": 0, "headers": {}, "body": b""}
    asked, answered = [], []  # (the events are made inside asyncio.run's loop)

    async def receive():  # the request, then (as an ASGI server does) nothing until the client hangs up
        if not asked:
            asked.append(True)
            return {"type": "http.request", "body": b"", "more_body": False}
        await answered[0].wait()
        return {"type": "http.disconnect"}

    async def send(message):
        if message["type"] == "http.response.start":
            out["status"] = message["status"]
            out["headers"] = {k.decode(): v.decode() for k, v in message.get("headers", [])}
        elif message["type"] == "http.response.body":
            out["body"] += message.get("body", b"")
            if not message.get("more_body", False):
                answered[0].set()

    async def run():
        answered.append(asyncio.Event())
        await app(scope, receive, send)

    asyncio.run(run())
    return out["status"], out["headers"], out["body"]

