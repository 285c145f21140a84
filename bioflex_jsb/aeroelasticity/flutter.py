"""Flutter of a clamped wing by either method, and the Goland benchmark.

The search, the result (:class:`~bioflex_jsb.flight_dynamics.flutter_engine.FlutterResult`)
and the mechanism rule are the one engine's (:mod:`bioflex_jsb.flight_dynamics.flutter_engine`);
this module picks the method (:mod:`~bioflex_jsb.aeroelasticity.pk` or
:mod:`~bioflex_jsb.aeroelasticity.state_space`, which import nothing from here).
"""

from __future__ import annotations

from bioflex_jsb.aeroelasticity import pk, state_space
from bioflex_jsb.aeroelasticity.clamped_wing import ClampedWingModel
from bioflex_jsb.aeroelasticity.strip_aero import divergence_speed_m_s
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.flutter_engine import MECHANISMS, METHODS, FlutterResult

__all__ = ["MECHANISMS", "FlutterResult", "clamped_flutter", "divergence_speed_m_s",
           "goland_flutter"]


def clamped_flutter(model: ClampedWingModel, *, method: str = "pk", aero: str = "unsteady",
                    density_kg_m3: float, structural_damping: float = 0.0,
                    speed_range_m_s: tuple[float, float], name: str = "") -> FlutterResult:
    """First instability of the clamped ``model`` in ``speed_range_m_s`` [m/s] by ``method``
    (``pk`` or ``state-space``) on ``aero`` strips (``unsteady``: Theodorsen's C(k) in p-k,
    Jones's finite-state form in state space; ``quasi-steady``: C = 1)."""
    kwargs = dict(density_kg_m3=density_kg_m3, aero=aero,
                  structural_damping=structural_damping, speed_range_m_s=speed_range_m_s,
                  name=name)
    if method == "pk":
        return pk.pk_flutter(model, **kwargs)
    if method == "state-space":
        return state_space.state_space_flutter(model, **kwargs)
    raise InputError(f"unknown method {method!r}; accepted: {', '.join(METHODS)}")


def goland_flutter(
    aero: str = "unsteady",
    lift_slope: str = "strip",
    method: str = "pk",
    structural_damping: float = 0.0,
    *,
    speed_range_m_s: tuple[float, float] = (20.0, 260.0),
    n_modes: int | None = None,
    inertia_about: str | None = None,
    density_kg_m3: float | None = None,
) -> FlutterResult:
    """Flutter of the clamped Goland wing (:mod:`bioflex_jsb.parameters.goland`).

    ``aero``: ``"unsteady"`` or ``"quasi-steady"``. ``lift_slope``: ``"strip"`` (2π on
    every strip) or ``"vlm"`` (the vortex lattice's spanwise lift slope). ``method``:
    ``"pk"`` or ``"state-space"``. ``structural_damping``: viscous modal damping ratio ζ [-]
    on every mode. ``inertia_about`` (default ``goland.DEFAULT_INERTIA_AXIS``): see
    :func:`~bioflex_jsb.aeroelasticity.clamped_wing.goland_sections`. ``density_kg_m3``
    defaults to ``goland.FLUTTER_DENSITY_KG_M3`` (sea level, the density at which the
    published flutter point is reproduced; the specification's 1.02 kg/m³ is
    ``goland.AIR_DENSITY_KG_M3``).
    """
    from bioflex_jsb.aeroelasticity.clamped_wing import (
        DEFAULT_N_MODES,
        clamped_wing_model,
        goland_sections,
    )
    from bioflex_jsb.parameters import goland as G

    axis = G.DEFAULT_INERTIA_AXIS if inertia_about is None else inertia_about
    rho = G.FLUTTER_DENSITY_KG_M3 if density_kg_m3 is None else float(density_kg_m3)
    model = clamped_wing_model(goland_sections(inertia_about=axis),
                               lift_slope=lift_slope, n_modes=n_modes or DEFAULT_N_MODES)
    return clamped_flutter(model, method=method, aero=aero, density_kg_m3=rho,
                           structural_damping=structural_damping,
                           speed_range_m_s=speed_range_m_s, name="goland")
