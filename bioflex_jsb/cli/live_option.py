"""``--live [HOST:]PORT``: serve a run's log live to Foxglove (``gust``, ``sitl``, ``ardupilot``).

The commands call four functions: :func:`add_live_arguments` when they register,
:func:`start_live` before their log file is made (it refuses what cannot be served: exit 2,
one line; it starts the command's one server, :class:`bioflex_jsb.sinks.live.LiveServer`),
:func:`live_opener` around the function that opens their log files (each file is teed to
that server as it is written) and :func:`stop_live` when the run is over (it prints what was
served). Without ``--live`` the four do nothing.

One server per command, not per file: a SITL session's log rolls to a new file at every
reset and size limit, and a server per file, stopped and bound again on the same port
there, fails ("Address already in use", 2 of 3 sessions with 17 files in 6 s) and
disconnects the clients at each file.

The server listens on loopback unless ``--live-any-host``: a simulation server should not
listen on the network by default (the Foxglove protocol has no authentication; anyone who
can reach the port sees the run).
"""

from __future__ import annotations

import argparse
import sys

DEFAULT_LIVE_HOST = "127.0.0.1"


def live_address(text: str) -> tuple[str, int]:
    """argparse type: ``[HOST:]PORT`` (``[::1]:PORT`` for an IPv6 address) → (host, port);
    PORT 0..65535 (0: any free port, printed at the start)."""
    host, sep, port = text.rpartition(":")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    elif ":" in host:
        raise argparse.ArgumentTypeError(
            f"--live {text!r}: write an IPv6 address in brackets, [::1]:PORT")
    if not (port.isascii() and port.isdigit()) or not 0 <= int(port) <= 65535:
        raise argparse.ArgumentTypeError(
            f"--live {text!r}: give [HOST:]PORT with PORT an integer 0..65535 (0: any free "
            "port), e.g. 8765 or 127.0.0.1:8765")
    if sep and not host:
        raise argparse.ArgumentTypeError(f"--live {text!r}: the host before ':' is empty; "
                                         "give PORT or HOST:PORT")
    return host or DEFAULT_LIVE_HOST, int(port)


live_address.plain_numbers = True  # type: ignore[attr-defined]  # checks its own text


def add_live_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--live", type=live_address, metavar="[HOST:]PORT", default=None,
        help="also serve every topic of the log live over the Foxglove WebSocket protocol "
        "(Foxglove: Open connection > Foxglove WebSocket > ws://127.0.0.1:PORT; needs "
        "bioflex-jsb[live]); HOST defaults to 127.0.0.1; PORT 0 picks a free port; "
        "docs/logging.md, Live view")
    parser.add_argument(
        "--live-any-host", action="store_true",
        help="allow --live on an address other than loopback (the protocol has no "
        "authentication: whoever reaches the port sees the run)")


def check_live(args: argparse.Namespace) -> None:
    """The live options' refusals (one line, a UsageError), with nothing opened or bound:
    a command checks them before it takes any port (``ardupilot``'s UDP port) or file."""
    from bioflex_jsb.cli.common import UsageError

    if getattr(args, "live", None) is None:
        if getattr(args, "live_any_host", False):
            raise UsageError("--live-any-host without --live: give --live HOST:PORT")
        return
    from bioflex_jsb.sinks.live import is_loopback

    host, port = args.live
    if not is_loopback(host) and not args.live_any_host:
        raise UsageError(f"--live {host}:{port} would listen on the network: a simulation "
                         "server listens on loopback (127.0.0.1, ::1, localhost) unless "
                         "--live-any-host is given")
    if getattr(args, "no_log", False):
        raise UsageError("--live serves the log as it is written: it needs the log "
                         "(drop --no-log)")


def start_live(args: argparse.Namespace, command: str) -> None:
    """Start the live server of ``args.live`` (kept as ``args.live_server``) before the log
    file is made; a UsageError (one line) for what cannot be served."""
    from bioflex_jsb.cli.common import UsageError

    args.live_server = None
    check_live(args)
    if getattr(args, "live", None) is None:
        return
    from bioflex_jsb.sinks.live import LiveError, LiveServer

    host, port = args.live
    try:
        args.live_server = LiveServer(host, port, name=f"bioflex-jsb {command}")
    except LiveError as exc:
        raise UsageError(str(exc)) from None
    print(f"bioflex-jsb {command}: live view on {args.live_server.url} (Foxglove: Open "
          "connection > Foxglove WebSocket)", file=sys.stderr, flush=True)


def live_opener(args: argparse.Namespace, open_log):
    """``open_log`` (any function returning a RunLog, or None), each log it opens also
    served live by the command's one server (a SITL session's files one after the other);
    ``open_log`` itself without ``--live``."""
    server = getattr(args, "live_server", None)
    if server is None:
        return open_log

    def opened(*a, **kw):
        log = open_log(*a, **kw)
        if log is not None:
            server.attach(log)
        return log

    return opened


def stop_live(args: argparse.Namespace) -> None:
    """Stop the live server (if any) and say on stderr what it served."""
    server = getattr(args, "live_server", None)
    if server is None or server.closed:
        return
    server.close()
    s = server.summary()
    dropped = (f", {s['dropped_messages']} dropped (the sender fell behind)"
               if s["dropped_messages"] else "")
    held = ("; a client that stopped reading holds its connection (it ends with this process)"
            if s["stop_held"] else "")
    print(f"bioflex-jsb: live view {s['url']} closed: {s['sent_messages']} messages "
          f"published to {s['clients']} clients{dropped}{held}", file=sys.stderr, flush=True)
