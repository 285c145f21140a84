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


def positive_float(label: str, unit: str):
    """argparse type: a finite number > 0, e.g. ``positive_float('speed', 'm/s')``."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{label} must be a number in {unit}, got {text!r}"
            ) from None
        if not math.isfinite(value) or value <= 0.0:
            raise argparse.ArgumentTypeError(
                f"{label} must be a finite number > 0 {unit}, got {text!r}"
            )
        return value

    parse.__name__ = label
    return parse


def print_json(payload: Any) -> None:
    """Write ``payload`` as JSON to stdout (NaN is refused: it is not valid JSON)."""
    json.dump(payload, sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")
