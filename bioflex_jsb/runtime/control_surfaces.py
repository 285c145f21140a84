"""A controller's commands into JSBSim: the elevator [rad] and the throttle [-] as the
aircraft's flight controls take them, converted here, once, at the JSBSim boundary (the
flaperon: its own path, below).

The elevator. An aircraft's flight controls map the normalised command
``fcs/elevator-cmd-norm`` (plus ``fcs/pitch-trim-cmd-norm``, clipped to −1..1) to the
surface's angle ``fcs/elevator-pos-rad``: the prototype's generated controls by one gain
(±20°, ``parameters.airframe.CONTROL_LIMITS``), JSBSim's c172p and SGS by an
``aerosurface_scale`` with a different travel up and down (c172p: −28°/+23°). The map is
measured, not assumed: :func:`elevator_map` loads a fresh JSBSim instance of the same
aircraft (its flight controls only matter; a 7 ms load) and runs its initial condition at
commands from −1 to 1 (:data:`PROBE_COMMANDS`); the map must be linear on each side of 0
(two slopes, rad per unit command, :class:`ElevatorMap`) to within
:data:`LINEARITY_TOL_RAD`, else a controller cannot command that elevator in rad (one line,
InputError). The flying instance is never touched (a trimmed airframe stays trimmed).

A command δe [rad] over the trim is then written as the normalised command
c = c₀ + (m⁻¹(δ₀ + δe) − m⁻¹(δ₀)), c₀ the trim's command and δ₀ its angle, m⁻¹ the inverse
map: exactly c₀ at δe = 0, and the surface at δ₀ + δe within its travel (the flight
controls clip beyond it).

The throttle: ``fcs/throttle-cmd-norm[i]`` of every engine, the trim's plus δt (the flight
controls clip the total to 0..1). A glider has no throttle.

**Over an autopilot** (``over_autopilot``: the SITL aircraft, whose autopilot system writes
``fcs/elevator-cmd-norm`` inside every JSBSim step, :mod:`bioflex_jsb.generators.autopilot`):
the controller's elevator goes to ``fcs/pitch-trim-cmd-norm`` instead, c = c₀ + m⁻¹(δ₀ + δe) −
m⁻¹(δ₀) with c₀ the trim's pitch trim, and the flight controls add the autopilot's command to
it: the surface is the autopilot's plus δe (exactly on an elevator of one slope, the
prototype's; on one of two slopes while the total command keeps the trim's side). The
prototype's autothrottle adds its increment to the lever ``fcs/throttle-cmd-norm``, so the
controller's throttle is added to the autopilot's alike; a powered aircraft's autopilot
writes the levers itself (``ap/throttle-trim-norm[i]`` plus its increment), over which a
controller's throttle is refused (one line).

**The flaperon** (both ailerons down together, :mod:`bioflex_jsb.aeroelasticity.flaperon`)
has no JSBSim property: JSBSim's tables carry no symmetric aileron. Its command is the
coupled step's own (:mod:`bioflex_jsb.runtime.flaperon_step`): its loads go to the external
reactions and its strip loads to the symmetric modes; ``fcs/aileron-cmd-norm`` is not
written, so nothing is counted twice.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from bioflex_jsb.errors import InputError
from bioflex_jsb.runtime.fdm import Airframe, load_fdm
from bioflex_jsb.runtime.jsbsim_log import CapturingLogger, captured
from bioflex_jsb.simulation import jsbsim_properties as JP

# The normalised commands the elevator map is measured at (0 and both ends included).
PROBE_COMMANDS = (-1.0, -0.75, -0.5, -0.25, 0.0, 0.25, 0.5, 0.75, 1.0)
# The map is linear on each side of 0 when every probe lies on its side's line within this
# [rad] (JSBSim's aerosurface_scale and pure_gain are exact to rounding: ~1e-16 measured on
# the prototype, the c172p and the SGS).
LINEARITY_TOL_RAD = 1e-9


@dataclass(frozen=True)
class ElevatorMap:
    """The elevator's angle against its normalised command (module docstring): ``down``
    and ``up`` [rad per unit command] the slopes for a positive and a negative command
    (+ trailing edge down)."""

    down_rad: float
    up_rad: float

    def angle_rad(self, command: float) -> float:
        """The angle [rad] of the (summed) command within −1..1."""
        return command * (self.down_rad if command >= 0.0 else self.up_rad)

    def command(self, angle_rad: float) -> float:
        """The (summed) command of the angle [rad] (beyond the travel: beyond ±1)."""
        return angle_rad / (self.down_rad if angle_rad >= 0.0 else self.up_rad)


def elevator_map(airframe: Airframe, over_autopilot: bool = False) -> ElevatorMap:
    """The elevator map of ``airframe``'s aircraft, measured on a fresh instance of it (over
    an autopilot, which writes ``fcs/elevator-cmd-norm`` itself: through the pitch trim,
    the elevator command at 0)."""
    log = CapturingLogger()
    fdm = load_fdm(airframe.root, airframe.aircraft, airframe.aircraft_path, log)
    manager = fdm.get_property_manager()
    for name in (JP.FCS_ELEVATOR_CMD_NORM, JP.FCS_ELEVATOR_POS_RAD):
        if not manager.hasNode(name):
            raise InputError(f"aircraft {airframe.aircraft!r} has no {name}: a controller's "
                             "elevator cannot be commanded")
    has_trim = manager.hasNode(JP.FCS_PITCH_TRIM_CMD_NORM)
    if over_autopilot and not has_trim:
        raise InputError(f"aircraft {airframe.aircraft!r} has no {JP.FCS_PITCH_TRIM_CMD_NORM}: "
                         "a controller's elevator cannot be added to its autopilot's")
    probe, rest = ((JP.FCS_PITCH_TRIM_CMD_NORM, JP.FCS_ELEVATOR_CMD_NORM) if over_autopilot
                   else (JP.FCS_ELEVATOR_CMD_NORM, JP.FCS_PITCH_TRIM_CMD_NORM))
    angles = []
    with captured(log):
        for c in PROBE_COMMANDS:
            fdm[probe] = c
            if has_trim:
                fdm[rest] = 0.0
            fdm.run_ic()
            angles.append(float(fdm[JP.FCS_ELEVATOR_POS_RAD]))
    zero = angles[PROBE_COMMANDS.index(0.0)]
    down, up = angles[-1], -angles[0]
    m = ElevatorMap(down, up)
    worst = max(abs(m.angle_rad(c) - a) for c, a in zip(PROBE_COMMANDS, angles, strict=True))
    if not (down > 0.0 and up > 0.0) or abs(zero) > LINEARITY_TOL_RAD \
            or worst > LINEARITY_TOL_RAD:
        raise InputError(f"aircraft {airframe.aircraft!r}: its elevator angle is not linear "
                         "on each side of zero command (fcs/elevator-pos-rad at commands "
                         f"{PROBE_COMMANDS}: {[round(a, 6) for a in angles]} rad), so a "
                         "controller's elevator in rad cannot be converted")
    return m


@dataclass(frozen=True)
class Command:
    """How one command δ (over the trim, SI) reaches JSBSim: the value
    v = offset + (angle + δ)/(down if angle + δ ≥ 0 else up) (the map a compiled controller
    applies itself: :class:`~bioflex_jsb.simulation.controller_kernel.LinearBinding`),
    written by each of ``setters`` with its own ``adds`` added (the throttle's per-engine
    trims)."""

    offset: float
    angle: float
    down: float
    up: float
    setters: tuple[Callable[[float], None], ...]
    adds: tuple[float, ...]

    def value(self, delta: float) -> float:
        angle = self.angle + delta
        return self.offset + angle / (self.down if angle >= 0.0 else self.up)

    def write_value(self, value: float) -> None:
        """Write an already mapped ``value``."""
        for set_value, add in zip(self.setters, self.adds, strict=True):
            set_value(add + value)

    def write(self, delta: float) -> None:
        """Write the command ``delta`` (over the trim)."""
        self.write_value(self.value(delta))


def elevator_command(airframe: Airframe, over_autopilot: bool = False) -> Command:
    """The elevator δe [rad, + trailing edge down] over the trim as ``fcs/elevator-cmd-norm``
    (module docstring: c₀ + m⁻¹(δ₀ + δe) − m⁻¹(δ₀)), or over an autopilot as
    ``fcs/pitch-trim-cmd-norm``; ``airframe`` trimmed."""
    m = elevator_map(airframe, over_autopilot)
    elevator0 = airframe[JP.FCS_ELEVATOR_CMD_NORM]
    manager = airframe.jsbsim.get_property_manager()
    has_trim = manager.hasNode(JP.FCS_PITCH_TRIM_CMD_NORM)
    pitch_trim = airframe[JP.FCS_PITCH_TRIM_CMD_NORM] if has_trim else 0.0
    angle0 = m.angle_rad(elevator0 + pitch_trim)
    target = JP.FCS_PITCH_TRIM_CMD_NORM if over_autopilot else JP.FCS_ELEVATOR_CMD_NORM
    command0 = pitch_trim if over_autopilot else elevator0
    setter = airframe.property_node(target).set_double_value
    return Command(command0 - m.command(angle0), angle0, m.down_rad, m.up_rad, (setter,),
                   (0.0,))


def throttle_command(airframe: Airframe, over_autopilot: bool = False) -> Command:
    """The throttle δt [-] over the trim on every engine's command (its trim added); over a
    powered aircraft's autopilot, which writes the levers itself, InputError."""
    if airframe.glider or not airframe.engines:
        raise InputError(f"aircraft {airframe.aircraft!r} has no engine: a controller cannot "
                         "command its throttle")
    if over_autopilot and airframe.has_property("ap/throttle-trim-norm[0]"):
        raise InputError(f"aircraft {airframe.aircraft!r}: its autopilot writes the throttle "
                         "levers itself; a controller in the loop commands its elevator only")
    names = [JP.throttle_cmd(e.index) for e in airframe.engines]
    return Command(0.0, 0.0, 1.0, 1.0,
                   tuple(airframe.property_node(n).set_double_value for n in names),
                   tuple(airframe[n] for n in names))


COMMANDS = {"elevator": elevator_command, "throttle": throttle_command}


def commands_for(airframe: Airframe, outputs: tuple[str, ...], over_autopilot: bool = False,
                 flaperon: Command | None = None, aileron: Command | None = None
                 ) -> tuple[Command, ...]:
    """One :class:`Command` per command of ``outputs`` (in that order), for the trimmed
    ``airframe`` (``over_autopilot``: added to its autopilot's, module docstring);
    ``flaperon`` the flaperon's writer (module docstring, "The flaperon"), ``aileron`` the
    aileron's (a full-span step's: runtime/aileron_input.py controller_aileron)."""
    given = {"flaperon": flaperon, "aileron": aileron}
    if "flaperon" in outputs and flaperon is None:
        raise InputError("a flaperon command needs the coupled step's flaperon (the half "
                         "wing's strips): runtime/flaperon_step.py")
    if "aileron" in outputs and aileron is None:
        raise InputError("an aileron command needs the full-span step's aileron writer: "
                         "runtime/aileron_input.py")
    return tuple(given[o] if o in given else COMMANDS[o](airframe, over_autopilot)
                 for o in outputs)
