"""The one thread that does ``physcam serve``'s slow work, shared fairly between client addresses.

The lens tracer (numba) and matplotlib are not to be entered from two threads at once, and the
GIL would serialise them anyway, so one thread draws every chart and traces every lens. A
single first-in first-out queue let one address that asks faster than the thread draws fill the
queue and starve everyone else (issue 24 item 11). Here each address has its own queue and the
thread takes one job from each address in turn (round robin, addresses in order of arrival), so
a chart asked by a second address waits for at most the job being done and one job of each other
address with work waiting.

Admission (issue 40 item 14): an address's **first** pending job is always taken, so many
addresses together cannot fill the queue against one more (40 addresses each under its own rate
limit answered a 41st with 503 when every job counted against one total). The bounds are on the
rest: each address may have ``per_client`` jobs pending (waiting or running), a further job is
taken only while all addresses together have fewer than ``total`` pending, and at most
``addresses`` addresses have work pending at once. Beyond any of them :meth:`FairWorker.submit`
raises :class:`Full` and the server answers 429 (this address) or 503 (everyone; docs/serve.md).
A newly arrived address therefore waits for at most one job of each of the other addresses with
work pending (fewer than ``addresses``) and the job being done.

Dropping (round 13): a job submitted with ``wanted`` is asked, when its turn comes, whether
anyone still wants it; if not it is dropped (never run) and the thread goes on to the next. It keeps
its place until then, so a client that timed out and asks again joins the job where it stands
(the server: ``wanted`` is "a request still waits for it"). A flood of clients that give up costs
only the work someone still waits for. A job whose future is cancelled while it waits leaves its
queue at once and frees its place (``Future.cancel`` fails once it runs). :meth:`FairWorker.stats`
counts the jobs done and dropped.
"""

from __future__ import annotations

import threading
from collections import OrderedDict, deque
from concurrent.futures import Future

from ..errors import WrongTypeError

__all__ = ["FairWorker", "Full"]


class Full(Exception):
    """No room for another job: ``everyone`` is True when all addresses together have ``total``
    pending (or ``addresses`` addresses have work: 503), False when this address has its
    ``per_client`` (429)."""

    def __init__(self, everyone: bool, limit: int):
        super().__init__(f"{limit} slow requests are pending" + (" in all" if everyone else " from this address"))
        self.everyone, self.limit = everyone, limit


class FairWorker:
    """One daemon thread running submitted functions, one per client address in turn."""

    def __init__(self, per_client: int, total: int, name: str = "physcam-serve", addresses: int = 256):
        for label, v in (("per_client", per_client), ("total", total), ("addresses", addresses)):
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise WrongTypeError(f"FairWorker {label} must be a positive integer, got {v!r}")
        self.per_client, self.total, self.name, self.addresses = per_client, total, name, addresses
        self._cv = threading.Condition()
        self._queues: OrderedDict[str, deque] = OrderedDict()  # the turn order: first key goes next
        self._pending: dict[str, int] = {}  # waiting + running, per address
        self._closed = False
        self._thread: threading.Thread | None = None
        self._done = self._dropped = 0

    def stats(self) -> dict[str, int]:
        """Jobs ``done`` (run, whatever their outcome), ``dropped`` (cancelled before they started)
        and ``pending`` (waiting or running) since the worker was made."""
        with self._cv:
            return {"done": self._done, "dropped": self._dropped, "pending": sum(self._pending.values())}

    def pending(self, client: str | None = None) -> int:
        """Jobs waiting or running: of ``client``, or of everyone."""
        with self._cv:
            return sum(self._pending.values()) if client is None else self._pending.get(client, 0)

    def submit(self, client: str, fn, wanted=None) -> Future:
        """Queue ``fn()`` for ``client`` (module notes: its first job always, further ones within
        ``per_client`` and ``total``); its future holds the result (or the exception). ``wanted()``,
        called on the worker's thread when the job's turn comes, False drops it (module notes)."""
        with self._cv:
            if self._closed:
                raise RuntimeError("the worker is closed")
            own = self._pending.get(client, 0)
            if own == 0:
                if len(self._pending) >= self.addresses:
                    raise Full(True, self.addresses)
            elif own >= self.per_client:
                raise Full(False, self.per_client)
            elif sum(self._pending.values()) >= self.total:
                raise Full(True, self.total)
            future: Future = Future()
            self._queues.setdefault(client, deque()).append((future, fn, wanted))
            future.add_done_callback(lambda f, client=client: self._drop(client, f))
            self._pending[client] = self._pending.get(client, 0) + 1
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name=self.name, daemon=True)
                self._thread.start()
            self._cv.notify()
        return future

    def _drop(self, client: str, future: Future) -> None:
        """A cancelled job still queued leaves its queue and frees its place (module notes); one the
        thread has already taken is left to it (``set_running_or_notify_cancel`` skips it)."""
        if not future.cancelled():
            return
        with self._cv:
            queue = self._queues.get(client)
            at = next((i for i, job in enumerate(queue or ()) if job[0] is future), None)
            if at is None:
                return
            del queue[at]
            if not queue:
                del self._queues[client]
            self._dropped += 1
            self._release(client)

    def _release(self, client: str) -> None:
        """One job of ``client`` is no longer pending. Holds the lock."""
        left = self._pending[client] - 1
        if left:
            self._pending[client] = left
        else:
            del self._pending[client]

    def close(self) -> None:
        """Stop taking jobs; the thread ends once the queued ones are done."""
        with self._cv:
            self._closed = True
            self._cv.notify()

    def _next(self):
        """The next (client, future, fn, wanted) in turn, or None when closed and empty. Holds the lock."""
        while not self._queues:
            if self._closed:
                return None
            self._cv.wait()
        client, queue = next(iter(self._queues.items()))
        future, fn, wanted = queue.popleft()
        if queue:
            self._queues.move_to_end(client)  # its next job waits for every other address's turn
        else:
            del self._queues[client]
        return client, future, fn, wanted

    def _run(self) -> None:
        while True:
            with self._cv:
                job = self._next()
            if job is None:
                return
            client, future, fn, wanted = job
            if wanted is not None and not wanted():
                future.cancel()  # nobody waits for it any more: dropped, and its waiters told
            ran = future.set_running_or_notify_cancel()
            result = error = None
            if ran:
                try:
                    result = fn()
                except BaseException as exc:  # noqa: BLE001 - handed to the waiting request
                    error = exc
            with self._cv:  # counted and released before its waiters wake: stats() and the place agree
                if ran:
                    self._done += 1
                else:
                    self._dropped += 1  # not wanted at its turn, or cancelled as it left its queue
                self._release(client)
            if ran and error is None:
                future.set_result(result)
            elif ran:
                future.set_exception(error)
