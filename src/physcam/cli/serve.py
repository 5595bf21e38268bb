"""``physcam serve``: the on-set calculator in a browser (a phone page and a JSON API).

The server (physcam.serve) answers with the CLI's own functions: :func:`cli_backend` parses each
query with the very argparse parser of ``physcam report`` / ``lens show`` / ``lens diagram`` /
``sensors`` (so the query names are the flags and every value is read and bounded as on the
command line) and builds the documents with the functions their ``--json`` paths call.
"""

from __future__ import annotations

from ._common import number

EPILOG = """\
examples:
  physcam serve                         this machine only: open http://127.0.0.1:8765/
  physcam serve --host 0.0.0.0          every phone on the set's network: prints the address and a QR code
  physcam serve --port 0 --check        bind a free port, answer one report in-process, exit (scripts, CI)

API (payloads are the CLI's --json; parameters are its flags without dashes; docs/serve.md):
  /api/report?focal=50&fstop=2.8&focus=3m&sensor=S35     /api/dof.svg?...   /api/focus-table?...&marks=1m,2m
  /api/sensors   /api/lenses   /api/lens/dgauss_50mm?focus=2m   /api/lens/dgauss_50mm/diagram.svg?fstop=4
"""

#: The lens diagram the page shows: inches wide and the points of its text (at 390 px, text >= 12 px).
DIAGRAM_WIDTH_IN, DIAGRAM_TEXT_PT = 4.4, 12.0
#: Flags of the CLI's parsers that choose output, files or file reading: never query parameters.
OUTPUT_FLAGS = frozenset({"json", "cameras", "plot", "force", "lenient", "output", "help"})


def register(sub) -> None:
    import argparse

    p = sub.add_parser(
        "serve",
        help="the on-set calculator in a browser: a phone page and a JSON API (the CLI's --json) for the set",
        description="Serve the lens report to browsers: one phone-first page and a JSON API whose payloads are "
        "the CLI's --json documents. Localhost by default; --host 0.0.0.0 opens it to the network.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on: 127.0.0.1 (default, this machine only) or 0.0.0.0 (every device on "
                        "the network; prints this machine's addresses and a QR code for phones)")
    p.add_argument("--port", type=_port, default=8765, help="TCP port (default 8765; 0 picks a free one)")
    p.add_argument("--rate-limit", metavar="N", type=number("rate limit", lo=1, hi=100000), default=60.0,
                   help="requests per second per client address, in bursts of up to twice that (default 60); "
                        "more are answered 429")
    p.add_argument("--log-requests", action="store_true", help="print one line per request")
    p.add_argument("--cert", metavar="PEM", help="serve HTTPS with this certificate (with --key): phones on the network "
                                                 "then install the page's offline copy (a secure context; docs/serve.md)")
    p.add_argument("--key", metavar="PEM", help="the certificate's private key (with --cert)")
    p.add_argument("--check", action="store_true",
                   help="bind the address, print what would be served, answer one report in-process and exit "
                        "without serving (for scripts and tests)")
    p.set_defaults(handler=run)


def _port(text):
    import argparse

    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"port must be a whole number from 0 to 65535, got {text!r}") from None
    if not 0 <= v <= 65535:
        raise argparse.ArgumentTypeError(f"port must be a whole number from 0 to 65535, got {text!r}")
    return v


# --------------------------------------------------------------------------------------------
def _refuse(message):
    """argparse's error, raised instead of exiting; "argument --focus: ..." reads "focus: ..." (the query name)."""
    import re

    from ..errors import InputError

    raise InputError(re.sub(r"^argument --([a-z0-9-]+)(/-\w)?: ", r"\1: ", str(message)))


def _leaf(parser, *path):
    """The sub-parser of ``physcam PATH...`` in ``parser``, made to raise InputError instead of exiting."""
    import argparse

    p = parser
    for name in path:
        sub = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction))
        p = sub.choices[name]
    p.error = _refuse  # an instance attribute: argparse calls self.error(message)
    return p


class _QueryParser:
    """``parser.parse_args(["--name=value", ...])`` for a query whose names are the parser's long flags
    exactly (the server has checked them against :func:`_names`), without argparse's scan of the
    argument list on every call (a tenth of a distinct report's CPU in ``physcam serve``, issue 47).

    Each value goes through argparse's own conversion and checks (``_get_values``: the option's type,
    its choices) and its action, into a namespace of the defaults argparse gives with no arguments,
    so the result and every refusal (``_refuse``'s line) are those of ``parse_args``; a name that is
    no such flag goes to ``parse_args`` itself. For a parser with no required options and no
    mutually exclusive groups (``parse_args`` checks those after the values)."""

    def __init__(self, parser):
        import argparse

        if parser._mutually_exclusive_groups or any(a.required for a in parser._actions):
            raise ValueError(f"{parser.prog}: required or exclusive options need parse_args")
        self.parser, self.actions = parser, {}
        for a in parser._actions:
            if a.option_strings and a.nargs != 0:
                flag = max(a.option_strings, key=len)
                self.actions[flag.lstrip("-")] = (a, flag)
        self.defaults = vars(parser.parse_args([]))
        self.error = argparse.ArgumentError

    def parse(self, q):
        """The namespace of ``q`` (name -> text), as ``parser.parse_args(_options(q))`` gives it."""
        import argparse

        if not self.actions.keys() >= q.keys():
            return self.parser.parse_args(_options(q))
        ns = argparse.Namespace(**self.defaults)
        try:
            for name, text in q.items():
                action, flag = self.actions[name]
                action(self.parser, ns, self.parser._get_values(action, [text]), flag)
        except self.error as err:
            self.parser.error(str(err))  # what parse_args does with a refused value: _refuse
        return ns


def _names(parser) -> frozenset[str]:
    """Query names of a parser: its long flags without dashes (and positionals by dest), less OUTPUT_FLAGS."""
    out = set()
    for a in parser._actions:
        if a.option_strings:
            if a.nargs == 0:
                continue
            name = max(a.option_strings, key=len).lstrip("-")
        else:
            name = a.dest
        if name not in OUTPUT_FLAGS:
            out.add(name)
    return frozenset(out)


def _bundled(name: str) -> str:
    """The slug of the bundled lens ``name``: the server reads no lens file, only the library."""
    from ..errors import InputError
    from ..lens.library import find_lens

    try:
        return find_lens(name).slug
    except InputError as exc:
        hint = str(exc).split(" (`physcam lenses`")[0]
        raise InputError(f"{hint} (the server offers the bundled lenses: /api/lenses lists them)") from None


def _options(q, skip=()) -> list[str]:
    return [f"--{k}={v}" for k, v in q.items() if k not in skip]


def _svg(fig, dpi: int = 130, description: str | None = None) -> bytes:
    """A figure as SVG with its text kept as text (a third of the size, quicker to draw and send)."""
    import matplotlib

    from ..figures import figure_bytes, figure_style

    with figure_style(), matplotlib.rc_context({"svg.fonttype": "none"}):  # physcam's settings, then this one
        return figure_bytes(fig, "svg", dpi=dpi, description=description)


def cli_backend():
    """A :class:`physcam.serve.Backend` answering with the CLI's functions and parsers."""
    from ..serve import Backend
    from . import build_parser
    from .lens import diagram_options, lenses_document, show_document
    from ..errors import InputError, PhysCamError
    from ._common import bare_hint, resolve_bare_distances
    from .report import camera_blocks, report_document, solve_from_args
    from .sensors import sensor_document

    root = build_parser()
    parsers = {"report": _leaf(root, "report"), "sensors": _leaf(root, "sensors"),
               "lens": _leaf(root, "lens", "show"), "diagram": _leaf(root, "lens", "diagram")}
    params = {k: _names(p) for k, p in parsers.items()}
    report_query = _QueryParser(parsers["report"])  # the report's options without argparse's scan
    params["lens"] = params["lens"] - {"lens", "_lens_positional"}  # the lens is the path: /api/lens/{name}
    params["diagram"] = params["diagram"] - {"lens", "_lens_positional"}
    params["lenses"] = frozenset()
    params["health"] = frozenset()

    def solved(q):
        q = dict(q)
        if "lens" in q:
            q["lens"] = _bundled(q["lens"])
        args = report_query.parse(q)
        resolve_bare_distances(args)  # the one rule for a bare focus, near or far (the page sends its units)
        try:
            rep = solve_from_args(args)
        except PhysCamError as exc:  # "did you mean 3m?", as the command line says it
            hint = bare_hint(args, str(exc))
            if not hint:
                raise
            raise InputError(str(exc).splitlines()[0] + hint) from None
        return rep, args

    def report(q):
        rep, args = solved(q)
        return report_document(rep, camera_blocks(rep, args), args)

    def dof_svg(q):
        import json

        from ..onset.dof_plot import dof_chart_figure
        from .report import dof_chart_solver

        rep, args = solved(q)  # the page asks for feet with units=ft (never the server's user config)
        fig = dof_chart_figure(rep, dof_chart_solver(args, rep), size_in=(4.4, 3.9), units=args.units or "m")
        # the chart's axes and curves, for the page's mark under the cursor (app.js)
        return _svg(fig, description=json.dumps(fig.physcam_chart, separators=(",", ":")))

    def sensors(q):
        from ..optics.sensors import sensors as all_sensors

        from .sensors import select

        args = parsers["sensors"].parse_args(["--", q["name"]] if "name" in q else [])
        rows = select(args) if args.name else list(all_sensors())
        return [sensor_document(s) for s in rows]

    def lens(name, q):
        return show_document(parsers["lens"].parse_args([*_options(q), f"--lens={_bundled(name)}"]))

    def diagram_svg(name, q):
        from ..analysis.lens_cards.diagram import lens_diagram
        from ..lens.library import load_lens

        args = parsers["diagram"].parse_args([*_options(q), "--output=diagram.svg", f"--lens={_bundled(name)}"])
        resolve_bare_distances(args)
        from ..optics.state import camera_state

        opts = diagram_options(args)
        camera = camera_state(load_lens(args.lens), focus_mm=opts.pop("focus_mm"), fstop=opts.pop("fstop"))
        # drawn for a phone: 4.4 in wide with 12 pt text reads >= 12 px at 390 px (the page's img is ~366 px wide)
        fig = lens_diagram(camera, **opts).figure(units=args.units or "m", width_in=DIAGRAM_WIDTH_IN,
                                                  text_pt=DIAGRAM_TEXT_PT)
        return _svg(fig, dpi=150)

    from ._config import load_config

    return Backend(report=report, dof_svg=dof_svg, sensors=sensors, lenses=lenses_document, lens=lens,
                   diagram_svg=diagram_svg, parameters=params, units=load_config().units or "m")


def _tls_files(args):
    """(certificate, key) for --cert/--key, both readable PEM files and a pair that loads, or None."""
    import ssl
    from pathlib import Path

    from ..errors import InputError

    if (args.cert is None) != (args.key is None):
        raise InputError("HTTPS needs both --cert and --key (PEM files, e.g. from mkcert or your own CA)")
    if args.cert is None:
        return None
    for name, path in (("--cert", args.cert), ("--key", args.key)):
        if not Path(path).is_file():
            raise InputError(f"{name} {path}: no such file")
    try:
        ssl.create_default_context(ssl.Purpose.CLIENT_AUTH).load_cert_chain(args.cert, args.key)
    except (ssl.SSLError, OSError) as exc:
        raise InputError(f"--cert {args.cert} with --key {args.key} do not load as a PEM certificate and its key: "
                         f"{getattr(exc, 'reason', None) or exc}") from None
    return args.cert, args.key


def run(args) -> int:
    import ipaddress
    import json
    import warnings
    from urllib.parse import urlencode

    from ..errors import PhysCamError, PhysCamWarning
    from ..serve import Limits, asgi_get, bind_socket, create_app, qr_text, run_server, url_for

    limits = Limits(rate=args.rate_limit, burst=max(2, int(2 * args.rate_limit)))
    tls = _tls_files(args)
    app = create_app(cli_backend(), limits)
    sock = bind_socket(args.host, args.port)
    try:
        if not args.check:
            # the lens library (read once, ~0.5 s) before the first phone asks: every page load lists it;
            # then one lens's report, so the first one asked does not pay for importing the real-lens
            # code (issue 47: 33 ms of CPU the first time, 7-11 ms after; under load every request
            # asking it meanwhile waited for that)
            status, _, body = asgi_get(app, "/api/lenses")
            names = [lens.get("slug") for lens in json.loads(body)] if status == 200 else []
            if names and isinstance(names[0], str):
                asgi_get(app, "/api/report?" + urlencode({"lens": names[0], "focus": "2m"}))
        host, port = sock.getsockname()[:2]
        urls = url_for(sock, "https" if tls else "http")
        try:
            wildcard = ipaddress.ip_address(host).is_unspecified
        except ValueError:
            wildcard = False
        if wildcard:
            print(f"physcam serve: listening on every network interface, port {port}", flush=True)
            lan = [u for u in urls if "127.0.0.1" not in u]
            if lan:
                print(f"on a phone on this network open {lan[0]}  (or scan the code)", flush=True)
                print(qr_text(lan[0]), end="", flush=True)
                for u in lan[1:]:
                    print(f"also: {u}", flush=True)
            else:
                print("no network address found on this machine's interfaces; phones cannot reach it yet",
                      flush=True)
            print(f"on this machine: {urls[-1]}", flush=True)
        else:
            print(f"physcam serve: listening on {urls[0]}", flush=True)
        if args.check:
            status, _, body = asgi_get(app, "/api/report?focal=50&fstop=2.8&focus=3m&sensor=S35")
            if status != 200:
                raise PhysCamError(f"the server's own check failed: HTTP {status} {body[:200]!r}")
            status, _, _ = asgi_get(app, "/")
            if status != 200:
                raise PhysCamError(f"the server's own check failed: the page answered HTTP {status}")
            print("check: the page and /api/report answer; not serving (--check)", flush=True)
            return 0
        print("Ctrl-C stops the server", flush=True)
        warnings.simplefilter("ignore", PhysCamWarning)  # the reports carry these in their notes
        try:
            run_server(app, sock, log_requests=args.log_requests, limits=limits, certfile=tls and tls[0],
                       keyfile=tls and tls[1])
        except KeyboardInterrupt:  # uvicorn has shut down cleanly and passes Ctrl-C on
            print("physcam serve: stopped", flush=True)
    finally:
        sock.close()
    return 0
