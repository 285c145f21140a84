"""The one base of the errors a user can fix.

:class:`InputError` is a problem with what was asked for (a speed outside the model's range,
a malformed wing or modal file, a gust that cannot be parsed, a trim that cannot exist): its
message is one line saying what is wrong and what is accepted, and the CLI reports it with
exit status 2. Any other exception is a bug and shows its traceback.
"""

from __future__ import annotations


class InputError(ValueError):
    """A validated-input problem; the message is one line (what is wrong, what is
    accepted)."""
