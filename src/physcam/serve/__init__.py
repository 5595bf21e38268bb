"""``physcam serve``: the on-set calculator in a browser, for the phones on a set's network.

One page (``static/``, shipped in the package: no CDN, works with no internet) and a JSON API
whose payloads are the CLI's own ``--json`` documents, with query parameters named like the CLI's
flags (docs/serve.md). The server is Starlette on uvicorn (why: docs/serve.md).

Layering: this package sits above ``usd/`` and below ``cli/``. It does not compute reports
itself: :class:`~physcam.serve.app.Backend` is a table of functions, and ``physcam.cli.serve``
fills it with the very functions the CLI's ``--json`` paths call, so the page, the API and the
command line cannot disagree.
"""

from __future__ import annotations

from ..extras import require_extra

require_extra("serve", "the phone page (physcam serve)")

from .app import Backend, Limits, create_app  # noqa: E402
from .net import asgi_get, bind_socket, lan_addresses, qr_text, run_server, url_for  # noqa: E402

__all__ = ["Backend", "Limits", "create_app", "asgi_get", "bind_socket", "lan_addresses", "qr_text", "run_server",
           "url_for"]
