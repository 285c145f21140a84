"""Shared CLI helpers: one-line errors, exit statuses, signals, validated argument types,
JSON output, log names.

Exit statuses (every command; docs/reliability.md):

* 0: done.
* 1 (:data:`EXIT_NO_RESULT`): the work ran and gave no result: every case of a sweep failed,
  a repeated run differs from its log, ``info --check`` found a damaged log; one line says
  why.
* 2 (:data:`EXIT_USAGE`): what was asked cannot be done as given (bad input, an unusable
  path, an existing output without ``--force``): one line, nothing ran.
* 3 (:data:`EXIT_DIVERGED`): a simulation left the model's valid range (a result).
* 4 (:data:`EXIT_ENVIRONMENT`): the machine stopped the work (no space, a read-only or
  failing disk, a lost cluster, an output another process holds): one line; what was
  finished is kept, and the same command (``sweep --resume``) completes it once the cause
  is fixed.
* 130 (:data:`EXIT_INTERRUPTED`): stopped by SIGINT (Ctrl-C) *or* SIGTERM, at any moment,
  including while the command closes its files or after it has finished (a signal that
  arrives then is deferred until the files are closed, and the status is still 130), so a
  supervisor sees one status for "stopped on request". A signal never turns 2 or 4 into
  130. A third signal while files are being closed ends the process at once (130, one line).
* 141: the reader of our output went away (``| head``), quietly.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import json
import math
import os
import re
import signal
import sys
import threading
from typing import Any, NoReturn

from bioflex_jsb.cli.usage import UsageError  # noqa: F401  (every command's, re-exported)
from bioflex_jsb.interrupts import STOP, unsafe_frame

EXIT_NO_RESULT = 1
EXIT_USAGE = 2
EXIT_DIVERGED = 3
EXIT_ENVIRONMENT = 4
EXIT_INTERRUPTED = 130
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class EnvironmentFault(Exception):
    """The machine stopped the work (disk full, a lost cluster, an output held by another
    process); reported as one line, exit status 4."""


# The errno values that mean "the storage or the system failed", not "this path is wrong":
# an OSError with one of them ends any command with one line and exit status 4.
ENVIRONMENT_ERRNOS = frozenset(
    getattr(errno, name) for name in
    ("ENOSPC", "EDQUOT", "EFBIG", "EROFS", "EIO", "ENOMEM", "EMFILE", "ENFILE", "ENOLCK")
    if hasattr(errno, name)
)


def environment_error(exc: BaseException) -> bool:
    """Whether ``exc`` is an OSError of the machine (disk full, read-only, I/O error)."""
    return isinstance(exc, OSError) and exc.errno in ENVIRONMENT_ERRNOS


def os_error_line(exc: OSError) -> str:
    """One line for an OSError: the reason and the file, without the chain."""
    where = f": {exc.filename!r}" if getattr(exc, "filename", None) else ""
    return f"{exc.strerror or ' '.join(str(exc).split()) or type(exc).__name__}{where}"


# ---------------------------------------------------------------------------------------
# Signals: the first SIGINT/SIGTERM stops the work (KeyboardInterrupt); later ones, and any
# that arrive inside ``closing()`` or after the command returned, are deferred. The handler
# raises only in a frame that can take an exception: landing in a callback from native code
# (JSBSim's logger) or in an import it sets ``interrupts.STOP.pending`` instead, and the stop
# is raised at the next safe point (a loop's check between steps, the end of JSBSim's
# capture block) or, failing that, by a re-delivery of the signal REDELIVERY_S later.
# ---------------------------------------------------------------------------------------
# Re-delivery delay of a deferred stop [s]: JSBSim's callbacks last microseconds and an
# import milliseconds to a second; 5 ms keeps a stop prompt at a negligible cost (one
# thread per deferred signal, a few retries at most while an import completes).
REDELIVERY_S = 0.005


class _SignalState:
    def __init__(self) -> None:
        self.depth = 0  # nested main() calls (rerun runs a command inside its own)
        self.received = 0  # stop signals since the outermost main() started
        self.shield = 0  # closing() blocks entered
        self.previous: dict[int, Any] = {}
        self.command = ""
        self.installed = False  # our stop handlers are in place (outermost main())
        self.redelivered = False  # the next stop signal is our own re-delivery
        self.lock = threading.Lock()  # re-delivery against uninstalling the handlers


SIGNALS = _SignalState()


def _emergency_exit(reason: str) -> NoReturn:
    with contextlib.suppress(OSError, ValueError):
        sys.stderr.write(f"bioflex-jsb {SIGNALS.command}: {reason}\n")
        sys.stderr.flush()
    os._exit(EXIT_INTERRUPTED)


def _on_stop_signal(signum, frame) -> None:
    if SIGNALS.redelivered:  # our own re-delivery of a deferred stop: not a new signal
        SIGNALS.redelivered = False
        if not STOP.pending or SIGNALS.shield:
            return  # a check point raised it meanwhile, or files are being closed (130 after)
    else:
        SIGNALS.received += 1
        if SIGNALS.shield or SIGNALS.received > 1 or STOP.pending:
            if SIGNALS.received >= 3:
                _emergency_exit("stopped at once (third signal while closing files); a "
                                "log may need `bioflex-jsb info --recover`")
            return  # deferred: the files are being closed; the exit status will be 130
    if unsafe_frame(frame):  # inside a native callback or an import: never raise here
        STOP.pending = True
        _redeliver_later(signum)
        return
    STOP.pending = False
    raise KeyboardInterrupt


def _redeliver_later(signum: int) -> None:
    """Send ``signum`` to the main thread again in REDELIVERY_S unless the deferred stop was
    raised by then (a real signal also wakes a blocking wait, which PEP 475 would resume)."""
    main_id = threading.main_thread().ident

    def send() -> None:
        with SIGNALS.lock:
            if STOP.pending and SIGNALS.installed and main_id is not None:
                SIGNALS.redelivered = True
                signal.pthread_kill(main_id, signum)

    timer = threading.Timer(REDELIVERY_S, send)
    timer.daemon = True
    timer.start()


def _on_late_signal(signum, frame) -> None:
    """After the command returned (the interpreter is exiting): flush, status 130."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError, AttributeError):
            stream.flush()
    _emergency_exit("interrupted while exiting (the work was complete and its files "
                    "closed)")


def install_signal_handlers(command: str) -> bool:
    """Called by ``main``: SIGINT and SIGTERM raise KeyboardInterrupt once (both exit 130).
    Returns False for a nested call (handlers already in place) or off the main thread."""
    SIGNALS.depth += 1
    if SIGNALS.depth > 1 or threading.current_thread() is not threading.main_thread():
        return False
    SIGNALS.received, SIGNALS.shield, SIGNALS.command = 0, 0, command
    SIGNALS.redelivered, STOP.pending = False, False
    SIGNALS.previous = {s: signal.signal(s, _on_stop_signal) for s in STOP_SIGNALS}
    SIGNALS.installed = True
    return True


def uninstall_signal_handlers(installed: bool, own_process: bool) -> None:
    """Called by ``main`` on its way out: an in-process caller (tests, rerun) gets its
    handlers back; the program itself (``own_process``) keeps deferring to the end."""
    SIGNALS.depth -= 1
    if not installed:
        return
    with SIGNALS.lock:  # no re-delivery reaches the caller's handlers
        SIGNALS.installed = False
        STOP.pending = False
    for s, h in SIGNALS.previous.items():
        signal.signal(s, _on_late_signal if own_process else h)
    SIGNALS.previous = {}


def stop_requested() -> bool:
    """Whether SIGINT/SIGTERM arrived since the command started (deferred or not)."""
    return SIGNALS.received > 0


@contextlib.contextmanager
def closing():
    """A block that a stop signal must not cut (closing a log, compacting a table): a signal
    inside it is deferred, the block completes, and the command then exits 130."""
    SIGNALS.shield += 1
    try:
        yield
    finally:
        SIGNALS.shield -= 1


class OneLineParser(argparse.ArgumentParser):
    """ArgumentParser whose errors are a single line on stderr and exit status 2.

    Stricter than argparse's defaults, for every command and sub-command (sub-parsers are
    of this class too): options are spelled out (no abbreviations: ``--spe`` is not
    ``--speed``, so a later option cannot change what an old command line means); an option
    that takes one value, or a flag, given twice is refused (argparse would keep the last
    silently; options meant to repeat, ``action="append"``, may); and every typed value is
    read with plain ASCII numbers only (:func:`check_plain_numbers`), also where an option's
    own type calls ``float()`` or ``int()``."""

    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)
        self._given: dict[int, str] = {}
        # a value that starts with "-" is a negative number, not an option, when it is a
        # plain number (argparse's own rule misses "-20." and "-1e3"), a non-finite one
        # ("-inf": the option's own check then names the range) or a LOW:HIGH range
        # ("-5:40"); argparse said "expected one argument" for those
        self._negative_number_matcher = re.compile(
            r"\A-(?:" + _UNSIGNED_PLAIN + r"(?::[-+]?" + _UNSIGNED_PLAIN + r")?"
            r"|inf|infinity|nan)\Z", re.IGNORECASE)

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_USAGE, f"{self.prog}: error: {' '.join(message.split())} (see --help)\n")

    def parse_known_args(self, args=None, namespace=None):
        for action in self._actions:  # also those added through argument groups
            if (action.option_strings and isinstance(action, _ONCE_ACTIONS)
                    and type(action) not in _ONCE_CLASSES.values()):
                action.__class__ = _once_class(type(action))
        self._given = {}
        return super().parse_known_args(args, namespace)

    def _get_value(self, action, arg_string):
        if (callable(action.type) and action.type is not str
                and not getattr(action.type, "plain_numbers", False)):  # our own types check
            problem = check_plain_numbers(arg_string)
            if problem:
                raise argparse.ArgumentError(action, problem)
        return super()._get_value(action, arg_string)


_UNSIGNED_PLAIN = r"(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
# Actions that keep one value: given twice, argparse silently keeps the last.
_ONCE_ACTIONS = (argparse._StoreAction, argparse._StoreConstAction,
                 argparse.BooleanOptionalAction)
_ONCE_CLASSES: dict[type, type] = {}


def _once_class(cls: type) -> type:
    """``cls`` refusing a second occurrence of its option in one command line."""
    if cls not in _ONCE_CLASSES:
        def __call__(self, parser, namespace, values, option_string=None):
            given = getattr(parser, "_given", None)
            if given is not None:
                if id(self) in given:
                    first, again = given[id(self)], option_string
                    both = f" (as {first} and {again})" if again and again != first else ""
                    raise argparse.ArgumentError(
                        self, f"given twice{both}; give it once")
                given[id(self)] = option_string or "/".join(self.option_strings)
            cls.__call__(self, parser, namespace, values, option_string)

        _ONCE_CLASSES[cls] = type(f"Once{cls.__name__}", (cls,), {"__call__": __call__})
    return _ONCE_CLASSES[cls]


def check_plain_numbers(text: str) -> str | None:
    """Why ``text`` (a typed option's value) holds a number only Python would read, or None.

    Each ``:`` or ``,`` separated piece that ``float()`` reads (so also ``1_5``, ``１５``,
    ``١٥``, `` 15 ``, ``nan``, ``inf``) must be a plain ASCII decimal
    (:data:`bioflex_jsb.errors.PLAIN_NUMBER_PATTERN`) and finite (``1e999`` is infinite)."""
    from bioflex_jsb.errors import PLAIN_NUMBER_HELP, is_plain_number

    for piece in re.split(r"[:,]", text):
        try:
            value = float(piece)
        except (ValueError, OverflowError):
            continue  # not a number: the option's own type says what it accepts
        where = "" if piece == text else f" in {text!r}"
        if not is_plain_number(piece):
            return f"{piece!r}{where} is not a plain number; accepted: {PLAIN_NUMBER_HELP}"
        if not math.isfinite(value):
            return f"{piece!r}{where} is beyond the range of a floating-point number"
    return None


def number_type(label: str, unit: str = "", *, low: float | None = None,
                high: float | None = None, low_open: bool = False, high_open: bool = False,
                integer: bool = False, symbol: str = ""):
    """argparse type: a plain ASCII number (:func:`bioflex_jsb.errors.plain_number`) in
    [low, high] (``low_open``/``high_open``: that end excluded), an int with ``integer``;
    ``symbol`` names the value in the message (``0 <= Z < 1``; default: ``label``).
    The one numeric type of the command line: every numeric option goes through it (or
    through :func:`finite_float`/:func:`positive_float`, which are made of it)."""
    from bioflex_jsb.errors import (
        PLAIN_INTEGER_HELP,
        PLAIN_NUMBER_HELP,
        InputError,
        is_plain_number,
        plain_integer,
        plain_number,
    )

    shown = f" {unit}" if unit else ""
    kind = "whole number" if integer else "number"
    help_text = PLAIN_INTEGER_HELP if integer else PLAIN_NUMBER_HELP
    below, above = ("<" if low_open else "<="), ("<" if high_open else "<=")
    cond = ""  # the range, as "0 <= Z < 1" or "> 0"
    if low is not None and high is not None:
        cond = f"{low:g} {below} {symbol or label} {above} {high:g}"
    elif low is not None:
        cond = f"{'>' if low_open else '>='} {low:g}"
    elif high is not None:
        cond = f"{above} {high:g}"
    within = f" with {cond}" if cond else ""

    def parse(text: str):
        try:
            value = plain_integer(text, label) if integer else plain_number(text, label)
        except InputError:
            if is_plain_number(text) and not integer:  # 1e999: overflows to infinity
                raise argparse.ArgumentTypeError(
                    f"{label} {text!r} is beyond the range of a floating-point number; give "
                    f"a finite number{' in' + shown if unit else ''}") from None
            raise argparse.ArgumentTypeError(
                f"{label} must be a {kind}{' in' + shown if unit else ''}{within} "
                f"({help_text}), got {text!r}") from None
        if ((low is not None and (value <= low if low_open else value < low))
                or (high is not None and (value >= high if high_open else value > high))):
            verb = "satisfy" if low is not None and high is not None else "be"
            raise argparse.ArgumentTypeError(f"{label} must {verb} {cond}{shown}, got {text!r}")
        return value

    parse.__name__ = label
    parse.plain_numbers = True  # type: ignore[attr-defined]
    return parse


def finite_float(label: str, unit: str):
    """argparse type: any finite plain number, e.g. an altitude (may be negative)."""
    return number_type(label, unit)


def positive_float(label: str, unit: str):
    """argparse type: a finite plain number > 0, e.g. ``positive_float('speed', 'm/s')``."""
    return number_type(label, unit, low=0.0, low_open=True)


def print_json(payload: Any) -> None:
    """Write ``payload`` as JSON to stdout (NaN is refused: it is not valid JSON)."""
    json.dump(payload, sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")


def models_list(text: str) -> tuple[str, ...]:
    """argparse type: comma-separated subset of rigid,coupled,qsd."""
    from bioflex_jsb.flight_dynamics.lti import MODELS

    names = tuple(t.strip() for t in text.split(",") if t.strip())
    bad = [n for n in names if n not in MODELS]
    if not names or bad:
        raise argparse.ArgumentTypeError(
            f"unknown model {bad[0] if bad else text!r}; accepted: {','.join(MODELS)}"
        )
    return tuple(dict.fromkeys(names))


def add_wing_arguments(parser: argparse.ArgumentParser, default: str = "original") -> None:
    """--wing and --mass-basis, shared by every command that builds the elastic wing."""
    from bioflex_jsb.cli.aircraft_option import WingAction
    from bioflex_jsb.flight_dynamics.wing_model import DEFAULT_MASS_BASIS, MASS_BASES, VARIANTS

    parser.add_argument(
        "--wing", default=default, metavar="NAME|FILE.toml", action=WingAction,
        help=f"wing variant: {', '.join(VARIANTS)}, or a variant file (docs/wing_variants.md); "
        f"default {default}",
    )
    parser.add_argument(
        "--mass-basis", choices=MASS_BASES, default=DEFAULT_MASS_BASIS,
        help="generalised masses of the whole wing against whole-span forces (consistent) or "
        "the half-wing m_i as Table B2 reads literally (paper: every H term doubled); "
        f"docs/decisions.md; default {DEFAULT_MASS_BASIS}",
    )
    from bioflex_jsb.cli.aircraft_option import add_aircraft_argument

    add_aircraft_argument(parser, default)  # --aircraft NAME|FILE (cli/aircraft_option.py)


def wing_from_args(args: argparse.Namespace):
    """Build the wing named by --wing (or --aircraft), with ``--lateral-aero`` where the
    command has it; any problem becomes a one-line UsageError."""
    from bioflex_jsb.flight_dynamics.wing_model import with_lateral_aero

    lateral_aero = getattr(args, "lateral_aero", None)
    build = _wing_from_args(args)
    return build if lateral_aero is None else with_lateral_aero(build, lateral_aero)


def _wing_from_args(args: argparse.Namespace):
    if getattr(args, "aircraft_definition", None) is not None:
        from bioflex_jsb.cli.aircraft_option import wing_from_aircraft

        return wing_from_aircraft(args)
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.flight_dynamics.wing_model import (
        VariantError,
        build_wing,
        modes_used_note,
        resolve_variant,
    )

    try:
        variant = resolve_variant(args.wing)
        build = build_wing(variant, mass_basis=args.mass_basis)
    except VariantError:
        raise
    except InputError as exc:  # modal-file and modal-data errors name their field
        raise UsageError(f"wing {args.wing!r}: {exc}") from None
    note = modes_used_note(variant)
    if note:  # accepted, and said: which modes fly and why (stderr: stdout may be JSON)
        print(f"bioflex-jsb: note: {note}", file=sys.stderr)
    return build


LOG_DIR_ENV_VAR = "BIOFLEX_LOG_DIR"  # where runs write their logs by default (else ./logs)


def add_log_arguments(parser: argparse.ArgumentParser) -> None:
    """--out, --force and --no-log: every run writes an MCAP log unless told not to."""
    parser.add_argument(
        "--out", metavar="RUN.mcap",
        help="MCAP log of every step (default: logs/<command>-<wing>-<UTC time>.mcap, the "
        f"directory from ${LOG_DIR_ENV_VAR} when set, never an existing file; an existing "
        "--out is refused unless --force; docs/logging.md)")
    parser.add_argument("--force", action="store_true",
                        help="replace existing output files (--out and the command's other "
                        "outputs: plots, tables, summaries)")
    parser.add_argument("--no-log", action="store_true", help="write no MCAP log")


MAX_LOG_NAME_TRIES = 10_000


def log_path(args: argparse.Namespace, command: str, wing: str) -> str | None:
    """The log file a run writes; None with --no-log.

    ``--out``: refused if it exists unless ``--force`` (:func:`check_output`). Otherwise a
    new file ``<command>-<wing>-<UTC time>[-N].mcap`` in the log directory, *created here*
    with ``O_CREAT | O_EXCL`` (empty, for the log writer to fill): of runs started at the
    same second, in any number of processes, each gets its own file (the first free N), and
    no run ever opens a file another created. The log directory (``$BIOFLEX_LOG_DIR``, else
    ``./logs``) is created if missing, but only its last component: a parent that does not
    exist (a mistyped path) is a UsageError, as is a directory that cannot be written."""
    import time
    from pathlib import Path

    if getattr(args, "no_log", False):
        if args.out is not None:
            raise UsageError("--out and --no-log contradict each other; give one")
        return None
    if args.out is not None:
        check_new_file(args.out, getattr(args, "force", False), "--out", (".mcap",))
        return args.out
    from_env = os.environ.get(LOG_DIR_ENV_VAR)
    folder = Path(from_env or "logs")
    what = f"the log directory ${LOG_DIR_ENV_VAR}" if from_env else "the log directory"
    check_file_name(str(folder), what)
    try:  # the directory itself, never its parents: a mistyped path creates no tree
        folder.mkdir(exist_ok=True)
    except FileNotFoundError:
        raise UsageError(f"{what} {str(folder)!r}: its parent {str(folder.parent)!r} does not "
                         "exist (only the last directory is created); create it, or give "
                         "--out FILE.mcap or --no-log") from None
    except FileExistsError:
        raise UsageError(f"{what} {str(folder)!r} exists and is not a directory; give "
                         "--out FILE.mcap or --no-log") from None
    except OSError as exc:
        kind = EnvironmentFault if environment_error(exc) else UsageError
        raise kind(f"cannot create {what} {str(folder)!r}: {exc.strerror}; give --out "
                   "FILE.mcap or --no-log") from None
    stem = (f"{command}-{_name_part(Path(wing).stem)}-"
            f"{time.strftime('%Y%m%dT%H%M%SZ', time.gmtime())}")
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0)
    for n in range(1, MAX_LOG_NAME_TRIES + 1):
        path = folder / (f"{stem}.mcap" if n == 1 else f"{stem}-{n}.mcap")
        try:
            fd = os.open(path, flags, 0o644)
        except FileExistsError:
            continue
        except OSError as exc:
            kind = EnvironmentFault if environment_error(exc) else UsageError
            raise kind(f"cannot create a log in {str(folder)!r}: {exc.strerror}; give "
                       "--out FILE.mcap or --no-log") from None
        os.close(fd)
        return str(path)
    raise UsageError(f"{str(folder)!r} already holds {MAX_LOG_NAME_TRIES} logs named "
                     f"{stem}*.mcap; give --out FILE.mcap")


# Longest wing-name part of a default log name [characters]: keeps the name, with the
# command and the UTC time, well under NAME_MAX (255 bytes) for any variant file name.
MAX_LOG_NAME_WING_CHARS = 64


# characters no default file name carries: path separators, and what Windows refuses in a
# file name (a colon also reads as a host to scp and rsync: aircraft:sgs_elastic)
NOT_IN_FILE_NAMES = '/\\<>:"|?*'


def _name_part(text: str) -> str:
    """``text`` fit for a default file name: refused characters (a newline, ...) and
    :data:`NOT_IN_FILE_NAMES` replaced by ``_``, cut to :data:`MAX_LOG_NAME_WING_CHARS`."""
    import unicodedata

    safe = "".join("_" if unicodedata.category(c) in REFUSED_NAME_CATEGORIES
                   or c in NOT_IN_FILE_NAMES else c for c in text)
    return safe[:MAX_LOG_NAME_WING_CHARS] or "wing"


def check_output(path: str, force: bool, what: str, ours=None) -> None:
    """Refuse to replace an existing file at ``path`` (a user's file is never overwritten
    without ``--force``): a UsageError naming it, unless ``force`` or ``ours(path)`` says it
    is a file bioflex-jsb wrote itself of this kind (e.g. a PNG with our Software tag). A
    directory or a special file is refused even with ``--force``."""
    from pathlib import Path

    check_file_name(path, what)
    p = Path(path)
    if not p.exists() and not p.is_symlink():
        return
    if not p.is_file():
        raise UsageError(f"{what} {path!r} exists and is not a regular file; give another name")
    if force or (ours is not None and ours(p)):
        return
    raise UsageError(f"{what} {path!r} already exists; give another name or --force to "
                     "replace it")


def check_new_file(path: str, force: bool, what: str, suffixes: tuple[str, ...] = (),
                   ours=None) -> None:
    """Refuse an output file before any work (one-line UsageError): an empty or unusable
    name (:func:`check_file_name`), a suffix not in ``suffixes`` (lower case, with the dot;
    empty: any), an existing file without ``force`` (:func:`check_output`), a directory
    that does not exist."""
    from pathlib import Path

    if not path:
        raise UsageError(f"{what}: the file name is empty")
    check_output(path, force, what, ours=ours)  # a directory, an existing file: said first
    if suffixes and Path(path).suffix.lower() not in suffixes:
        raise UsageError(f"{what} {path!r}: give a name ending in {', '.join(suffixes)}")
    parent = Path(path).parent
    if not parent.is_dir():
        raise UsageError(f"{what} {path!r}: the directory {str(parent)!r} does not exist")


def check_distinct_outputs(*named: tuple[str, str | None]) -> None:
    """Refuse two outputs of one command naming the same file (``named``: (option, path)
    pairs, None or empty for an output not written): the second would replace the first
    while both are reported written."""
    import os.path

    seen: dict[str, str] = {}
    for option, path in named:
        if not path:
            continue
        check_file_name(path, option)  # a NUL or control character: its own one line
        key = os.path.realpath(path)
        if key in seen:
            raise UsageError(f"{seen[key]} and {option} name the same file {path!r}; give "
                             "each its own")
        seen[key] = option


# Longest name of one path component and whole path [bytes] where the file system cannot be
# asked (os.pathconf): Linux's NAME_MAX and PATH_MAX (<linux/limits.h>).
NAME_MAX_BYTES = 255
PATH_MAX_BYTES = 4096
# Characters refused in a file name we create: control characters (Cc: newline, tab, escape,
# NUL, DEL, C1), line and paragraph separators (Zl, Zp: str.splitlines breaks on them) and
# surrogates (Cs: bytes that are not text in the file-system encoding). Each makes a file
# whose name breaks a line of our own output or of `ls`, a shell loop, a CSV of log names.
REFUSED_NAME_CATEGORIES = {"Cc": "a control character", "Zl": "a line separator",
                           "Zp": "a paragraph separator", "Cs": "a byte that is not text"}


def _name_max(path) -> int:
    """NAME_MAX of the file system the nearest existing ancestor of ``path`` is on."""
    from pathlib import Path

    p = Path(path).absolute().parent
    while not p.exists() and p != p.parent:
        p = p.parent
    try:
        return int(os.pathconf(p, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):  # not a POSIX system, or not answerable
        return NAME_MAX_BYTES


def check_file_name(path: str, what: str) -> None:
    """Refuse, as one-line UsageError, a name for a file or directory we create that no file
    system or reader would take: empty, a component longer than the file system's NAME_MAX
    (ENAMETOOLONG), a path longer than PATH_MAX, or characters of
    :data:`REFUSED_NAME_CATEGORIES` (a newline, ...)."""
    import unicodedata

    if not path:
        raise UsageError(f"{what}: the file name is empty; give a file name")
    for ch in path:
        kind = REFUSED_NAME_CATEGORIES.get(unicodedata.category(ch))
        if kind:
            raise UsageError(f"{what} {path[:80]!r}: the name holds {kind} ({ascii(ch)}); "
                             "accepted: printable characters only")
    raw = os.fsencode(path)
    if len(raw) > PATH_MAX_BYTES:
        raise UsageError(f"{what} {path[:40]!r}...: the path is {len(raw)} bytes long; "
                         f"accepted: up to {PATH_MAX_BYTES}")
    limit = _name_max(path)
    for part in raw.split(b"/"):
        if len(part) > limit:
            name = os.fsdecode(part)
            raise UsageError(f"{what} {name[:40]!r}...: a name of {len(part)} bytes; accepted: "
                             f"up to {limit} bytes per file or directory name (the file "
                             "system's limit)")


# Characters a log's text may not put on the terminal as they are: control characters (an
# ESC starts the terminal's escape sequences: clear the screen, set the title, move the
# cursor; CR and LF fake lines), format characters (the bidirectional overrides U+202A-E,
# U+2066-9 reorder what is shown), surrogates (undecodable bytes) and line or paragraph
# separators. Printed escaped as Python writes them in a string: \x1b, \n, \u202e.
UNPRINTED_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Zl", "Zp"})


def escaped(text: object) -> str:
    """``text`` with the characters of :data:`UNPRINTED_CATEGORIES` written as escapes
    (``repr``'s, without the quotes); other text, accented and Greek letters included, as
    it is."""
    import unicodedata

    text = str(text)
    if all(unicodedata.category(ch) not in UNPRINTED_CATEGORIES for ch in text):
        return text
    return "".join(ascii(ch)[1:-1] if unicodedata.category(ch) in UNPRINTED_CATEGORIES
                   else ch for ch in text)
