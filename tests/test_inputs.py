"""The one validator of inputs (bioflex_jsb.inputs): each field kind's accepted values and
its one-line message, and a table's problems as one line (pydantic's multi-line
ValidationError never reaches a user)."""

import math

import numpy as np
import pytest

from bioflex_jsb.errors import InputError
from bioflex_jsb.inputs import (
    Choice,
    Count,
    Flag,
    Invalid,
    Real,
    Table,
    Text,
    Triple,
    field_path,
    problem,
    read_table,
)


class BadFile(InputError):
    pass


@pytest.mark.parametrize("kind, value, message", [
    (Real("m", 0.05, 100.0), 6096.0, "6096 m is outside the valid range 0.05..100 m"),
    (Real("m", 0.05, 100.0), True, "must be a finite number in m, got True"),
    (Real("m", 0.05, 100.0), "15", "must be a finite number in m, got '15'"),
    (Real("m", 0.05, 100.0), math.nan, "must be a finite number in m, got nan"),
    (Real("s", hi=600.0, positive=True), 0.0, "must be > 0 s, got 0.0"),
    (Real("s", hi=600.0, positive=True), 601, "must be ≤ 600 s, got 601"),
    (Real("s", lo=0.0), -1, "must be ≥ 0 s, got -1"),
    (Count(4, 200), 3, "must be a whole number 4..200, got 3"),
    (Count(4, 200), 5.0, "must be a whole number 4..200, got 5.0"),
    (Count(1), False, "must be a whole number ≥ 1, got False"),
    (Choice(("strip", "vlm")), "panel", "must be one of strip, vlm, got 'panel'"),
    (Choice(("strip", "vlm")), 3, "must be one of strip, vlm, got 3"),
    (Text(), "  ", "must be a non-empty string"),
    (Text(), "a\nb", "holds a control character ('\\n'); accepted: printable text"),
    (Text(), "wing\u202egnp", "holds a bidirectional control character (U+202E)"),
    (Text(empty=True), 3, "must be a string"),
    (Flag(), 1, "must be true or false, got 1"),
    (Triple(Real("m", -1.0, 1.0)), [0.0, 1.0], "must be [x, y, z] in m, got [0.0, 1.0]"),
    (Triple(Real("m", -1.0, 1.0)), [0.0, 2.0, 0.0], "2 m is outside the valid range -1..1 m"),
])
def test_each_kind_says_what_is_wrong_and_what_is_accepted(kind, value, message):
    with pytest.raises(Invalid) as err:
        kind.check(value)
    assert message in err.value.text
    assert "\n" not in err.value.text


@pytest.mark.parametrize("kind, value, expected", [
    (Real("m", 0.05, 100.0), np.float64(1.5), 1.5),
    (Real("m", 0.05, 100.0), 2, 2.0),
    (Count(4, 200), np.int32(24), 24),
    (Flag(), False, False),
    (Triple(Real("m")), (1, 2, 3), (1.0, 2.0, 3.0)),
])
def test_kinds_accept_numpy_scalars_and_return_plain_python(kind, value, expected):
    got = kind.check(value)
    assert got == expected and type(got) is type(expected)


def test_a_missing_value_names_what_is_expected():
    with pytest.raises(Invalid, match=r"missing \(a number in m/s\)"):
        Real("m/s", 1.0, 100.0).read({}, "speed_m_s")
    assert Real("m/s", 1.0, 100.0).read({}, "speed_m_s", 15) == 15.0


class Sub(Table):
    x: Real("m", 0.0, 1.0).type()


class Run(Table):
    duration_s: Real("s", hi=600.0, positive=True).type() = 5.0
    aero: Choice(("unsteady", "quasi-steady")).type() = "unsteady"
    count: Count(1).type()
    sub: Sub | None = None
    subs: tuple[Sub, ...] = ()


@pytest.mark.parametrize("data, line", [
    ({"count": True}, "f.toml: run.count: must be a whole number ≥ 1, got True"),
    ({"count": 1, "duration_s": -1}, "f.toml: run.duration_s: must be > 0 s, got -1"),
    ({"count": 1, "zz": 1, "aa": 2},
     "f.toml: run: unknown key 'aa'; accepted: aero, count, duration_s, sub, subs "
     "(and 1 more problem)"),
    ({"count": 0, "duration_s": -1, "sub": {"x": 2}},
     "f.toml: run.duration_s: must be > 0 s, got -1 (and 2 more problems)"),
    ({}, "f.toml: run.count: missing (a whole number ≥ 1)"),
    ({"count": 1, "sub": {"x": 2}}, "f.toml: run.sub.x: 2 m is outside the valid range 0..1 m"),
    ({"count": 1, "sub": {"y": 2}},
     "f.toml: run.sub: unknown key 'y'; accepted: x (and 1 more problem)"),
    ({"count": 1, "subs": [{"x": 0.5}, {"x": "a"}]},
     "f.toml: run.subs[1].x: must be a finite number in m, got 'a'"),
    ({"count": 1, "sub": 3}, "f.toml: run.sub: must be a table"),
    ([1], "f.toml: run: must be a table"),
])
def test_a_table_problem_is_one_line_naming_the_file_table_and_key(data, line):
    with pytest.raises(BadFile) as err:
        read_table(Run, data, "f.toml", BadFile, "run")
    assert str(err.value) == line


def test_a_table_reads_into_a_frozen_record():
    run = read_table(Run, {"count": np.int64(2), "subs": [{"x": 1}]}, "f", BadFile)
    assert (run.count, run.duration_s, run.subs[0].x) == (2, 5.0, 1.0)
    with pytest.raises(Exception):  # noqa: B017 - pydantic's frozen-instance error
        run.count = 3


def test_one_line_even_from_a_multiline_text():
    assert str(problem(BadFile, "f", "a.b", "two\nlines")) == "f: a.b: two lines"
    assert field_path(["axes", "speeds_m_s", 0]) == "axes.speeds_m_s[0]"


# The modules that still write the "a number, not a bool" guard by hand (log readers and
# the controller's file: not yet on bioflex_jsb.inputs). The list may only shrink: a reader
# moved onto the kinds is taken off it, and no new module may join it.
HAND_WRITTEN_NUMBER_GUARDS = {
    "simulation/controller.py",
    "sinks/mcap/compare.py",
    "sinks/mcap/history.py",
    "sinks/mcap/reader.py",
}


def test_no_new_module_writes_its_own_number_guard():
    import re
    from pathlib import Path

    import bioflex_jsb

    root = Path(bioflex_jsb.__file__).parent
    guard = re.compile(r"isinstance\([^)]*\bbool\b")
    writers = {p.relative_to(root).as_posix() for p in root.rglob("*.py")
               if guard.search(p.read_text(encoding="utf-8"))}
    writers -= {"inputs.py", "values.py"}  # the one validator and its number rule
    assert writers <= HAND_WRITTEN_NUMBER_GUARDS, sorted(writers - HAND_WRITTEN_NUMBER_GUARDS)
    # a module taken off the list stays off it
    assert HAND_WRITTEN_NUMBER_GUARDS <= writers, sorted(HAND_WRITTEN_NUMBER_GUARDS - writers)
