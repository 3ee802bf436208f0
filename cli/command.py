"""The ``jik`` command (also ``python -m jik``): ``jik serve``, ``jik reproduce NAME [--json]``,
``jik errata``, ``jik bench [NAME]``.

Only ``serve`` needs the web parts (the ``app`` extra); the others run on the engine alone,
so this module imports nothing of :mod:`jik.app` until ``serve`` asks for it.
"""

from __future__ import annotations

import argparse
import importlib
import json
import signal
import sys
from typing import Any

from jik import install_hint

from .robot_commands import add_robot_commands, guarded
from .serve_address import Announcer, listen_problem, port_number

#: Reproductions: name -> module in jik.engine.reproductions with run() and format_text().
REPRODUCTIONS = {
    "table1": "Table 1: repeatability of Manipulator 2, pseudoinverse vs extended (38)",
    "manipulator1": "Manipulator 1: E1 and E2 of (32), (33), (36) and the symbolic checks",
    "manipulator2": "Manipulator 2: E2 synthesis, cubic fit, Table 1 with e2_synthesized",
    "unicycle": "Unicycle, section 6.2: runs from A and B with both inverses",
    "algorithms": "drift of all five algorithms on Table 1's loop after 1, 10 and 100 cycles",
}


#: The top-level modules that the web parts and the benchmarks import and only the ``app``
#: extra installs (tests/test_packaging.py checks the list against their imports).
WEB_PACKAGES = frozenset(
    "fastapi fastapi_offline starlette sse_starlette uvicorn httpx pydantic pydantic_core "
    "pydantic_settings psutil websockets viser plotly rich markdown_it".split()
)


def _progress(fraction: float) -> None:
    """The progress on stderr: rewritten in place on a terminal, a line each in a log."""
    text = f"  progress {100 * fraction:5.1f}%"
    if not sys.stderr.isatty():
        sys.stderr.write(text + "\n")
    else:
        sys.stderr.write("\r" + text + ("\n" if fraction >= 1 else ""))
    sys.stderr.flush()


def reproduce(args: argparse.Namespace) -> int:
    if args.printed_gradient and args.name != "table1":
        from ..engine.exceptions import InvalidInputError

        raise InvalidInputError(
            f"--printed-gradient is for table1 (the printed j32, j33 of (39)), not {args.name}",
            "printed_gradient",
        )
    module = importlib.import_module(f"..engine.reproductions.{args.name}", __package__)
    kwargs: dict[str, Any] = {}
    if args.name == "table1" and args.printed_gradient:
        kwargs["printed_gradient"] = True
    elif args.name != "table1" and not args.json:
        kwargs["progress"] = _progress
    result = module.run(**kwargs)
    if args.json:
        print(json.dumps(result))
    else:
        print(module.format_text(result))
    return 0


def errata(args: argparse.Namespace) -> int:
    from ..docs import paper_errata

    print(paper_errata(), end="")
    return 0


#: What installs the web parts, for the message of a command that needs them.
APP_EXTRA_HINT = install_hint("app")


def missing_app_extra(error: ModuleNotFoundError) -> int:
    """Say which command installs the web parts that ``error`` found missing; exit code 2.

    Re-raises an error about any other module: that is a fault, not a missing extra.
    """
    if not error.name or error.name.split(".")[0] not in WEB_PACKAGES:
        raise error
    sys.stderr.write(
        f"jik: this command needs the web parts of jik, and {error.name!r} is not installed.\n"
        f"Install them with:  {APP_EXTRA_HINT}\n"
    )
    return 2


def serve(args: argparse.Namespace) -> int:
    try:
        from ..app.api.server import PortInUse, run_server
    except ModuleNotFoundError as error:
        return missing_app_extra(error)
    from ..engine.exceptions import InvalidInputError

    problem = listen_problem(args.host, args.port)
    if problem:
        sys.stderr.write(f"jik serve: {problem}\n")
        return 2
    announcer = Announcer(args.host, args.port)
    announcer.start()
    try:
        run_server(
            host=args.host,
            port=args.port,
            allowed_hosts=tuple(args.allowed_host),
            forwarded_allow_ips=args.forwarded_allow_ips,
        )
    except (PortInUse, InvalidInputError) as refused:
        sys.stderr.write(f"jik serve: {refused}\n")
        return 2
    finally:
        announcer.stop()
    return 0


def bench(args: argparse.Namespace) -> int:
    from ..benchmarks import run_benchmarks

    try:
        return run_benchmarks(args.names, quick=args.quick)
    except ModuleNotFoundError as error:
        return missing_app_extra(error)


def main(argv: list[str] | None = None) -> int:
    from jik import __version__

    from .atlas import add_atlas_parser

    parser = argparse.ArgumentParser(
        prog="jik", description="jik: a lab for repeatable Jacobian inverse kinematics"
    )
    parser.add_argument("--version", action="version", version=f"jik {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser(
        "serve",
        help="start the REST API and the dashboard",
        description="Serve the dashboard (open the address it prints) and the REST API (its "
        "reference at /docs), on 127.0.0.1 unless --host says otherwise.",
    )
    p.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    p.add_argument(
        "--port",
        type=port_number,
        default=8000,
        help="HTTP port of the API, page and scene (default 8000)",
    )
    p.add_argument(
        "--allowed-host",
        action="append",
        default=[],
        metavar="NAME",
        help="a host name the server answers to besides localhost, 127.0.0.1 and [::1] (repeat it; "
        "also JIK_ALLOWED_HOSTS, comma-separated; '*' for any)",
    )
    p.add_argument(
        "--forwarded-allow-ips",
        default=None,
        metavar="IPS",
        help="behind a reverse proxy: its addresses (comma-separated, '*' for any), whose "
        "X-Forwarded-For names the client; default: none, the client is the connection's peer",
    )
    p.set_defaults(func=serve)

    p = sub.add_parser("reproduce", help="recompute a result of the paper")
    p.add_argument(
        "name",
        choices=sorted(REPRODUCTIONS),
        help="; ".join(f"{k}: {v}" for k, v in REPRODUCTIONS.items()),
    )
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")
    p.add_argument(
        "--printed-gradient",
        action="store_true",
        help="table1 only: use the printed j32, j33 of (39) instead of the gradient of (38)",
    )
    p.set_defaults(func=guarded(reproduce))

    p = sub.add_parser(
        "errata",
        help="print where the printed paper and jik disagree, each with the command that shows "
        "it (docs/paper-errata.md, Markdown)",
    )
    p.set_defaults(func=errata)

    add_atlas_parser(sub)

    p = sub.add_parser("bench", help="run the benchmarks (medians, ratios to straightforward code)")
    from ..benchmarks import available

    p.add_argument(
        "names", nargs="*", help=f"benchmarks to run (default: all): {', '.join(available())}"
    )
    p.add_argument("--quick", action="store_true", help="fewer repetitions, for a smoke test")
    p.set_defaults(func=bench)

    add_robot_commands(sub)

    args = parser.parse_args(argv)
    if args.func is serve or not hasattr(signal, "SIGPIPE"):
        # The server keeps Python's handling: a client or worker that goes away is an EPIPE
        # error where it is written to, not the end of the server.
        return args.func(args)
    # `jik reproduce table1 | head` ends quietly (and the caller's handling comes back after).
    previous = signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    try:
        return args.func(args)
    finally:
        signal.signal(signal.SIGPIPE, previous)


if __name__ == "__main__":
    raise SystemExit(main())
