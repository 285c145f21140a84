"""The one base of the errors a user can fix.

:class:`InputError` is a problem with what was asked for (a speed outside the model's range,
a malformed wing or modal file, a gust that cannot be parsed, a trim that cannot exist): its
message is one line saying what is wrong and what is accepted, and the CLI reports it with
exit status 2. Any other exception is a bug and shows its traceback.

:func:`plain_number` and :func:`plain_integer` are the one rule for a number a user types
(command-line options, gust specifications): plain ASCII decimals, finite.
:func:`unprintable` is the one rule for a name or description read from a file.
"""

from __future__ import annotations


class InputError(ValueError):
    """A validated-input problem; the message is one line (what is wrong, what is
    accepted)."""


# ---------------------------------------------------------------------------------------
# Numbers a user types (command-line options, gust specifications): plain ASCII decimals.
# ---------------------------------------------------------------------------------------
# Python's float() and int() also take "1_5" (15), full-width "１５" and Arabic-Indic "١٥"
# digits, surrounding blanks, "nan", "inf" and "infinity": none of them is a number a user
# means to type on a command line, and each has turned a typo into a silent value. A number
# here is an optional sign, ASCII digits with an optional point, and an optional exponent.
PLAIN_NUMBER_PATTERN = r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
PLAIN_INTEGER_PATTERN = r"[+-]?[0-9]+"
PLAIN_NUMBER_HELP = "plain ASCII decimal digits, e.g. 15, -0.5 or 1e-3"
PLAIN_INTEGER_HELP = "ASCII digits, e.g. 42"
# Longest number text read [characters]: int() of a 5000-digit text is refused by Python
# itself (ValueError, sys.int_info.default_max_str_digits = 4300); no option needs 100.
MAX_NUMBER_CHARS = 100


def _full(pattern: str):
    import re

    return re.compile(rf"\A{pattern}\Z")


_PLAIN_NUMBER = _full(PLAIN_NUMBER_PATTERN)
_PLAIN_INTEGER = _full(PLAIN_INTEGER_PATTERN)


def is_plain_number(text: str) -> bool:
    """Whether ``text`` is a plain ASCII decimal number (:data:`PLAIN_NUMBER_PATTERN`)."""
    return len(text) <= MAX_NUMBER_CHARS and _PLAIN_NUMBER.match(text) is not None


def plain_number(text: str, what: str) -> float:
    """``text`` as a finite float, or :class:`InputError` naming ``what`` and what is
    accepted (a plain decimal; 1e999 overflows to infinity and is refused too)."""
    if not is_plain_number(text):
        raise InputError(f"{what} must be a number ({PLAIN_NUMBER_HELP}), got {text!r}")
    value = float(text)
    if value != value or value in (float("inf"), float("-inf")):
        raise InputError(f"{what} {text!r} is beyond the range of a floating-point number; "
                         "give a finite number")
    return value


def plain_integer(text: str, what: str) -> int:
    """``text`` as an int, or :class:`InputError` (ASCII digits with an optional sign)."""
    if len(text) > MAX_NUMBER_CHARS or _PLAIN_INTEGER.match(text) is None:
        raise InputError(f"{what} must be a whole number ({PLAIN_INTEGER_HELP}), got {text!r}")
    return int(text)


# ---------------------------------------------------------------------------------------
# Names and descriptions read from files: printed and logged, so printable text only.
# ---------------------------------------------------------------------------------------
# The bidirectional embedding, override and isolate controls make a name display as another
# ("Trojan Source", CVE-2021-42574: U+202E shows "wing\u202egnp.evil" as "winglive.png");
# the Unicode categories: control characters (a newline splits a one-line message, an ESC
# drives the terminal) and line or paragraph separators.
BIDI_CONTROLS = frozenset("\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069")
_UNPRINTABLE_CATEGORIES = {"Cc": "a control character", "Zl": "a line separator",
                           "Zp": "a paragraph separator", "Cs": "a byte that is not text"}


def unprintable(text: str) -> str | None:
    """What the first character of ``text`` that a name may not hold is (e.g. "a
    bidirectional override (U+202E)"), or None when every character is printable text."""
    import unicodedata

    for ch in text:
        if ch in BIDI_CONTROLS:
            return f"a bidirectional control character (U+{ord(ch):04X})"
        kind = _UNPRINTABLE_CATEGORIES.get(unicodedata.category(ch))
        if kind:
            return f"{kind} ({ascii(ch)})"
    return None
