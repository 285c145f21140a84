"""A controller's flaperon in the coupled step (:class:`~bioflex_jsb.runtime.coupled_step.
CoupledStep`): the wing's ailerons deflected together (sign and section data:
:mod:`bioflex_jsb.aeroelasticity.flaperon`).

JSBSim's tables have no symmetric aileron, so JSBSim never sees the flaperon's deflection:
its loads reach the airframe through the external reactions the wing's loads already use
(``modal-lift``, ``modal-drag``, ``modal-pitch``), added to the modes' there, and its strip
loads force the symmetric modes (:meth:`~bioflex_jsb.simulation.modal_wing.ModalWing.
set_flaperon`). Nothing is counted twice: ``fcs/aileron-cmd-norm`` (the antisymmetric
aileron, JSBSim's C_lδa) is not written, and the flaperon's lift is on no table.

**Timing**, as the elevator's (:mod:`bioflex_jsb.simulation.controller`, "Timing"): the
command δf_k of the row of t_k is clipped to the travel and

* its lift ΔL = Q_k S C_Lδf δf_k (up), induced drag 2 k C_L0 ΔL and moment Q_k S c̄ C_mδf
  δf_k (nose up, about the CG) join the reactions written before JSBSim's step k: they act
  over step k+1 with the forces of x_{k+1}, as a surface JSBSim moves in step k would;
* the wing's next step (η_{k+1} → η_{k+2}) holds it in the modes' forcing.

The row of t_k logs the command (``ctrl_flaperon_rad``), the deflection whose loads acted
over step k (``flaperon_rad``: δf_{k−1} clipped, as ``elevator_rad`` is JSBSim's surface at
x_k), and in ``lift_n``, ``drag_n``, ``pitch_moment_n_m`` the reactions as written, the
flaperon's included.

**The step.** Both steps fly it: the readable Python step (:func:`apply_flaperon`, the
reference) and the compiled kernel (:func:`~bioflex_jsb.simulation.step_kernel.step_kernel`
with its flaperon block, :func:`pack_flaperon`: the held deflection's forcing of the modes
and ``flaperon_rad``; then :func:`~bioflex_jsb.simulation.step_kernel.flaperon_loads` after
the controller, :func:`compiled_flaperon_control`: the loads of the new command into the
row and the reactions), the half wing's and, through it, both halves' (the full-span
kernel steps the half wing with the half wing's kernel). ``tests/test_flaperon.py`` holds
the two to 1e-9 of each channel's range. The compiled step holds δf in its parameter array
(:attr:`FlaperonLoads.applied_rad` and the wing's ``flaperon_rad`` are the Python step's).
"""

from __future__ import annotations

import math

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.aeroelasticity.flaperon import (
    FLAPERON_LIMIT_RAD,
    FlaperonDerivatives,
    flaperon_derivatives,
)
from bioflex_jsb.errors import InputError
from bioflex_jsb.runtime.control_surfaces import Command
from bioflex_jsb.simulation import step_kernel as K


class FlaperonLoads:
    """The flaperon of one step (module docstring): ``deriv`` its derivatives, ``k_induced2``
    the induced-drag factor 2 k C_L0 of its lift, ``area_m2``, ``chord_m`` S and c̄."""

    def __init__(self, deriv: FlaperonDerivatives, k_induced2: float) -> None:
        self.deriv = deriv
        self.k_induced2 = float(k_induced2)
        self.command_rad = 0.0  # the last command, clipped: applied from the next step
        self.applied_rad = 0.0  # the deflection of the step being flown

    def set_command(self, delta_rad: float) -> None:
        """The controller's δf [rad] over the trim (0), clipped to ±FLAPERON_LIMIT_RAD."""
        self.command_rad = max(-FLAPERON_LIMIT_RAD, min(FLAPERON_LIMIT_RAD, float(delta_rad)))

    def command(self) -> Command:
        """The controller's writer of the flaperon (a :class:`Command` of unit map)."""
        return Command(0.0, 0.0, 1.0, 1.0, (self.set_command,), (0.0,))

    def loads(self, q_pa: float, delta_rad: float) -> tuple[float, float, float]:
        """(lift [N, up], drag [N, aft], pitching moment [N·m, nose up]) of δf at Q."""
        d = self.deriv
        lift = q_pa * d.area_m2 * d.c_l_per_rad * delta_rad
        return (lift, self.k_induced2 * lift,
                q_pa * d.area_m2 * d.chord_m * d.c_m_per_rad * delta_rad)


def flaperon_for(step, build, aileron) -> FlaperonLoads:
    """The flaperon of ``step`` (a CoupledStep on the Python modal wing) with the wing's
    ``build`` and ``aileron`` (None: the prototype variant's shipped definition's), its
    modes forced (:meth:`~bioflex_jsb.simulation.modal_wing.ModalWing.set_flaperon`); one
    line (InputError) for what cannot carry one."""
    if step.native or build is None:
        raise InputError("a flaperon command needs the Python modal wing and its build (its "
                         "strips): fly the coupled, qsd or rigid model of a built wing")
    if not hasattr(step.wing, "set_flaperon"):
        raise InputError("a flaperon command is for the quasi-steady strips (aero="
                         "'quasi-steady'); the unsteady wing has no flap terms")
    if aileron is None:
        from bioflex_jsb.simulation.full_span import prototype_aileron

        aileron = prototype_aileron(build.variant.name)
    deriv = flaperon_derivatives(build, aileron)
    step.wing.set_flaperon(deriv.forcing_per_q(step.wing.matrices.mass_kg_m2))
    cl = step.reference.cl_trim
    k2 = 2.0 * step.airframe_data.aero.k_induced * cl
    if not math.isfinite(k2):
        raise InputError("the trim's lift coefficient is not finite")
    return FlaperonLoads(deriv, k2)


def apply_flaperon(step, flow, loads, values: tuple[float, ...]) -> tuple[float, ...]:
    """After the controller of step k (module docstring, "Timing"): the reactions rewritten
    with the flaperon's loads of its new command added to the wing's ``loads`` in ``flow``
    (lift and drag turned from wind to body axes with α_k, as the wing's), the row
    ``values`` with them, and the command held for the wing's next step."""
    fl = step.flaperon
    delta = fl.command_rad
    dl, dd, dm = fl.loads(flow.dynamic_pressure_pa, delta)
    lift, drag, moment = loads.lift_n + dl, loads.drag_n + dd, loads.pitch_moment_n_m + dm
    ca, sa = math.cos(flow.alpha_rad), math.sin(flow.alpha_rad)
    step._write_reactions(lift * ca + drag * sa, drag * ca - lift * sa, moment)
    row = list(values)
    names = step.names
    row[names.index("lift_n")] = lift
    row[names.index("drag_n")] = drag
    row[names.index("pitch_moment_n_m")] = moment
    fl.applied_rad = delta
    step.wing.flaperon_rad = delta
    return tuple(row)


def pack_flaperon(step, views) -> None:
    """Fill the compiled kernel's flaperon blocks (``views``: the half wing's parameter
    array by :func:`~bioflex_jsb.simulation.step_kernel.layout` block) of ``step``, whose
    row (``step.names``) is complete: the forcing b_δf of the quasi-static wing, the
    flaperon's constants and the row's columns (step_kernel.N_FLAP); the step column
    Ψ_r b_δf follows each reference (CoupledStep._load_reference)."""
    fl, names = step.flaperon, step.names
    views["flap_force"][:] = step.wing._flap_force
    d = fl.deriv
    block = views["flap"]
    block[K.FLAP_HELD] = 0.0  # the trim's: no deflection before the first command
    block[K.FLAP_AREA], block[K.FLAP_CL], block[K.FLAP_K2] = (d.area_m2, d.c_l_per_rad,
                                                              fl.k_induced2)
    block[K.FLAP_CHORD], block[K.FLAP_CM] = d.chord_m, d.c_m_per_rad
    block[K.FLAP_COL] = names.index("flaperon_rad") + 1
    for i, name in enumerate(("lift_n", "drag_n", "pitch_moment_n_m")):
        block[K.FLAP_LOAD_COLS + i] = names.index(name)
    block[K.FLAP_LBF], block[K.FLAP_LBF_FT] = U.LBF_PER_N, U.LBF_FT_PER_N_M


def compiled_flaperon_control(step, control):
    """The compiled step's controller with the flaperon (module docstring, "Timing"):
    ``control(table, k)`` (the controller, its commands written, the flaperon's
    :meth:`FlaperonLoads.set_command` among them), then
    :func:`~bioflex_jsb.simulation.step_kernel.flaperon_loads` with the command and the
    reactions it returns written, before JSBSim's step (they replace the wing's alone,
    written before the controller)."""
    fl = step.flaperon
    size = sum(n for _, n in K.layout(step.n_modes).values())
    params = step._params[:size]  # the half wing's block (the whole array on a half wing)
    K.say_if_compiling(K.flaperon_loads, "flaperon's loads")
    entry, accepts = K.flaperon_entry(params)
    set_lift, set_drag, set_pitch = step._set_reactions
    loads = K.flaperon_loads
    checked, call = None, loads

    def control_flaperon(table: np.ndarray, k: int) -> None:
        nonlocal checked, call
        if table is not checked:  # the machine code for the table type it was built for
            checked, call = table, (entry if accepts(table) else loads)
        control(table, k)
        lift_lbf, drag_lbf, pitch_lbf_ft = call(params, table, k, fl.command_rad)
        set_lift(lift_lbf)
        set_drag(drag_lbf)
        set_pitch(pitch_lbf_ft)

    return control_flaperon
