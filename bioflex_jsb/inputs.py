"""The one validator of inputs: definitions, wing variants, modal files, campaigns and API
arguments are checked here, with one message per problem.

A *field kind* (:class:`Real`, :class:`Count`, :class:`Choice`, :class:`Text`,
:class:`Flag`, :class:`Triple`) declares once what a field accepts (type, range, unit) and
the one-line text that says what is wrong and what is accepted. A reader uses a kind on one
value (:meth:`Kind.check`, raising :class:`Invalid` with that text), or declares a whole
table as a :class:`Table` (a frozen pydantic model whose fields are kinds, :meth:`Kind.type`)
and reads it with :func:`read_table`. Either way the problem reaches the user as the
reader's own :class:`~bioflex_jsb.errors.InputError` through :func:`problem`, the one place
that writes the line "<where>: <field>: <what is wrong; what is accepted>" (exit status 2).
Pydantic's multi-line ``ValidationError`` never leaves this module.

The number rules are :mod:`bioflex_jsb.values`' (a bool is never a number; numpy scalars
count; strings never do); the text rule is :func:`bioflex_jsb.errors.unprintable`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Annotated, Any, ClassVar, TypeVar

import numpy as np
from pydantic import BaseModel, ConfigDict, PlainValidator, ValidationError
from pydantic_core import PydanticCustomError

from bioflex_jsb.errors import InputError, unprintable
from bioflex_jsb.values import is_finite_real, is_real, is_whole

# The error type of a kind's problem inside pydantic (its text is the kind's message).
_KIND_ERROR = "bioflex_input"


class Invalid(ValueError):
    """One field's problem: ``text`` says what is wrong and what is accepted (the field and
    the file are added by :func:`problem`)."""

    def __init__(self, text: str) -> None:
        super().__init__(text)
        self.text = text


def problem(error: type[InputError], where: str, field: str, text: str) -> InputError:
    """The one line of every input problem: ``<where>: <field>: <text>`` (``where`` the
    file or the call, ``field`` its table.key; either may be empty), as ``error``."""
    parts = [p for p in (where, field) if p]
    return error(": ".join([*parts, " ".join(text.split())]))


def argument(kind: Kind, value: Any, name: str) -> Any:
    """An API argument ``name`` checked by ``kind``: the value, or one-line
    :class:`~bioflex_jsb.errors.InputError` ``<name>: <what is wrong; what is accepted>``."""
    try:
        return kind.check(value)
    except Invalid as exc:
        raise problem(InputError, "", name, exc.text) from None


def field_path(loc: Sequence[str | int]) -> str:
    """A location as the files write it: ``table.key[index].key``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out


def _g(x: float) -> str:
    return f"{x:g}"


def _in(unit: str) -> str:
    """" in <unit>" (nothing for a dimensionless number without a unit name)."""
    return f" in {unit}" if unit else ""


def _u(unit: str) -> str:
    return f" {unit}" if unit else ""


class Kind:
    """What one field accepts; subclasses give :meth:`check` and :meth:`missing_text`."""

    python_type: ClassVar[Any] = Any

    def check(self, value: Any) -> Any:  # pragma: no cover - each kind gives its own
        raise NotImplementedError

    def missing_text(self) -> str:
        return "missing"

    def read(self, table: Mapping, key: str, default: Any = None) -> Any:
        """``table[key]`` (or ``default``) checked; :class:`Invalid` if missing or bad."""
        value = table.get(key, default)
        if value is None:
            raise Invalid(self.missing_text())
        return self.check(value)

    def type(self) -> Any:
        """This kind as a pydantic field type (for a :class:`Table`)."""
        def validate(value: Any) -> Any:
            try:
                return self.check(value)
            except Invalid as exc:
                raise PydanticCustomError(_KIND_ERROR, "{text}", {"text": exc.text}) from None

        return Annotated[self.python_type, PlainValidator(validate), self]


@dataclass(frozen=True)
class Real(Kind):
    """A finite real number [unit] in lo..hi; ``positive``: above 0 (the lower bound 0
    excluded); ``below``: under hi (the upper bound excluded). ``hint`` follows a range
    message (why the range, what a value outside probably is). ``unit`` "" for a pure
    number."""

    unit: str
    lo: float = -math.inf
    hi: float = math.inf
    positive: bool = False
    hint: str = ""
    below: bool = False
    python_type: ClassVar[Any] = float

    def missing_text(self) -> str:
        return f"missing (a number{_in(self.unit)})"

    def check(self, value: Any) -> float:
        u = _u(self.unit)
        if not is_finite_real(value):
            raise Invalid(f"must be a finite number{_in(self.unit)}, got {value!r}")
        x = float(value)
        if self.positive and x <= 0.0:
            raise Invalid(f"must be > 0{u}, got {value!r}{self.hint}")
        if self.lo > -math.inf and self.hi < math.inf and not self.positive:
            if not self.lo <= x <= self.hi or (self.below and x == self.hi):
                span = (f"[{_g(self.lo)}, {_g(self.hi)})" if self.below
                        else f"{_g(self.lo)}..{_g(self.hi)}")
                raise Invalid(f"{x:g}{u} is outside the valid range {span}{u}{self.hint}")
            return x
        if x < self.lo:
            raise Invalid(f"must be ≥ {_g(self.lo)}{u}, got {value!r}{self.hint}")
        if x > self.hi or (self.below and x == self.hi):
            op = "<" if self.below else "≤"
            raise Invalid(f"must be {op} {_g(self.hi)}{u}, got {value!r}{self.hint}")
        return x


@dataclass(frozen=True)
class Count(Kind):
    """A whole number (int or numpy integer; not a bool, not 3.0) in lo..hi."""

    lo: int = 0
    hi: int | None = None
    python_type: ClassVar[Any] = int

    def accepted(self) -> str:
        return f"≥ {self.lo}" if self.hi is None else f"{self.lo}..{self.hi}"

    def missing_text(self) -> str:
        return f"missing (a whole number {self.accepted()})"

    def check(self, value: Any) -> int:
        if not is_whole(value) or value < self.lo or (self.hi is not None and value > self.hi):
            raise Invalid(f"must be a whole number {self.accepted()}, got {value!r}")
        return int(value)


@dataclass(frozen=True)
class Choice(Kind):
    """One of a fixed set of strings; ``noun`` names what they are ("unknown mass basis
    'x'; accepted: ...") where a bare list would not say it."""

    choices: tuple[str, ...]
    noun: str = ""
    python_type: ClassVar[Any] = str

    def missing_text(self) -> str:
        return f"missing (one of {', '.join(self.choices)})"

    def check(self, value: Any) -> str:
        if not isinstance(value, str) or value not in self.choices:
            if self.noun:
                raise Invalid(f"unknown {self.noun} {value!r}; accepted: "
                              f"{', '.join(self.choices)}")
            raise Invalid(f"must be one of {', '.join(self.choices)}, got {value!r}")
        return value


@dataclass(frozen=True)
class Text(Kind):
    """A string that is printed and logged (a name, a description): printable text only
    (no newline, which would split a one-line message or a log field; no bidirectional
    override). ``empty``: whether "" (or blanks) is accepted."""

    empty: bool = False
    python_type: ClassVar[Any] = str

    def missing_text(self) -> str:
        return "missing (a string)"

    def check(self, value: Any) -> str:
        if not isinstance(value, str) or (not self.empty and not value.strip()):
            raise Invalid("must be a string" if self.empty else "must be a non-empty string")
        bad = unprintable(value)
        if bad:
            raise Invalid(f"holds {bad}; accepted: printable text")
        return value


@dataclass(frozen=True)
class Flag(Kind):
    """true or false (a bool only: 1 and "yes" are refused)."""

    python_type: ClassVar[Any] = bool

    def missing_text(self) -> str:
        return "missing (true or false)"

    def check(self, value: Any) -> bool:
        if not isinstance(value, bool):
            raise Invalid(f"must be true or false, got {value!r}")
        return value


@dataclass(frozen=True)
class Triple(Kind):
    """Three numbers [x, y, z], each a :class:`Real` ``element``."""

    element: Real
    python_type: ClassVar[Any] = tuple[float, float, float]

    def missing_text(self) -> str:
        return f"missing ([x, y, z] in {self.element.unit})"

    def check(self, value: Any) -> tuple[float, float, float]:
        if not isinstance(value, list | tuple) or len(value) != 3:
            raise Invalid(f"must be [x, y, z] in {self.element.unit}, got {value!r}")
        x, y, z = (self.element.check(v) for v in value)
        return (x, y, z)


@dataclass(frozen=True)
class Interval(Kind):
    """Two numbers [low, high] [unit] with lo < low < high <= hi (a speed range: its low end
    above ``lo``, 0 by default; ``from_lo``: lo <= low); ``hint`` says where it comes from.
    A list or a tuple (an API argument: any sequence but a string, made a tuple by the
    caller)."""

    unit: str
    lo: float = 0.0
    hi: float = math.inf
    hint: str = ""
    from_lo: bool = False
    python_type: ClassVar[Any] = tuple[float, float]

    def accepted(self) -> str:
        high = f" <= {_g(self.hi)} {self.unit}" if self.hi < math.inf else ""
        op = "<=" if self.from_lo else "<"
        return f"[low, high] {self.unit} with {_g(self.lo)} {op} low < high{high}{self.hint}"

    def missing_text(self) -> str:
        return f"missing ({self.accepted()})"

    def check(self, value: Any) -> tuple[float, float]:
        ok = (isinstance(value, list | tuple) and len(value) == 2
              and all(is_finite_real(x) for x in value)
              and (self.lo <= value[0] if self.from_lo else self.lo < value[0])
              and value[0] < value[1] <= self.hi)
        if not ok:
            raise Invalid(f"must be {self.accepted()}, got {value!r}")
        return (float(value[0]), float(value[1]))


@dataclass(frozen=True)
class Matrix(Kind):
    """A matrix of numbers: a list of rows of equal length (a file's table; a row may be
    empty) or a numeric array (an .npz file's), as a float array (a list: 2-D; an array
    keeps its shape, which the reader fits). Finiteness is the reader's to check, with the
    matrix's name."""

    python_type: ClassVar[Any] = Any

    def missing_text(self) -> str:
        return "missing (a list of rows of numbers)"

    def check(self, value: Any) -> Any:
        if isinstance(value, np.ndarray):
            if value.dtype.kind not in "fiu":
                raise Invalid(f"must be a matrix of numbers, got an array of {value.dtype}")
            return value.astype(float)
        if not (isinstance(value, list) and all(isinstance(r, list) for r in value)
                and all(is_real(v) for r in value for v in r)):
            raise Invalid(f"must be a list of rows of numbers, got {value!r}")
        if len({len(r) for r in value}) > 1:
            raise Invalid(f"its rows differ in length ({', '.join(str(len(r)) for r in value)} "
                          "numbers)")
        return np.array(value, dtype=float).reshape(len(value), -1 if value else 0)


@dataclass(frozen=True)
class Names(Kind):
    """A non-empty list of non-empty names, each once (a list or a tuple; a string is not
    a list of names), as a tuple."""

    python_type: ClassVar[Any] = tuple[str, ...]

    def missing_text(self) -> str:
        return "missing (a list of names)"

    def check(self, value: Any) -> tuple[str, ...]:
        if isinstance(value, str) or not isinstance(value, list | tuple):
            raise Invalid(f"must be a list of names, got {value!r}")
        if not value:
            raise Invalid("none given; accepted: a list of names")
        bad = [n for n in value if not isinstance(n, str) or not n]
        if bad:
            raise Invalid(f"must be non-empty names, got {bad[0]!r}")
        dup = sorted({n for n in value if value.count(n) > 1})
        if dup:
            raise Invalid(f"name {dup[0]!r} more than once")
        return tuple(value)


# Kinds many inputs share, declared once.
CHORD_FRACTION = Real("chord fraction", 0.0, 1.0)  # a position along the chord, LE 0, TE 1


def unknown_keys(table: Mapping, accepted: Sequence[str]) -> str | None:
    """The first (sorted) key of ``table`` that is not ``accepted``, or None."""
    unknown = sorted(str(k) for k in set(table) - set(accepted))
    return unknown[0] if unknown else None


def unknown_key_text(key: str, accepted: Sequence[str]) -> str:
    """The one wording of an unknown key, in every reader: ``unknown key 'X'; accepted: a,
    b, c`` (the accepted keys sorted; the line's field is the table that holds the key)."""
    return f"unknown key {str(key)!r}; accepted: {', '.join(sorted(accepted))}"


def keys_text(table: Mapping, accepted: Sequence[str]) -> str | None:
    """The problem of ``table``'s unknown keys, or None: the first (sorted) in the one
    wording (:func:`unknown_key_text`), the others counted (:func:`more_text`)."""
    unknown = sorted(str(k) for k in set(table) - set(accepted))
    if not unknown:
        return None
    return unknown_key_text(unknown[0], accepted) + more_text(len(unknown) - 1)


def check_keys(table: Mapping, accepted: Sequence[str]) -> None:
    """:class:`Invalid` (:func:`keys_text`) if ``table`` has a key that is not
    ``accepted``."""
    text = keys_text(table, accepted)
    if text is not None:
        raise Invalid(text)


def more_text(n: int) -> str:
    """What follows the first problem of a reader that finds several at once (a
    :class:`Table`): `` (and N more problems)``; nothing for none. The first problem is
    reported in full and the others counted, so that the message stays one line."""
    if n <= 0:
        return ""
    return f" (and {n} more problem{'s' if n > 1 else ''})"


# ---------------------------------------------------------------------------------------
# Tables: frozen pydantic models whose fields are kinds
# ---------------------------------------------------------------------------------------
class Table(BaseModel):
    """A table of an input file (or a set of API arguments): its fields are kinds
    (``field: Real("m", 0.0, 1.0).type()``); unknown keys are refused. Read it with
    :func:`read_table`, never with ``model_validate`` (whose errors are multi-line)."""

    # defer_build: the schema is built at the first read, not at import (the CLI's --help
    # imports the readers and reads nothing)
    model_config = ConfigDict(extra="forbid", frozen=True, defer_build=True)


T = TypeVar("T", bound=Table)


def accepted_keys(model: type[Table]) -> tuple[str, ...]:
    """The keys a table accepts (its fields' names, aliases where given)."""
    return tuple(f.alias or name for name, f in model.model_fields.items())


def _kind_of(model: type[BaseModel], loc: Sequence[str | int]) -> Kind | None:
    """The kind declared for the field at ``loc`` (nested tables followed), or None."""
    current: Any = model
    kind = None
    for part in loc:
        if isinstance(part, int) or not (isinstance(current, type)
                                          and issubclass(current, BaseModel)):
            continue
        info = current.model_fields.get(part)
        if info is None:
            return None
        kind = next((m for m in info.metadata if isinstance(m, Kind)), None)
        current = info.annotation
    return kind


def _nested_model(model: type[BaseModel], loc: Sequence[str | int]) -> type[BaseModel]:
    """The table type that holds the key at the end of ``loc``."""
    current: type[BaseModel] = model
    for part in loc[:-1]:
        if isinstance(part, int):
            continue
        info = current.model_fields.get(part)
        ann = getattr(info, "annotation", None)
        args = getattr(ann, "__args__", ())
        found = next((a for a in (ann, *args) if isinstance(a, type)
                      and issubclass(a, BaseModel)), None)
        if found is None:
            break
        current = found
    return current


def read_table(model: type[T], data: Any, where: str, error: type[InputError],
                         table: str = "") -> T:
    """``data`` checked as ``model``; the first problem raises ``error`` with one line
    (:func:`problem`): an unknown key first (the first in sorted order, with the accepted
    keys), then the first field in declaration order; the others pydantic found are
    counted after it (:func:`more_text`)."""
    prefix = [table] if table else []
    if not isinstance(data, Mapping):
        raise problem(error, where, table, "must be a table")
    try:
        return model.model_validate(dict(data))
    except ValidationError as exc:
        errors = exc.errors(include_url=False, include_context=True, include_input=True)
    extras = sorted((e for e in errors if e["type"] == "extra_forbidden"),
                    key=lambda e: [str(p) for p in e["loc"]])
    first = extras[0] if extras else errors[0]
    field, text = _error_line(model, first, prefix)
    raise problem(error, where, field, text + more_text(len(errors) - 1))


def _error_line(model: type[BaseModel], error: Any, prefix: list[str]) -> tuple[str, str]:
    """One pydantic error as (field, text) in the kinds' wording."""
    loc = list(error["loc"])
    field = field_path([*prefix, *loc])
    if error["type"] == "extra_forbidden":
        keys = accepted_keys(_nested_model(model, loc))
        return field_path([*prefix, *loc[:-1]]), unknown_key_text(str(loc[-1]), keys)
    if error["type"] == _KIND_ERROR:
        return field, error["ctx"]["text"]
    kind = _kind_of(model, loc)
    if error["type"] == "missing":
        return field, kind.missing_text() if kind else "missing"
    if error["type"] in ("model_type", "model_attributes_type", "dict_type"):
        return field, "must be a table"
    # any other type check of pydantic's (a tuple's length, a list): its message, one line
    return field, f"{error['msg']}, got {error.get('input')!r}"
