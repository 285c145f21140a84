"""The CLI's usage error: a problem with what the user asked for, reported as one line and
exit status 2 (``cli/__init__.py``). A leaf module: every CLI module may raise it."""

from __future__ import annotations


class UsageError(Exception):
    """A problem with what the user asked for; reported as one line, exit status 2."""
