"""The HTTP/1.1 connection of ``physcam serve``: uvicorn's h11 protocol with bounds per connection.

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

This relies on uvicorn internals (``uvicorn>=0.29``, checked against 0.54): the
``H11Protocol`` attributes ``conn`` (the ``h11.Connection``, replaced here), ``transport``,
``client``, ``loop`` and ``flow``; its methods ``connection_made``, ``connection_lost``,
``data_received``, ``on_response_complete``, ``shutdown`` and ``_unset_keepalive_if_required``;
and that ``handle_events`` answers an ``h11.RemoteProtocolError`` by calling
``send_400_response``. h11 is used through its public API (``trailing_data``, states,
``RemoteProtocolError.error_status_hint``).
"""

from __future__ import annotations

import json
import re
from http import HTTPStatus

import h11
from uvicorn.protocols.http.h11_impl import H11Protocol

from .app import SECURITY_HEADERS, Limits, one_line

__all__ = ["LINGER_S", "protocol_class"]

#: Seconds a refused connection that has sent something is read (and its input discarded) before it closes.
LINGER_S = 2.0

#: Where h11 ends a head: the first empty line (h11._receivebuffer's blank_line_regex).
_BLANK_LINE = re.compile(b"\n\r?\n")


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
        return f"the request line and headers are over {self.head_bytes} bytes ({self.head_bytes // 1024} KiB)"


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


class LimitedH11Protocol(H11Protocol):
    """uvicorn's h11 protocol with the head cap, the header timeout and the connection caps."""

    limits: Limits = Limits()
    tally: _Tally = _Tally()

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.conn = _HeadCappedConnection(self.limits.head_bytes)
        self._who: str | None = None  # the address this connection is counted under
        self._refused = False
        self._phase_start = 0.0
        self._timer = None

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
        conn, lim = self.conn, self.limits
        if conn.their_state not in (h11.IDLE, h11.SEND_BODY):
            return  # the request is in (DONE, or MUST_CLOSE after "Connection: close"): the server is
            # answering, and its answer starts the next phase
        elapsed = self.loop.time() - self._phase_start
        idle = conn.their_state is h11.IDLE and not conn.trailing_data[0]
        if idle and elapsed >= lim.keep_alive:
            self._close_quietly()
        elif elapsed >= lim.head_timeout:
            if conn.their_state is h11.IDLE:
                self._refuse(408, f"the request line and headers did not arrive within {lim.head_timeout:g} s",
                             linger=True)
            else:
                self._close_quietly()  # a request body trickling in (this server takes none)
        else:
            deadlines = [lim.head_timeout] + ([lim.keep_alive] if idle else [])
            self._arm(min(d for d in deadlines if d > elapsed) - elapsed)

    def _close_quietly(self) -> None:
        self._refused = True
        self.transport.close()  # uvicorn's connection_lost tells h11

    # --- uvicorn's hooks --------------------------------------------------------------------
    def data_received(self, data: bytes) -> None:
        if self._refused:
            return  # discarded, so that closing sends no reset before the client has read its answer
        super().data_received(data)

    def on_response_complete(self) -> None:
        if not self.transport.is_closing():
            self._start_phase()
        super().on_response_complete()

    def send_400_response(self, msg: str) -> None:
        status, reason = self.conn.refusal or (400, "malformed HTTP request")
        self._refuse(status, reason, linger=True)

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


def protocol_class(limits: Limits) -> type[LimitedH11Protocol]:
    """A protocol class for ``uvicorn.Config(http=...)`` bounded by ``limits``, with its own
    count of open connections (one class per server)."""
    if not isinstance(limits, Limits):
        from ..errors import WrongTypeError

        raise WrongTypeError(f"limits must be a physcam.serve.Limits, got {type(limits).__name__}")
    return type("PhysCamH11Protocol", (LimitedH11Protocol,), {"limits": limits, "tally": _Tally()})
