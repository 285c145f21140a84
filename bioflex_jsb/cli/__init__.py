"""The ``bioflex-jsb`` command: one client of the Python API and the drivers.

Every sub-command lives in its own module of this package and exposes
``register(subparsers)``; the module's ``run(args) -> int`` does the work. Errors a user can
fix are raised as :class:`~bioflex_jsb.cli.common.UsageError` and end as one line on stderr
with exit status 2; a simulation that diverges exits with status 3.
"""

from __future__ import annotations

import importlib
import signal
import sys

from bioflex_jsb.cli.common import EXIT_USAGE, OneLineParser, UsageError
from bioflex_jsb.errors import InputError

# Sub-command modules, in the order ``--help`` lists them.
COMMAND_MODULES = (
    "trim",
    "linearize",
    "modes",
    "flutter",
    "export",
    "gust",
    "sitl",
    "sitl_ardupilot",
    "compare",
    "export_jsbsim",
    "info",
    "plot",
    "rerun",
    "sweep",
    "bench",
)


def build_parser() -> OneLineParser:
    parser = OneLineParser(
        prog="bioflex-jsb",
        description=(
            "Bio-inspired elastic-wing UAV: JSBSim airframe, modal wing, coupled LTI model. "
            "All inputs and outputs are SI: speeds in m/s, angles in rad in JSON "
            "(degrees only where a column says deg), frequencies in rad/s unless marked Hz."
        ),
    )
    from bioflex_jsb import __version__

    parser.add_argument("--version", action="version", version=f"bioflex-jsb {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    for name in COMMAND_MODULES:
        importlib.import_module(f"bioflex_jsb.cli.{name}").register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: --help/--version (0) or a usage error (2)
        return int(exc.code or 0)
    if args.command is None:
        parser.print_help()
        return EXIT_USAGE
    previous = signal.getsignal(signal.SIGTERM)
    signal.signal(signal.SIGTERM, _terminate)  # SIGTERM stops a run like Ctrl-C: logs close
    try:
        return int(args.run(args) or 0)
    except (UsageError, InputError) as exc:  # what the user can fix: one line, exit 2
        print(f"bioflex-jsb {args.command}: error: {' '.join(str(exc).split())}",
              file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print(f"bioflex-jsb {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader of our output went away (`| head`): stop quietly
        _silence_stdout()
        return 128 + signal.SIGPIPE
    finally:
        signal.signal(signal.SIGTERM, previous)


def _silence_stdout() -> None:
    """Point stdout at /dev/null, so the interpreter's final flush does not fail again."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # stdout without a file descriptor
        pass


def _terminate(signum, frame):
    raise KeyboardInterrupt


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
