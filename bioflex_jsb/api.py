"""Python API (first form; see README)."""
from __future__ import annotations


def fly_fig21(model: str = "coupled", duration_s: float = 3.0):
    from bioflex_jsb.drivers.gust import RunSetup, run_gust
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.generators import native_wing as J
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust

    setup = RunSetup(15.0, parse_gust("sharp:3"), duration_s)
    if model == "native":
        return run_gust(Airframe(aircraft=J.aircraft_name("optimised")), None, "native", setup)
    wing = build_wing(VARIANTS["optimised"]).model
    return run_gust(Airframe(), wing, model, setup)
