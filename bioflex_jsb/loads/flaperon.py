"""The flaperon's part of the section loads (force summation), of a run and of the LTI model.

A flaperon δf [rad] (both ailerons down together: :mod:`bioflex_jsb.aeroelasticity.flaperon`)
adds on strip k, per unit span, the flap lift Q c a₀ τ χ δf at the strip's aerodynamic
centre and the quarter-chord moment Q c² χ c_mδ δf (the co-simulation's strip terms), so at
a station y_s (the signs and frames of :mod:`bioflex_jsb.loads.model`)

    ΔV = Q δf Σ_out w l_δ,   ΔM = Q δf Σ_out w (y − y_s) l_δ,   ΔT = Q δf Σ_out w (l_δ e + m_δ)

over the force summation's cells outboard of the station (l_δ, m_δ the strip's lift and
moment per unit Q δf, e the aerodynamic centre ahead of the elastic axis), and the modes'
η̈ gains Q δf b_δf (the modal equation as flown: the inertial loads follow). The mode
displacement loads need nothing: they are the deflection's, which the flaperon drives.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from bioflex_jsb.aeroelasticity.control_surface import ControlSurface
from bioflex_jsb.aeroelasticity.flaperon import (
    FLAPERON_LIMIT_RAD,
    FlaperonDerivatives,
    flaperon_derivatives,
)
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.modal_coefficients import shifted, spanwise_geometry
from bioflex_jsb.loads.model import LoadsModel


@dataclass(frozen=True, eq=False)
class FlaperonLoads:
    """``fs_rows`` (3 s,) the force summation's rows (shear, bending, torque per station, the
    fs_matrix's row order) per unit Q δf [N/(Pa·rad), N·m/(Pa·rad)]; ``force`` (n,) b_δf,
    η̈ per unit Q δf [1/(Pa·s²·rad)]."""

    fs_rows: np.ndarray
    force: np.ndarray


def flaperon_loads(lm: LoadsModel, deriv: FlaperonDerivatives) -> FlaperonLoads:
    """The flaperon's rows of ``lm`` (its cells, stations and wing build; module
    docstring)."""
    build = lm.build
    planform, modes = build.planform, build.modes
    strips = shifted(spanwise_geometry(build.aero, planform, modes.x_elastic_frac,
                                       modes.stations_m), build.e_shift_frac * planform.chord_m)
    k = lm.cell_strips
    lift = deriv.strip_lift_m[k]
    torque = deriv.strip_lift_m[k] * strips.e_m[k] + deriv.strip_moment_m2[k]
    yc, wc, ys = lm.cells_m, lm.cell_widths_m, lm.stations_m
    out = yc[None, :] > ys[:, None]
    a_v = out * wc[None, :]
    a_m = a_v * (yc[None, :] - ys[:, None])
    rows = np.concatenate([a_v @ lift, a_m @ lift, a_v @ torque])
    return FlaperonLoads(rows, deriv.forcing_per_q(lm.matrices.mass_kg_m2))


def with_flaperon(lm: LoadsModel, deriv: FlaperonDerivatives) -> LoadsModel:
    """``lm`` carrying the flaperon's loads (``lm.flaperon``)."""
    return replace(lm, flaperon=flaperon_loads(lm, deriv))


def of_run(lm: LoadsModel, run) -> tuple[LoadsModel, np.ndarray | None]:
    """(``lm`` with the flaperon ``run`` flew, the deflection [rad] of each row; None: the
    run flew none). The deflection is the run's ``flaperon_rad``; a history that kept only
    the command (a log read back) gives it as the runtime does: ``ctrl_flaperon_rad`` one
    row later, within the travel (:mod:`bioflex_jsb.runtime.flaperon_step`). The surface is
    ``lm``'s, else the run's record (``meta["flaperon"]``); a run whose flaperon moved with
    neither is refused (InputError, one line): its loads would miss the flap's own."""
    channels = run.channels
    if "flaperon_rad" in channels:
        delta = np.asarray(run["flaperon_rad"], dtype=float)
    elif "ctrl_flaperon_rad" in channels:
        cmd = np.clip(np.asarray(run["ctrl_flaperon_rad"], dtype=float), -FLAPERON_LIMIT_RAD,
                      FLAPERON_LIMIT_RAD)
        delta = np.concatenate([[0.0], cmd[:-1]])
    else:
        return lm, None
    if lm.flaperon is not None:
        return lm, delta
    record = run.meta.get("flaperon")
    if not isinstance(record, dict) or not isinstance(record.get("surface"), dict):
        if not np.any(delta):
            return lm, None
        raise InputError("the run flew a flaperon whose surface it does not record "
                         "(meta['flaperon']): give the loads model its flaperon "
                         "(loads.flaperon.with_flaperon)")
    s = record["surface"]
    surface = ControlSurface(float(s["start_m"]), float(s["end_m"]),
                             float(s["hinge_chord_fraction"]), str(s["name"]))
    return with_flaperon(lm, flaperon_derivatives(lm.build, surface)), delta
