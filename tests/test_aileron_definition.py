"""The ``[aileron]`` of a definition (docs/aircraft.md): read in fractions of the semispan or
in metres, absent is no surface, and every bad value is one line naming the field."""

from __future__ import annotations

import re

import pytest

from bioflex_jsb import api
from bioflex_jsb.definition import DefinitionError, load_definition
from bioflex_jsb.definition.loader import shipped_path

GOLAND_TEXT = shipped_path("goland").read_text(encoding="utf-8")
SEMISPAN_M = 6.096  # goland.toml's tip y_m


def _with_aileron(tmp_path, table: str):
    path = tmp_path / "wing.toml"
    path.write_text(GOLAND_TEXT + "\n[aileron]\n" + table + "\n", encoding="utf-8")
    return path


def test_no_aileron_is_none_and_the_shipped_case_reads():
    assert load_definition("goland").aileron is None
    s = api.load_definition("goland_aileron").aileron
    # goland_aileron.toml: span = [0.6, 1.0] of the 6.096 m semispan, hinge 0.8
    assert (s.start_m, s.end_m, s.hinge) == pytest.approx((0.6 * SEMISPAN_M, SEMISPAN_M, 0.8),
                                                          rel=1e-15)
    assert s.flap_chord_ratio == pytest.approx(0.2) and s.name == "aileron"


def test_span_in_fractions_equals_span_in_metres(tmp_path):
    a = load_definition(_with_aileron(tmp_path, "span = [0.5, 0.9]\nhinge = 0.75")).aileron
    b = load_definition(_with_aileron(tmp_path, f"y_m = [{0.5 * SEMISPAN_M!r}, "
                                                f"{0.9 * SEMISPAN_M!r}]\nhinge = 0.75")).aileron
    assert (a.start_m, a.end_m, a.hinge) == pytest.approx((b.start_m, b.end_m, b.hinge),
                                                          rel=1e-15)


BAD = [
    ("hinge = 0.75", "aileron", "give its span range once"),
    ("span = [0.5, 0.9]\ny_m = [1.0, 2.0]\nhinge = 0.75", "aileron", "not both"),
    ("span = [60, 95]\nhinge = 0.75", "aileron.span", "a fraction: 60 % is 0.6"),
    ("span = [0.9, 0.5]\nhinge = 0.75", "aileron.span", "start must be below end"),
    ("span = [0.5, 0.505]\nhinge = 0.75", "aileron.span", "is a tab"),
    ("span = [0.5]\nhinge = 0.75", "aileron.span", "must be [start, end]"),
    ("y_m = [3000.0, 6000.0]\nhinge = 0.75", "aileron.y_m", "outside the valid range"),
    ("span = [0.5, 0.9]", "aileron.hinge", "missing"),
    ("span = [0.5, 0.9]\nhinge = 25", "aileron.hinge", "a 25 %-chord aileron is 0.75"),
    ("span = [0.5, 0.9]\nhinge = 0.3", "aileron.hinge", "0.5..0.95"),
    ("span = [0.5, 0.9]\nhinge = 0.75\nchord = 0.2", "aileron",
     "unknown key 'chord'; accepted: "),
    ("span = [0.5, 0.9]\nhinge = nan", "aileron.hinge", "finite number"),
]


@pytest.mark.parametrize(("table", "field", "reason"), BAD)
def test_bad_aileron_is_one_line_naming_the_field(tmp_path, table, field, reason):
    with pytest.raises(DefinitionError, match=re.escape(field)) as info:
        load_definition(_with_aileron(tmp_path, table))
    assert reason in str(info.value) and "\n" not in str(info.value)
