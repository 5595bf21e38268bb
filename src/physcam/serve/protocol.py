"""The HTTP/1.1 connection of ``physcam serve``: uvicorn's protocol with bounds per connection.

uvicorn alone let one client lock everyone out (issue 24 item 11): a connection that never
finishes its request head was held for ever, so 256 half-sent requests filled uvicorn's
``limit_concurrency``; and h11 bounds only a head still *incomplete*, so a 20 KB head arriving in
one piece passed the 16 KiB cap. :func:`protocol_class` gives uvicorn a protocol that adds, with
the numbers of :class:`~physcam.serve.app.Limits`:

- the head cap: a request line and headers over ``head_bytes`` are answered 431, whole or in pieces;
- the header timeout: a head not complete ``head_timeout`` seconds after the connection opened or
  after the previous answer is answered 408 (more bytes trickling in do not restart the clock);
  a connection that sends nothing for ``keep_alive`` seconds is closed without an answer;
- connection caps: ``client_connections`` open connections per client address (the next is
  answered 429 and closed at once) and ``connections`` in all (503), in place of uvicorn's
  ``limit_concurrency``, so one address cannot take every connection.

Every refusal here is one JSON line ``{"error": "..."}`` with ``connection: close`` (400 for
malformed HTTP too). After refusing a client that has sent something, the server stops writing
and reads and discards its input for up to :data:`LINGER_S` seconds before closing: closing a
socket with unread input sends a reset, which can make the client lose the answer.

Two parsers, the same bounds (:class:`_Bounded`): httptools (llhttp, in C; the serve extra installs
it: h11 in Python cost a third of a cached answer's CPU, issue 47), or h11 when httptools is not
installed or ``PHYSCAM_HTTP_PARSER=h11`` asks for it. The head cap counts the bytes up to the head's first empty line itself for both, before
the parser sees them. One difference is h11's: an HTTP/1.1 request without a Host header is
malformed there (400), llhttp takes it.

This relies on uvicorn internals (``uvicorn>=0.29``, checked against 0.54): the protocols'
attributes ``transport``, ``client``, ``loop`` and ``flow``, the methods ``connection_made``,
``connection_lost``, ``data_received``, ``on_response_complete``, ``shutdown`` and
``_unset_keepalive_if_required``; for h11, ``conn`` (the ``h11.Connection``, replaced here) and
that ``handle_events`` answers an ``h11.RemoteProtocolError`` by calling ``send_400_response``;
for httptools, ``parser`` and its callbacks ``on_headers_complete`` and ``on_message_complete``.
h11 is used through its public API (``trailing_data``, states,
``RemoteProtocolError.error_status_hint``), httptools through ``feed_data`` and its errors.
"""

from __future__ import annotations

import json
import re
from http import HTTPStatus

import h11
from uvicorn.protocols.http.h11_impl import H11Protocol

try:
    import httptools
    from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol
except ImportError:  # the serve extra installs it; h11 serves alone without it
    httptools = HttpToolsProtocol = None

from .app import SECURITY_HEADERS, Limits, one_line

__all__ = ["LINGER_S", "protocol_class"]

#: Seconds a refused connection that has sent something is read (and its input discarded) before it closes.
LINGER_S = 2.0

#: Where h11 ends a head: the first empty line (h11._receivebuffer's blank_line_regex).
_BLANK_LINE = re.compile(b"\n\r?\n")


def _head_too_long(head_bytes: int) -> str:
    return f"the request line and headers are over {head_bytes} bytes ({head_bytes // 1024} KiB)"


class _HeadCappedConnection(h11.Connection):
    """h11's server connection with the whole head bounded (h11 bounds only an incomplete one), and
    the status and reason of the last protocol error kept for the answer."""

    def __init__(self, head_bytes: int):
        super().__init__(h11.SERVER, max_incomplete_event_size=head_bytes)
        self.head_bytes = head_bytes
        self.refusal: tuple[int, str] | None = None

    def next_event(self):
        if self.their_state is h11.IDLE:
            buf = self.trailing_data[0]
            end = _BLANK_LINE.search(buf)
            if (end.end() if end else len(buf)) > self.head_bytes:
                self.refusal = (431, self._too_long())
                raise h11.RemoteProtocolError(self.refusal[1], error_status_hint=431)
        try:
            return super().next_event()
        except h11.RemoteProtocolError as exc:
            if self.refusal is None:
                status = exc.error_status_hint
                self.refusal = (431, self._too_long()) if status == 431 else (
                    status, one_line(f"malformed HTTP request ({str(exc)[:120]})"))
            raise

    def _too_long(self) -> str:
        return _head_too_long(self.head_bytes)


class _Tally:
    """Open connections admitted, per client address and in all (one per server)."""

    def __init__(self):
        self.per: dict[str, int] = {}
        self.total = 0

    def add(self, who: str) -> None:
        self.per[who] = self.per.get(who, 0) + 1
        self.total += 1

    def remove(self, who: str) -> None:
        left = self.per.pop(who) - 1
        if left:
            self.per[who] = left
        self.total -= 1


class _Bounded:
    """The bounds of a connection, over uvicorn's protocol (h11's or httptools'): the connection caps,
    the header timeout and the refusals. A subclass says where the request stands (:meth:`_stage`)."""

    limits: Limits = Limits()
    tally: _Tally = _Tally()

    def _bounds_init(self) -> None:
        self._who: str | None = None  # the address this connection is counted under
        self._refused = False
        self._phase_start = 0.0
        self._timer = None

    def _stage(self) -> str:
        """"idle" (no byte of the next head yet), "head" (part of it), "body" (its body coming) or
        "answering" (the request is in: the server's answer starts the next phase)."""
        raise NotImplementedError

    # --- the connection caps ----------------------------------------------------------------
    def connection_made(self, transport) -> None:
        super().connection_made(transport)
        lim, who = self.limits, (self.client[0] if self.client else "?")
        if self.tally.total >= lim.connections:
            self._refuse(503, f"the server has {lim.connections} connections open; try again shortly", linger=False)
        elif self.tally.per.get(who, 0) >= lim.client_connections:
            self._refuse(429, f"this address has {lim.client_connections} connections open; close some and try "
                              "again", linger=False)
        else:
            self._who = who
            self.tally.add(who)
            self._start_phase()

    def connection_lost(self, exc) -> None:
        self._cancel_timer()
        if self._who is not None:
            self.tally.remove(self._who)
            self._who = None
        super().connection_lost(exc)

    # --- the header timeout -----------------------------------------------------------------
    def _start_phase(self) -> None:
        """A new request head is awaited from now (connection opened, or previous answer sent)."""
        self._phase_start = self.loop.time()
        self._arm(min(self.limits.keep_alive, self.limits.head_timeout))

    def _arm(self, delay: float) -> None:
        self._cancel_timer()
        self._timer = self.loop.call_later(delay, self._on_timer)

    def _cancel_timer(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _on_timer(self) -> None:
        self._timer = None
        if self._refused or self.transport.is_closing():
            return
        lim, stage = self.limits, self._stage()
        if stage == "answering":
            return  # the request is in: the server is answering, and its answer starts the next phase
        elapsed = self.loop.time() - self._phase_start
        idle = stage == "idle"
        if idle and elapsed >= lim.keep_alive:
            self._close_quietly()
        elif elapsed >= lim.head_timeout:
            if stage != "body":
                self._refuse(408, f"the request line and headers did not arrive within {lim.head_timeout:g} s",
                             linger=True)
            else:
                self._close_quietly()  # a request body trickling in (this server takes none)
        else:
            deadlines = [lim.head_timeout] + ([lim.keep_alive] if idle else [])
            self._arm(min(d for d in deadlines if d > elapsed) - elapsed)

    def _close_quietly(self) -> None:
        self._refused = True
        self.transport.close()  # uvicorn's connection_lost tells the parser

    # --- uvicorn's hooks --------------------------------------------------------------------
    def on_response_complete(self) -> None:
        if not self.transport.is_closing():
            self._start_phase()
        super().on_response_complete()

    def shutdown(self) -> None:
        if self._refused:
            self.transport.close()
        else:
            super().shutdown()

    # --- refusals ---------------------------------------------------------------------------
    def _refuse(self, status: int, reason: str, *, linger: bool) -> None:
        """Answer ``status`` with one JSON line and close: at once, or after reading (and
        discarding) the client's input for up to LINGER_S seconds."""
        self._refused = True
        self._cancel_timer()
        self._unset_keepalive_if_required()
        body = json.dumps({"error": one_line(reason)}, ensure_ascii=False).encode()
        head = [f"HTTP/1.1 {status} {HTTPStatus(status).phrase}".encode(),
                b"content-type: application/json", b"content-length: " + str(len(body)).encode(),
                b"connection: close", b"cache-control: no-store",
                *(k + b": " + v for k, v in SECURITY_HEADERS)]
        self.transport.write(b"\r\n".join(head) + b"\r\n\r\n" + body)
        if not linger:
            self.transport.close()
            return
        self.flow.resume_reading()
        if self.transport.can_write_eof():
            self.transport.write_eof()  # the answer, then end of stream: the client reads it and closes
        self._timer = self.loop.call_later(LINGER_S, self.transport.close)


class LimitedH11Protocol(_Bounded, H11Protocol):
    """uvicorn's h11 protocol with the head cap, the header timeout and the connection caps."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.conn = _HeadCappedConnection(self.limits.head_bytes)
        self._bounds_init()

    def _stage(self) -> str:
        state = self.conn.their_state
        if state is h11.IDLE:
            return "head" if self.conn.trailing_data[0] else "idle"
        return "body" if state is h11.SEND_BODY else "answering"

    def data_received(self, data: bytes) -> None:
        if self._refused:
            return  # discarded, so that closing sends no reset before the client has read its answer
        super().data_received(data)

    def send_400_response(self, msg: str) -> None:
        status, reason = self.conn.refusal or (400, "malformed HTTP request")
        self._refuse(status, reason, linger=True)


class LimitedHttpToolsProtocol(_Bounded, HttpToolsProtocol or object):
    """uvicorn's httptools protocol with the head cap, the header timeout and the connection caps.
    The head's bytes are counted here up to its first empty line before llhttp parses them (llhttp
    sets no bound: httptools gathers a header's value however long it grows)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._bounds_init()
        self._in_head = True  # the bytes coming are a request head's
        self._head_len = 0  # bytes of it so far
        self._tail = b""  # its last two bytes, for an empty line split between two reads
        self._pending = 0  # requests in and not yet answered
        self._deferred: tuple[int, str] | None = None  # a refusal waiting for those answers

    def _stage(self) -> str:
        if self._pending:
            return "answering"
        if self._in_head:
            return "head" if self._head_len else "idle"
        return "body"

    def data_received(self, data: bytes) -> None:
        if self._refused or self._deferred:
            return  # discarded, so that closing sends no reset before the client has read its answer
        while data:
            if not self._in_head:  # a body (this server answers one with 413)
                self._feed(data)
                return
            found = _BLANK_LINE.search(self._tail + data)
            end = len(data) if found is None else found.end() - len(self._tail)
            if self._head_len + end > self.limits.head_bytes:
                self._refuse_in_turn(431, _head_too_long(self.limits.head_bytes))
                return
            self._head_len += end
            self._tail = b"" if found is not None else (self._tail + data)[-2:]
            piece, data = data[:end], data[end:]
            if not self._feed(piece):
                return

    def _feed(self, data: bytes) -> bool:
        """``data`` to the parser (uvicorn's ``data_received``, a malformed request refused here); whether
        the connection goes on."""
        self._unset_keepalive_if_required()
        try:
            self.parser.feed_data(data)
        except httptools.HttpParserUpgrade:
            self._unsupported_upgrade_warning()  # (no websockets here)
        except httptools.HttpParserError as exc:
            self._refuse_in_turn(400, f"malformed HTTP request ({str(exc)[:120]})")
        return not (self._refused or self._deferred or self.transport.is_closing())

    def _refuse_in_turn(self, status: int, reason: str) -> None:
        """Refuse the request being read, after the answers of those before it (pipelined in the
        same connection: h11 reads a request only once the one before is answered)."""
        if self._pending:
            self._deferred = (status, reason)
        else:
            self._refuse(status, reason, linger=True)

    def on_headers_complete(self) -> None:
        self._in_head = False
        super().on_headers_complete()

    def on_message_complete(self) -> None:
        if not self.cycle.response_complete:
            self._pending += 1
        self._in_head, self._head_len, self._tail = True, 0, b""
        super().on_message_complete()

    def on_response_complete(self) -> None:
        self._pending = max(0, self._pending - 1)
        super().on_response_complete()
        if self._deferred and not self._pending and not self.transport.is_closing():
            self._refuse(*self._deferred, linger=True)

    def send_400_response(self, msg: str) -> None:
        self._refuse(400, "malformed HTTP request", linger=True)


def protocol_class(limits: Limits, parser: str | None = None) -> type[_Bounded]:
    """A protocol class for ``uvicorn.Config(http=...)`` bounded by ``limits``, with its own
    count of open connections (one class per server). ``parser``: "httptools" or "h11"; None
    (default) httptools when it is installed, else h11."""
    if not isinstance(limits, Limits):
        from ..errors import WrongTypeError

        raise WrongTypeError(f"limits must be a physcam.serve.Limits, got {type(limits).__name__}")
    if parser is None:
        parser = "h11" if httptools is None else "httptools"
    if parser not in ("httptools", "h11"):
        from ..errors import InputError

        raise InputError(f"the HTTP parser is 'httptools' or 'h11', got {parser!r}")
    if parser == "httptools" and httptools is None:
        from ..errors import InputError

        raise InputError("the httptools parser is not installed: pip install 'physcam[serve]'")
    base, name = (LimitedHttpToolsProtocol, "PhysCamHttpToolsProtocol") if parser == "httptools" else (
        LimitedH11Protocol, "PhysCamH11Protocol")
    return type(name, (base,), {"limits": limits, "tally": _Tally()})
