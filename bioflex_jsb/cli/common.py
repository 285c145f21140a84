"""Shared CLI helpers: one-line errors, validated argument types, JSON output."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any, NoReturn

EXIT_USAGE = 2
EXIT_DIVERGED = 3


class UsageError(Exception):
    """A problem with what the user asked for; reported as one line, exit status 2."""


class OneLineParser(argparse.ArgumentParser):
    """ArgumentParser whose errors are a single line on stderr and exit status 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see --help)\n")


def finite_float(label: str, unit: str):
    """argparse type: any finite number, e.g. an altitude (may be negative)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{label} must be a number in {unit}, got {text!r}"
            ) from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(
                f"{label} must be a finite number in {unit}, got {text!r}"
            )
        return value

    parse.__name__ = label
    return parse


def positive_float(label: str, unit: str):
    """argparse type: a finite number > 0, e.g. ``positive_float('speed', 'm/s')``."""
    finite = finite_float(label, unit)

    def parse(text: str) -> float:
        try:
            value = finite(text)
        except argparse.ArgumentTypeError:
            if not _is_number(text):
                raise  # not a number at all: finite_float's message
            value = math.nan  # nan or inf
        if not value > 0.0:
            raise argparse.ArgumentTypeError(
                f"{label} must be a finite number > 0 {unit}, got {text!r}"
            )
        return value

    parse.__name__ = label
    return parse


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


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
    from bioflex_jsb.flight_dynamics.wing_model import DEFAULT_MASS_BASIS, MASS_BASES, VARIANTS

    parser.add_argument(
        "--wing", default=default, metavar="NAME|FILE.toml",
        help=f"wing variant: {', '.join(VARIANTS)}, or a variant file (docs/wing_variants.md); "
        f"default {default}",
    )
    parser.add_argument(
        "--mass-basis", choices=MASS_BASES, default=DEFAULT_MASS_BASIS,
        help="generalised masses of the whole wing against whole-span forces (consistent) or "
        "the half-wing m_i as Table B2 reads literally (paper: every H term doubled); "
        f"docs/decisions.md; default {DEFAULT_MASS_BASIS}",
    )


def wing_from_args(args: argparse.Namespace):
    """Build the wing named by --wing; any problem becomes a one-line UsageError."""
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.flight_dynamics.wing_model import VariantError, build_wing, resolve_variant

    try:
        return build_wing(resolve_variant(args.wing), mass_basis=args.mass_basis)
    except VariantError:
        raise
    except InputError as exc:  # modal-file and modal-data errors name their field
        raise UsageError(f"wing {args.wing!r}: {exc}") from None


LOG_DIR_ENV_VAR = "BIOFLEX_LOG_DIR"  # where runs write their logs by default (else ./logs)


def add_log_arguments(parser: argparse.ArgumentParser) -> None:
    """--out and --no-log: every run writes an MCAP log unless told not to."""
    parser.add_argument(
        "--out", metavar="RUN.mcap",
        help="MCAP log of every step (default: logs/<command>-<wing>-<UTC time>.mcap, the "
        f"directory from ${LOG_DIR_ENV_VAR} when set; docs/logging.md)")
    parser.add_argument("--no-log", action="store_true", help="write no MCAP log")


def log_path(args: argparse.Namespace, command: str, wing: str) -> str | None:
    """The log file a run writes: --out, else a new file in the log directory (created);
    None with --no-log. A directory that cannot be created is a UsageError."""
    import os
    import time
    from pathlib import Path

    if getattr(args, "no_log", False):
        if args.out:
            raise UsageError("--out and --no-log contradict each other; give one")
        return None
    if args.out:
        return args.out
    folder = Path(os.environ.get(LOG_DIR_ENV_VAR) or "logs")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError(f"cannot create the log directory {str(folder)!r}: {exc.strerror}; "
                         "give --out FILE.mcap or --no-log") from None
    stem = f"{command}-{Path(wing).stem}-{time.strftime('%Y%m%dT%H%M%SZ', time.gmtime())}"
    path, n = folder / f"{stem}.mcap", 1
    while path.exists():
        n += 1
        path = folder / f"{stem}-{n}.mcap"
    return str(path)


def check_output(path: str, force: bool, what: str, ours=None) -> None:
    """Refuse to replace an existing file at ``path`` (a user's file is never overwritten
    without ``--force``): a UsageError naming it, unless ``force`` or ``ours(path)`` says it
    is a file bioflex-jsb wrote itself of this kind (e.g. a PNG with our Software tag). A
    directory or a special file is refused even with ``--force``."""
    from pathlib import Path

    p = Path(path)
    if not p.exists() and not p.is_symlink():
        return
    if not p.is_file():
        raise UsageError(f"{what} {path!r} exists and is not a regular file; give another name")
    if force or (ours is not None and ours(p)):
        return
    raise UsageError(f"{what} {path!r} already exists; give another name or --force to "
                     "replace it")
