"""Every public function of ``bioflex_jsb.api`` names each of its parameters in its docstring,
with the unit of a physical one (as python-control's docstring test checks its API): a user
reading ``help(api.flutter)`` learns what ``density_kg_m3`` is and in what unit."""

from __future__ import annotations

import inspect
import re

import pytest

from bioflex_jsb import api

# A parameter's unit from its name's suffix (docs/conventions.md: the unit is in the name),
# longest suffix first, and how its docstring may write it.
UNIT_SUFFIXES = (
    ("_kg_m3", ("[kg/m^3]", "[kg/m³]")),
    ("_m_s", ("[m/s]",)),
    ("_rad", ("[rad]",)),
    ("_s", ("[s]",)),
    ("_m", ("[m]",)),
)
# Physical parameters whose name carries no unit, and what their docstring must say of it.
NAMED_UNITS = {
    "structural_damping": ("[-]", "ζ [-]"),  # a fraction of critical damping
    "stations": ("semispan",),  # fractions of the semispan
}
# How far after a mention of the parameter (``name`` or ``name=value``) its unit may stand
# [characters]: "``speed_m_s`` [m/s]", "``range_m_s`` (low, high) [m/s]".
UNIT_WINDOW = 80


def public_functions() -> list[tuple[str, object]]:
    return [(name, f) for name, f in inspect.getmembers(api, inspect.isfunction)
            if not name.startswith("_") and f.__module__ == api.__name__]


def units_of(parameter: str) -> tuple[str, ...] | None:
    """The accepted spellings of ``parameter``'s unit; None for one without a unit."""
    if parameter in NAMED_UNITS:
        return NAMED_UNITS[parameter]
    for suffix, units in UNIT_SUFFIXES:
        if parameter.endswith(suffix):
            return units
    return None


def problems(name: str, function) -> list[str]:
    doc = inspect.getdoc(function) or ""
    out = []
    for parameter in inspect.signature(function).parameters:
        mentions = [m.end() for m in re.finditer(rf"``{re.escape(parameter)}(=[^`]*)?``",
                                                 doc)]
        if not mentions:
            out.append(f"{name}({parameter}): not named in the docstring as ``{parameter}``")
            continue
        units = units_of(parameter)
        if units and not any(u in doc[end:end + UNIT_WINDOW] for end in mentions
                             for u in units):
            out.append(f"{name}({parameter}): no unit ({' or '.join(units)}) within "
                       f"{UNIT_WINDOW} characters of ``{parameter}``")
    return out


def test_the_api_has_the_functions_a_notebook_user_needs():
    names = {n for n, _ in public_functions()}
    assert {"fly_gust", "read_log", "linear_model", "modes", "flutter", "metrics",
            "section_loads", "plot_runs"} <= names, names


@pytest.mark.parametrize("name,function", public_functions(), ids=lambda x: x
                         if isinstance(x, str) else "")
def test_every_parameter_is_named_in_the_docstring_with_its_unit(name, function):
    bad = problems(name, function)
    assert not bad, "\n".join(bad)


def test_the_check_sees_an_unnamed_parameter_and_a_missing_unit():
    def f(wing, speed_m_s: float, density_kg_m3: float):
        """Fly ``wing`` at ``speed_m_s`` (no unit); the air's density."""

    assert problems("f", f) == [
        "f(speed_m_s): no unit ([m/s]) within 80 characters of ``speed_m_s``",
        "f(density_kg_m3): not named in the docstring as ``density_kg_m3``"]
