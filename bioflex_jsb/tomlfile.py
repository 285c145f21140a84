"""Reading the project's TOML input files (variants, campaigns, definitions) with one-line
errors.

The file is read by :func:`bioflex_jsb.files.read_input_text` (a regular file of at most
:data:`MAX_TOML_BYTES`, read with that bound, UTF-8); TOML nested deeper than the parser's
recursion allows (about 1000 levels; the project's files nest fewer than 5) is refused.
Each refusal is the caller's ``error`` class with one line naming the file.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

from bioflex_jsb.files import read_input_text

MAX_TOML_BYTES = 16 * 1024 * 1024  # campaign, variant and definition files: a few kB in practice


def loads_toml(text: str, name: str, error: type[Exception]) -> dict:
    """``tomllib.loads`` with one-line errors (syntax, nesting too deep) naming ``name``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{name} is not valid TOML: {' '.join(str(exc).split())}") from None
    except RecursionError:  # nesting deeper than the interpreter's recursion limit
        raise error(f"{name} nests arrays or tables too deep to parse (the project's "
                    "files nest fewer than 5 levels)") from None


def read_toml(path: str | Path, what: str, error: type[Exception],
              limit: int = MAX_TOML_BYTES) -> dict:
    """Parse the TOML file ``path``; any problem raises ``error`` with one line naming the
    file as a ``what`` (e.g. "variant file") and the reason."""
    text = read_input_text(path, what, limit, error)
    return loads_toml(text, f"{what} {str(path)!r}", error)
