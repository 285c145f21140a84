"""The ``bioflex-jsb`` command: one client of the Python API and the drivers.

Every sub-command lives in its own module of this package and exposes
``register(subparsers)``; the module's ``run(args) -> int`` does the work. Errors a user can
fix are raised as :class:`~bioflex_jsb.cli.common.UsageError` and end as one line on stderr
with exit status 2; a simulation that diverges exits with status 3; the machine failing
(:class:`~bioflex_jsb.cli.common.EnvironmentFault`, an OSError such as ENOSPC) exits 4;
SIGINT and SIGTERM, at any moment of the command, exit 130. The full rule is in
:mod:`bioflex_jsb.cli.common` and docs/reliability.md.
"""

from __future__ import annotations

import errno
import importlib
import signal
import sys

from bioflex_jsb.allocator import keep_freed_memory
from bioflex_jsb.cli.common import (
    EXIT_DIVERGED,
    EXIT_ENVIRONMENT,
    EXIT_INTERRUPTED,
    EXIT_USAGE,
    NAME_MAX_BYTES,
    PATH_MAX_BYTES,
    EnvironmentFault,
    OneLineParser,
    UsageError,
    environment_error,
    install_signal_handlers,
    os_error_line,
    stop_requested,
    uninstall_signal_handlers,
)
from bioflex_jsb.errors import InputError

# Sub-command modules, in the order ``--help`` lists them.
COMMAND_MODULES = (
    "trim",
    "linearize",
    "modes",
    "flutter",
    "aileron",
    "export",
    "gust",
    "sitl",
    "sitl_ardupilot",
    "compare",
    "loads",
    "export_jsbsim",
    "import_modes",
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
    """Run the command line ``argv`` (default: this process's arguments); the exit status.

    With ``argv=None`` the caller is the program itself (the ``bioflex-jsb`` script,
    ``python -m bioflex_jsb``): the stop-signal handlers stay in place after the return,
    so a signal while the interpreter exits still ends with status 130 and one line. An
    in-process caller (tests, ``rerun``) passes ``argv`` and gets its handlers back."""
    installed = install_signal_handlers("")
    if argv is None:
        _escape_unencodable_output()
        # the program's own process: freed buffers kept for the next chunk, no page fault
        # for each (bioflex_jsb.allocator; 0.14-0.20 faults a step of a gust log otherwise)
        keep_freed_memory()
    try:
        return _main(argv)
    except KeyboardInterrupt:  # before a command was chosen (parsing the line, importing)
        print("bioflex-jsb: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        uninstall_signal_handlers(installed, own_process=argv is None)


def _main(argv: list[str] | None) -> int:
    from bioflex_jsb.cli import common
    from bioflex_jsb.cli.speed_option import check_speed

    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: --help/--version (0) or a usage error (2)
        return int(exc.code or 0)
    if args.command is None:
        parser.print_help()
        return EXIT_USAGE
    if common.SIGNALS.depth == 1:
        common.SIGNALS.command = args.command
    name = f"bioflex-jsb {args.command}"
    try:
        if getattr(args, "aircraft_definition", None) is not None or \
                getattr(args, "aircraft", None) is None:  # trim/linearize: theirs at run
            check_speed(args)
        status = int(args.run(args) or 0)
    except (UsageError, InputError) as exc:  # what the user can fix: one line, exit 2
        print(f"{name}: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return EXIT_USAGE
    except EnvironmentFault as exc:
        print(f"{name}: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return EXIT_ENVIRONMENT
    except KeyboardInterrupt:
        print(f"{name}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # the reader of our output went away (`| head`): stop quietly
        _silence_stdout()
        return 128 + signal.SIGPIPE
    except OSError as exc:
        if exc.errno == errno.ENAMETOOLONG:  # only ever a path the user gave: bad input
            print(f"{name}: error: {os_error_line(exc)[:200]}; accepted: names of at most "
                  f"{NAME_MAX_BYTES} bytes, paths of {PATH_MAX_BYTES}", file=sys.stderr)
            return EXIT_USAGE
        if not (environment_error(exc) or _is_log_write_error(exc)):
            raise  # a bug: its traceback
        print(f"{name}: error: {os_error_line(exc)} (what was written before is kept; "
              "docs/reliability.md)", file=sys.stderr)
        return EXIT_ENVIRONMENT
    if stop_requested() and status in (0, EXIT_DIVERGED):
        # the signal arrived while the command was closing its files (deferred): it finished
        print(f"{name}: interrupted while closing its files; they were closed first",
              file=sys.stderr)
        return EXIT_INTERRUPTED
    return status


OUTPUT_ERRORS = "bioflex-jsb-output"  # the error handler of stdout and stderr (below)


def _escape_or_pass_bytes(exc: UnicodeError):
    """The encoding error handler of our output: an undecodable byte of a file name (a
    surrogate U+DC80-U+DCFF, as ``surrogateescape`` made it) is written back as that byte;
    any other character the encoding cannot hold as ``\\u03b1`` (``backslashreplace``)."""
    import codecs

    if not isinstance(exc, UnicodeEncodeError):
        raise exc
    part = exc.object[exc.start:exc.end]
    if all(0xDC80 <= ord(c) <= 0xDCFF for c in part):
        return bytes(ord(c) - 0xDC00 for c in part), exc.end
    return codecs.backslashreplace_errors(exc)


def _escape_unencodable_output() -> None:
    """stdout and stderr write ``\\u03b1`` for a character their encoding cannot hold
    (``PYTHONIOENCODING=ascii``, a C locale, a Latin-1 terminal) instead of failing: our
    tables and help texts use α, η, Δ, °, µ, ≤. A stream that fails on them is one whose
    errors are ``strict`` or, in the C/POSIX locale without UTF-8 mode, ``surrogateescape``
    (which passes undecodable bytes of file names and nothing else): both take
    :func:`_escape_or_pass_bytes`, which keeps what ``surrogateescape`` did. Only for the
    program itself (``argv=None``); an in-process caller keeps its own streams."""
    import codecs

    try:
        codecs.lookup_error(OUTPUT_ERRORS)
    except LookupError:
        codecs.register_error(OUTPUT_ERRORS, _escape_or_pass_bytes)
    for stream in (sys.stdout, sys.stderr):
        if getattr(stream, "errors", None) in ("strict", "surrogateescape") and \
                hasattr(stream, "reconfigure"):
            stream.reconfigure(errors=OUTPUT_ERRORS)


def _is_log_write_error(exc: OSError) -> bool:
    """A log that could not be written (the MCAP sink's own OSError, one line)."""
    mcap_errors = sys.modules.get("bioflex_jsb.sinks.mcap_io.errors")
    return mcap_errors is not None and isinstance(exc, mcap_errors.LogWriteError)


def _silence_stdout() -> None:
    """Point stdout at /dev/null, so the interpreter's final flush does not fail again."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # stdout without a file descriptor
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
