"""The ``aircraft`` axis of a campaign: aircraft definitions (docs/aircraft.md) as
the wings of a sweep (pure: parsing, checks, identity).

``[axes] aircraft = ["bioflex_original", "my_aircraft.toml"]`` names shipped aircraft
(``bioflex_<variant>``, ``sgs_elastic``) or definition files with an ``[airframe]`` (a path
relative to the campaign file). Each is read and checked when the campaign is loaded, so a
bad file is one line (exit 2) before any case runs:

* with the ``gust`` metric, the aircraft must fly
  (:func:`~bioflex_jsb.definition.flying.flight_refusal`, the line of ``gust --aircraft``):
  the prototype's airframe with any wing, or another airframe on its own JSBSim aircraft
  (``runtime.jsbsim_aircraft.airframe_for``; a glider in its steady glide). A case whose
  speed is outside the aircraft's ``speed_range_m_s`` is a failed row saying so (one
  campaign may sweep aircraft of different speeds);
* with the linear metrics only (``flutter``, ``eigenvalues``, ``coefficients``) any airframe
  the linear analyses take (:meth:`Aircraft.linear_problem`): its wing's model carries the
  airframe's mass, inertia and derivatives.

A case of an aircraft hashes the definition file's content (SHA-256 of its bytes, as a
modes file's), so editing the file gives new case ids and ``--resume`` reruns them; the
wing's own modes file enters through the wing's identity as before.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

from bioflex_jsb.sweep.errors import CampaignError

AXIS_KEY = "aircraft"


def _fail(message: str):
    return CampaignError(message)


def aircraft_axis(values: list, base_dir: Path | None, metrics: tuple[str, ...]) -> list:
    """The :class:`~bioflex_jsb.definition.aircraft.Aircraft` of ``values`` (the axis's
    list), each checked for the campaign's ``metrics`` (module docstring)."""
    from bioflex_jsb.definition.aircraft import load_aircraft
    from bioflex_jsb.definition.flying import flight_refusal
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.runtime.jsbsim_aircraft import complete

    out = []
    names: set[str] = set()
    for i, v in enumerate(values):
        key = f"axes.{AXIS_KEY}[{i}]"
        if not isinstance(v, str):
            raise _fail(f"{key}: must be a shipped aircraft's name or a definition file "
                        f"(.toml), got {v!r}")
        source: str | Path = v
        if v.endswith(".toml"):
            path = Path(v)
            source = base_dir / path if base_dir is not None and not path.is_absolute() \
                else path
        try:
            # JSBSim's numbers where the file has none, its own checked against JSBSim
            aircraft = complete(load_aircraft(source))
            aircraft.variant()  # a wing the flight model takes (a beam wing is refused)
        except InputError as exc:  # the definition's one line, naming the field
            raise _fail(f"{key}: {exc}") from None
        if "gust" in metrics:
            try:
                problem = flight_refusal(aircraft)
            except InputError as exc:  # its planform, in one line
                problem = str(exc)
            if not problem:  # it must trim where its cases fly: found now, not per case
                from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

                try:
                    airframe_for(aircraft).trim(aircraft.airframe.cruise_speed_m_s)
                except InputError as exc:
                    problem = str(exc)
            if problem:
                raise _fail(f"{key}: {problem}; with metrics from flutter, eigenvalues, "
                            "coefficients only (no gust runs) its linear analyses sweep")
        else:
            problem = aircraft.linear_problem()
            if problem:
                raise _fail(f"{key}: {problem}")
        if aircraft.name in names:
            raise _fail(f"axes.{AXIS_KEY}: aircraft {aircraft.name!r} appears twice")
        names.add(aircraft.name)
        out.append(aircraft)
    return out


_DIGESTS: dict[str, str] = {}


def aircraft_identity(aircraft) -> dict[str, Any]:
    """What of ``aircraft`` enters its cases' ids: its name and the SHA-256 of its
    definition file's bytes (read once per process and file); for an aircraft on another
    airframe also that its default flutter range is derived from its wing (a stored case
    computed on the prototype's 5-40 m/s range keeps another id and is not reused)."""
    path = str(aircraft.definition.path)
    if path not in _DIGESTS:
        from bioflex_jsb.definition.loader import DefinitionError
        from bioflex_jsb.files import read_input_bytes
        from bioflex_jsb.tomlfile import MAX_TOML_BYTES

        data = read_input_bytes(path, "definition file", MAX_TOML_BYTES, DefinitionError)
        _DIGESTS[path] = hashlib.sha256(data).hexdigest()
    out = {"name": aircraft.name, "definition_sha256": _DIGESTS[path]}
    if aircraft.flight_problem() is not None:
        out["flutter_range"] = "derived"
    return out
