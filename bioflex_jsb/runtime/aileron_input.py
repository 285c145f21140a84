"""An aileron angle over the trim as JSBSim's normalised aileron command (the JSBSim
boundary of a full-span run's aileron step or doublet, :class:`~bioflex_jsb.simulation
.full_span.AileronInput`).

δa = ½ (δ_left − δ_right) [rad] (JSBSim's sign: + rolls right) against
``fcs/aileron-cmd-norm`` is measured, as the elevator's map is
(:func:`~bioflex_jsb.runtime.control_surfaces.elevator_map`), on a fresh instance of the
aircraft at commands −1..1: linear on each side of zero to 1e-9 rad (the prototype's one
gain, the c172p's aerosurface_scales with their −20°/+15° travel, each side zero-centred),
else one line. The command of δa over the trim is c₀ + m⁻¹(δa₀ + δa) − m⁻¹(δa₀), clipped to
−1..1 (the surface's travel).

A controller's ``aileron`` command (:mod:`bioflex_jsb.simulation.controller`) is written the
same way (:func:`controller_aileron`: a :class:`~bioflex_jsb.runtime.control_surfaces.Command`
whose setter clips), on a full-span step only and not over an autopilot (one line).
"""

from __future__ import annotations

from collections.abc import Callable

from bioflex_jsb.errors import InputError
from bioflex_jsb.runtime.control_surfaces import (
    LINEARITY_TOL_RAD,
    PROBE_COMMANDS,
    Command,
    ElevatorMap,
)
from bioflex_jsb.runtime.fdm import Airframe, load_fdm
from bioflex_jsb.runtime.jsbsim_log import CapturingLogger, captured
from bioflex_jsb.simulation import jsbsim_properties as JP

_NEEDED = (JP.FCS_AILERON_CMD_NORM, JP.FCS_LEFT_AILERON_POS_RAD, JP.FCS_RIGHT_AILERON_POS_RAD)


def aileron_map(airframe: Airframe) -> ElevatorMap:
    """δa [rad] against the aileron command (a two-slope map, the elevator's type)."""
    log = CapturingLogger()
    fdm = load_fdm(airframe.root, airframe.aircraft, airframe.aircraft_path, log)
    manager = fdm.get_property_manager()
    for name in _NEEDED:
        if not manager.hasNode(name):
            raise InputError(f"aircraft {airframe.aircraft!r} has no {name}: its aileron "
                             "cannot be commanded in rad")
    has_trim = manager.hasNode(JP.FCS_ROLL_TRIM_CMD_NORM)
    angles = []
    with captured(log):
        for c in PROBE_COMMANDS:
            fdm[JP.FCS_AILERON_CMD_NORM] = c
            if has_trim:
                fdm[JP.FCS_ROLL_TRIM_CMD_NORM] = 0.0
            fdm.run_ic()
            angles.append(0.5 * (float(fdm[JP.FCS_LEFT_AILERON_POS_RAD])
                                 - float(fdm[JP.FCS_RIGHT_AILERON_POS_RAD])))
    zero = angles[PROBE_COMMANDS.index(0.0)]
    m = ElevatorMap(angles[-1], -angles[0])
    worst = max(abs(m.angle_rad(c) - a) for c, a in zip(PROBE_COMMANDS, angles, strict=True))
    if not (m.down_rad > 0.0 and m.up_rad > 0.0) or abs(zero) > LINEARITY_TOL_RAD \
            or worst > LINEARITY_TOL_RAD:
        raise InputError(f"aircraft {airframe.aircraft!r}: its aileron angle is not linear on "
                         f"each side of zero command (at commands {PROBE_COMMANDS}: "
                         f"{[round(a, 6) for a in angles]} rad)")
    return m


def aileron_command(airframe: Airframe) -> tuple[Command, float]:
    """(the :class:`Command` writing δa [rad] over the trim as the aileron command, clipped to
    −1..1; its travel [rad]: the largest δa it reaches on the smaller side) of the trimmed
    ``airframe``."""
    m = aileron_map(airframe)
    c0 = airframe[JP.FCS_AILERON_CMD_NORM]
    manager = airframe.jsbsim.get_property_manager()
    trim = airframe[JP.FCS_ROLL_TRIM_CMD_NORM] if manager.hasNode(JP.FCS_ROLL_TRIM_CMD_NORM) \
        else 0.0
    angle0 = m.angle_rad(max(-1.0, min(1.0, c0 + trim)))
    node = airframe.property_node(JP.FCS_AILERON_CMD_NORM).set_double_value

    def set_clipped(value: float) -> None:
        node(max(-1.0, min(1.0, value)))

    command = Command(c0 - m.command(angle0), angle0, m.down_rad, m.up_rad, (set_clipped,),
                      (0.0,))
    return command, min(m.down_rad, m.up_rad)


def aileron_setter(airframe: Airframe) -> tuple[Callable[[float], None], float]:
    """(``set(δa)``: write δa [rad] over the trim as the aileron command, its travel
    [rad]: the largest δa it reaches on the smaller side) of the trimmed ``airframe``."""
    command, travel = aileron_command(airframe)
    return command.write, travel


def controller_aileron(airframe: Airframe, full_span: bool, over_autopilot: bool) -> Command:
    """A controller's ``aileron`` command for the trimmed ``airframe`` (module docstring);
    InputError, one line, on the half wing (``full_span`` False) or over an autopilot."""
    if not full_span:
        raise InputError("a controller's aileron command needs both wing halves "
                         "(span='full', --span full): the half wing has no antisymmetric "
                         "modes for it to load; on the half wing accepted: elevator, "
                         "throttle, flaperon")
    if over_autopilot:
        raise InputError("a controller's aileron command over an autopilot: its roll loop "
                         "writes fcs/aileron-cmd-norm itself; accepted over it: elevator, "
                         "throttle")
    return aileron_command(airframe)[0]
