"""The field reader of definition files: one line naming the file and the field for every
problem (:class:`DefinitionError`, an :class:`~bioflex_jsb.errors.InputError`: exit 2).

Each field is checked by a kind of :mod:`bioflex_jsb.inputs` (the one validator of inputs,
where the accepted values and the messages are written); this reader only names the field
(``table.key``) and the file."""

from __future__ import annotations

from bioflex_jsb.errors import InputError
from bioflex_jsb.inputs import (
    Choice,
    Count,
    Flag,
    Invalid,
    Kind,
    Real,
    Text,
    Triple,
    check_keys,
    problem,
)


class DefinitionError(InputError):
    """A definition file that cannot be used; the message names the file and the field."""


class Reader:
    def __init__(self, data: dict, where: str) -> None:
        self.data = data
        self.where = where

    def fail(self, field: str, text: str) -> DefinitionError:
        return problem(DefinitionError, self.where, field, text)

    def field(self, kind: Kind, t: dict, where: str, key: str, default=None):
        """``t[key]`` (or ``default``) checked by ``kind``; the problem names
        ``where.key``."""
        try:
            return kind.read(t, key, default)
        except Invalid as exc:
            raise self.fail(f"{where}.{key}" if where else key, exc.text) from None

    def table(self, key: str, allowed: tuple[str, ...] | None, required: bool = True
              ) -> dict:
        """The table ``key`` (its fields checked against ``allowed`` unless None)."""
        t = self.data.get(key)
        if t is None:
            if required:
                raise self.fail(f"[{key}]", "missing table")
            return {}
        if not isinstance(t, dict):
            raise self.fail(f"[{key}]", "must be a table")
        if allowed is not None:
            self.keys(t, key, allowed)
        return t

    def keys(self, t: dict, where: str, allowed: tuple[str, ...]) -> None:
        """An unknown key of table ``where``: ``<file>: <where>: unknown key 'X'; accepted:
        …`` (the one wording of :func:`bioflex_jsb.inputs.unknown_key_text`)."""
        try:
            check_keys(t, allowed)
        except Invalid as exc:
            raise self.fail(where, exc.text) from None

    def number(self, t: dict, where: str, key: str, lo: float, hi: float, unit: str,
               default: float | None = None, hint: str = "") -> float:
        return self.field(Real(unit, lo, hi, hint=hint), t, where, key, default)

    def integer(self, t: dict, where: str, key: str, lo: int, hi: int, default: int) -> int:
        return self.field(Count(lo, hi), t, where, key, default)

    def choice(self, t: dict, where: str, key: str, choices: tuple[str, ...],
               default: str | None) -> str:
        return self.field(Choice(choices), t, where, key, default)

    def text(self, t: dict, where: str, key: str, default: str | None = None) -> str:
        """A string; names and descriptions are printed and logged, so printable text
        only (:class:`bioflex_jsb.inputs.Text`); empty only where a default is given."""
        return self.field(Text(empty=default is not None), t, where, key, default)

    def boolean(self, t: dict, where: str, key: str, default: bool | None = None) -> bool:
        return self.field(Flag(), t, where, key, default)

    def vector(self, t: dict, where: str, key: str, lo: float, hi: float, unit: str,
               default: tuple[float, float, float] | None = None, hint: str = ""
               ) -> tuple[float, float, float]:
        """Three numbers [x, y, z] in ``unit``, each in lo..hi."""
        return self.field(Triple(Real(unit, lo, hi, hint=hint)), t, where, key, default)
