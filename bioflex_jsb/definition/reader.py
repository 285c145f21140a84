"""The field reader of definition files: one line naming the file and the field for every
problem (:class:`DefinitionError`, an :class:`~bioflex_jsb.errors.InputError`: exit 2)."""

from __future__ import annotations

from bioflex_jsb.errors import InputError, unprintable
from bioflex_jsb.values import is_finite_real, is_whole


class DefinitionError(InputError):
    """A definition file that cannot be used; the message names the file and the field."""


class Reader:
    def __init__(self, data: dict, where: str) -> None:
        self.data = data
        self.where = where

    def fail(self, field: str, text: str) -> DefinitionError:
        return DefinitionError(f"{self.where}: {field}: {text}")

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
        unknown = sorted(set(t) - set(allowed))
        if unknown:
            raise self.fail(f"{where}.{unknown[0]}", f"unknown field; accepted: "
                            f"{', '.join(allowed)}")

    def number(self, t: dict, where: str, key: str, lo: float, hi: float, unit: str,
               default: float | None = None, hint: str = "") -> float:
        v = t.get(key, default)
        if v is None:
            raise self.fail(f"{where}.{key}", f"missing (a number in {unit})")
        if not is_finite_real(v):
            raise self.fail(f"{where}.{key}", f"must be a finite number in {unit}, got {v!r}")
        if not lo <= v <= hi:
            raise self.fail(f"{where}.{key}", f"{v:g} {unit} is outside the valid range "
                            f"{lo:g}..{hi:g} {unit}{hint}")
        return float(v)

    def integer(self, t: dict, where: str, key: str, lo: int, hi: int, default: int) -> int:
        v = t.get(key, default)
        if not is_whole(v) or not lo <= v <= hi:
            raise self.fail(f"{where}.{key}", f"must be an integer {lo}..{hi}, got {v!r}")
        return int(v)

    def choice(self, t: dict, where: str, key: str, choices: tuple[str, ...],
               default: str | None) -> str:
        v = t.get(key, default)
        if v not in choices:
            raise self.fail(f"{where}.{key}", f"must be one of {', '.join(choices)}, got {v!r}")
        return str(v)

    def text(self, t: dict, where: str, key: str, default: str | None = None) -> str:
        """A string; names and descriptions are printed and logged, so printable text
        only (:func:`bioflex_jsb.errors.unprintable`: no newline, which would split a
        one-line message or a log field, no bidirectional override)."""
        v = t.get(key, default)
        field = f"{where}.{key}" if where else key
        if not isinstance(v, str) or (default is None and not v.strip()):
            raise self.fail(field, "must be a non-empty string")
        bad = unprintable(v)
        if bad:
            raise self.fail(field, f"holds {bad}; accepted: printable text")
        return v

    def boolean(self, t: dict, where: str, key: str, default: bool | None = None) -> bool:
        v = t.get(key, default)
        if not isinstance(v, bool):
            raise self.fail(f"{where}.{key}", f"must be true or false, got {v!r}")
        return v

    def vector(self, t: dict, where: str, key: str, lo: float, hi: float, unit: str,
               default: tuple[float, float, float] | None = None, hint: str = ""
               ) -> tuple[float, float, float]:
        """Three numbers [x, y, z] in ``unit``, each in lo..hi."""
        v = t.get(key, default)
        if not isinstance(v, list | tuple) or len(v) != 3:
            raise self.fail(f"{where}.{key}", f"must be [x, y, z] in {unit}, got {v!r}")
        out = [self.number({key: x}, where, key, lo, hi, unit, hint=hint) for x in v]
        return (out[0], out[1], out[2])
