"""Gust loads of the elastic wing: section loads at monitoring stations by force summation
and by mode displacement, from a run or from the LTI model (docs/loads.md). Pure numerics:
no JSBSim, no files but the figures asked for; the flying is the caller's
(``api.section_loads``, ``bioflex-jsb loads``)."""

from __future__ import annotations

from bioflex_jsb.errors import InputError
from bioflex_jsb.loads.history import (
    SectionLoads,
    loads_metrics,
    section_loads_of_run,
    with_load_channels,
)
from bioflex_jsb.loads.model import (
    DEFAULT_STATION_FRACTIONS,
    METHODS,
    QUANTITIES,
    LoadsModel,
    build_loads_model,
)
from bioflex_jsb.parameters import constants as C

__all__ = ["DEFAULT_STATION_FRACTIONS", "METHODS", "QUANTITIES", "LoadsModel", "SectionLoads",
           "build_loads_model", "loads_metrics", "monitoring_stations", "section_loads",
           "section_loads_of_run", "with_load_channels"]

# Highest start altitude [m] at which a run's loads are taken at sea-level density without
# being told the density: 100 m of ISA lowers ρ by 1 % (and Q, the aerodynamic loads, alike).
SEA_LEVEL_ALTITUDE_MAX_M = 100.0


def monitoring_stations(aircraft=None) -> tuple[float, ...]:
    """The monitoring stations [fractions of the semispan, root 0] of ``aircraft``: its
    definition's ``[loads] stations`` (an :class:`~bioflex_jsb.definition.aircraft.Aircraft`
    or a :class:`~bioflex_jsb.definition.Definition`; the definition's default is
    :data:`DEFAULT_STATION_FRACTIONS`'s), or with none the default stations."""
    if aircraft is None:
        return tuple(DEFAULT_STATION_FRACTIONS)
    definition = getattr(aircraft, "definition", aircraft)
    return tuple(float(s) for s in definition.monitoring_stations)


def section_loads(build, run, stations=None, *, static: str | None = None,
                  density_kg_m3: float | None = None) -> SectionLoads:
    """Section loads of the nonlinear ``run`` (a TimeHistory of ``build``'s wing) at
    ``stations`` (fractions of the semispan; None: the wing's ``monitoring_stations``, else
    :data:`DEFAULT_STATION_FRACTIONS`) by both methods. ``static``: the 1 g part,
    ``elastic`` (default for the coupled and qsd models) or ``rigid`` (the rigid model's
    only choice). ``density_kg_m3`` [kg/m³]: default the density of the run's own loads
    (``meta["loads"]``, a run of ``run_gust(loads=...)``: JSBSim's at its trim), else sea
    level (refused for a run starting above SEA_LEVEL_ALTITUDE_MAX_M without it)."""
    if density_kg_m3 is None and run.meta.get("loads"):
        density_kg_m3 = float(run.meta["loads"]["density_kg_m3"])
    if density_kg_m3 is None:
        alt = run.channels.get("altitude_m")
        if alt is not None and len(alt) and float(alt[0]) > SEA_LEVEL_ALTITUDE_MAX_M:
            raise InputError(f"the run starts at {float(alt[0]):.0f} m; give density_kg_m3 "
                             "(sea level is assumed up to 100 m)")
        density_kg_m3 = C.SEA_LEVEL_DENSITY_KG_M3
    if static is None:
        static = "rigid" if run.model == "rigid" else "elastic"
    if run.model == "rigid" and static != "rigid":
        raise InputError("a rigid-wing run has no static deflection: static='rigid'")
    speed = float(run.meta.get("speed_m_s"))
    lm = build_loads_model(build, speed, stations, density_kg_m3=density_kg_m3, static=static)
    return section_loads_of_run(lm, run)
