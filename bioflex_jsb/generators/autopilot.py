"""The SITL aircraft's autopilot as JSBSim systems, and the SITL aircraft that loads it.

JSBSim cannot add a system file to a loaded model, so the SITL airframe is its own aircraft:
``aircraft/bioflex_sitl/`` is the generated ``bioflex`` airframe (``airframe_xml``'s
generators, used read-only) with one more ``<system file="bioflex_autopilot"/>`` ahead of the
flight controls, and ``aircraft/bioflex_sitl_trim/`` its trim companion (the plain trim
companion: JSBSim's trim never sees the autopilot). ``systems/bioflex_autopilot.xml`` holds:

* **pitch/altitude hold** (elevator): θ_cmd = θ_trim + K_h (h_set − h) − K_ḣ ḣ, clipped to
  ±``THETA_CMD_MAX_RAD``; Δδ_e = −K_θ (θ_cmd − θ) + K_q q (normalised elevator, + =
  trailing edge down = nose down);
* **heading/roll hold** (ailerons): φ_cmd = K_ψ wrap(ψ_set − ψ) clipped to ±``PHI_CMD_MAX_RAD``,
  or a fixed bank ``ap/loiter-bank-rad`` when ``ap/loiter`` is 1 (a loiter circle), or the
  bank ``ap/bank-cmd-rad`` (clipped to ±``BANK_CMD_MAX_RAD``) when ``ap/roll-mode`` is 1
  (the lateral guidance of :mod:`bioflex_jsb.simulation.guidance`, or the stick in
  STABILIZE); Δδ_a = K_φ (φ_cmd − φ) − K_p p (+ = roll right);
* ``ap/pitch-mode`` 1 replaces the altitude loop's θ_cmd by ``ap/pitch-cmd-rad`` (the stick
  in STABILIZE);
* **airspeed hold** (throttle, ``systems/bioflex_autothrottle.xml``, included *after* the
  flight controls so that it sets the motors' ``fcs/throttle-pos-norm[i]`` last):
  δ_t = δ_t,trim + K_V (V_set − V) clipped to 0..1 when ``ap/autothrottle`` is 1, with
  δ_t,trim the trimmed lever ``fcs/throttle-cmd-norm``; 0 when ``ap/armed`` is 0 (motor
  stopped); otherwise the lever as the flight controls set it.

Both act as *increments on the trim*. JSBSim's full trim balances pitch with
``fcs/pitch-trim-cmd-norm`` and roll with ``fcs/aileron-cmd-norm`` and leaves
``fcs/elevator-cmd-norm`` and ``fcs/roll-trim-cmd-norm`` at 0: the autopilot drives those two,
which the flight controls add to the trimmed ones. Disengaged (``ap/engage`` 0, the default,
so that the trim and the settling of the flying instance see no autopilot) both are 0.
``ap/manual`` 1 puts ``ap/manual-elevator-norm`` / ``ap/manual-aileron-norm`` (stick
increments on the trim, −1..1) there instead: manual input overrides the autopilot.

Gains were tuned on the rigid airframe at 15 m/s (``tests/test_sitl.py`` checks the hold).
Run ``python -m bioflex_jsb.generators.autopilot`` to regenerate the files.

**The glider's autopilot** (:func:`render_glider_autopilot`; an aircraft without an engine
such as JSBSim's SGS, added to the copy of its aircraft by
:func:`bioflex_jsb.drivers.sitl.glider_airframe`, not written to the repository) is built
from the same pitch-attitude and roll laws (:func:`_pitch_loop`, :func:`_roll_channel`) with
its own gains, θ_cmd from the airspeed error (a PI loop: the speed is held with pitch, no
altitude hold) instead of the altitude loop, and the sideslip fed to the rudder
(docs/sitl.md, "A glider").

**A powered aircraft's autopilot** (:func:`render_powered_autopilot`; another JSBSim aircraft
with engines, such as JSBSim's c172p, added to the copy of its aircraft by
:func:`bioflex_jsb.drivers.sitl.powered_airframe`) has the prototype's laws (altitude hold
through the pitch attitude, the heading/roll hold, the stick modes, the autothrottle) and
the glider's sideslip-to-rudder loop, with gains from the aircraft's own dynamics
(:func:`powered_gains`: its rigid short period at the speed, the control power and thrust
its JSBSim model gives per unit command, runtime/control_power.py), the airspeed held by a
PI autothrottle, and the attitude command limited to the climb angle its engines allow.
Its commands are increments on the trim's (``ap/<surface>-trim-norm``, set by the SITL
after each trim) written to the normalised commands every JSBSim aircraft reads
(``fcs/elevator-cmd-norm``, ``fcs/aileron-cmd-norm``, ``fcs/rudder-cmd-norm``,
``fcs/throttle-cmd-norm[i]``); disengaged, each writes its command's own value back, so
JSBSim's trim (which moves those commands) sees no autopilot.
"""

from __future__ import annotations

import argparse
import math
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from bioflex_jsb import units as U
from bioflex_jsb.generators import airframe as AX
from bioflex_jsb.generators.xml_writer import XmlWriter, num_repr, serialise
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2

SYSTEM_FILE = "bioflex_autopilot"
THROTTLE_SYSTEM_FILE = "bioflex_autothrottle"
SITL_AIRCRAFT = "bioflex_sitl"
SITL_TRIM_AIRCRAFT = SITL_AIRCRAFT + AX.TRIM_SUFFIX

# Gains (SI in, normalised control out). ESTIMATE: tuned on the rigid airframe at 15 m/s.
K_ALTITUDE_RAD_PER_M = 0.03  # θ_cmd per metre of altitude error
K_CLIMB_RAD_PER_M_S = 0.06  # θ_cmd per m/s of climb rate (damping of the altitude loop)
THETA_CMD_MAX_RAD = math.radians(12.0)
K_THETA_PER_RAD = 2.5  # elevator (normalised) per rad of pitch error
K_Q_PER_RAD_S = 0.25  # elevator per rad/s of pitch rate
ELEVATOR_AUTHORITY = 0.6  # largest autopilot elevator increment (normalised)
K_HEADING_RAD_PER_RAD = 1.0  # φ_cmd per rad of heading error
PHI_CMD_MAX_RAD = math.radians(25.0)
K_PHI_PER_RAD = 1.2  # aileron per rad of bank error
K_P_PER_RAD_S = 0.15  # aileron per rad/s of roll rate
AILERON_AUTHORITY = 0.6
LOITER_BANK_RAD = math.radians(20.0)
BANK_CMD_MAX_RAD = math.radians(30.0)  # guidance and stick bank commands
K_AIRSPEED_PER_M_S = 0.08  # throttle per m/s of airspeed error

# The glider's autopilot (render_glider_autopilot: the SGS, any aircraft without an engine).
# Its airspeed is held with the pitch attitude (no throttle): θ_cmd = θ_trim + K_V (V − V_set)
# (too fast: nose up), clipped to θ_trim ± GLIDER_THETA_SPAN_RAD; the pitch and roll loops
# are the prototype's laws (_pitch_loop, _roll_channel) with the glider's gains, chosen from
# the SGS's own dynamics at 25 m/s (docs/sitl.md, "A glider"): short period 2.66 rad/s,
# phugoid 0.417 rad/s (`bioflex-jsb modes --aircraft sgs_elastic`), and SGS.xml's control
# power (elevator −28..+23 deg per unit command, Cmde −1.0088/rad, Iyy 911 kg m²: ≈ 2.4 rad/s²
# of pitch per unit; ailerons −20..+15 deg, Clda 0.252/rad, Clp −0.47, Ixx 1376 kg m²:
# ≈ 0.5 rad/s of steady roll rate per unit).
# K_θ 2.0: the pitch stiffness grows from 2.66² = 7.1 to ≈ 11.9 rad/s² per rad (3.4 rad/s),
# K_q 0.5 adds ≈ 1.2 1/s of pitch damping to the airframe's ≈ 1.6 1/s (ζ ≈ 0.4).
# K_V 0.03 rad per m/s: V̇ = −g Δθ closes the speed loop at g K_V ≈ 0.3 rad/s, below the
# phugoid (0.42 rad/s) and a decade below the pitch loop, which it damps (measured in
# tests/test_glider_sitl.py: the speed held to its tolerance there).
# K_φ 2.0: the bank settles with a time constant 1/(0.5 · 2.0) ≈ 1 s (the prototype's 1.2
# would give 1.7 s on the SGS's slower roll); K_p 0.15 as the prototype's. The SGS has a
# rudder but the prototype's autopilot has no yaw damper: neither has this one.
GLIDER_SYSTEM_FILE = "bioflex_glider_autopilot"
GLIDER_K_AIRSPEED_RAD_PER_M_S = 0.03
GLIDER_KI_AIRSPEED_RAD_PER_M = 0.003
GLIDER_THETA_SPAN_RAD = math.radians(10.0)
GLIDER_K_THETA_PER_RAD = 2.0
GLIDER_K_Q_PER_RAD_S = 0.5
GLIDER_K_PHI_PER_RAD = 2.0
GLIDER_K_P_PER_RAD_S = 0.3
GLIDER_K_BETA_PER_RAD = 4.0
RUDDER_AUTHORITY = 0.6
# SGS.xml's aileron channel reads fcs/aileron-cmd-norm only (its roll trim is summed but not
# used), which its trim leaves at 0 (wings level): the roll increment goes there.
GLIDER_AILERON_OUTPUT = "fcs/aileron-cmd-norm"

_HEADER = (
    "<!-- GENERATED by bioflex_jsb.generators.autopilot: do not edit; run\n"
    "     `python -m bioflex_jsb.generators.autopilot` to regenerate. -->\n"
)
# The SITL aircraft's: the airframe's header, naming this module as the generator.
_AIRCRAFT_HEADER = AX.HEADER.replace(
    "GENERATED by bioflex_jsb.generators.airframe",
    "GENERATED by bioflex_jsb.generators.autopilot (from airframe_xml)", 1)


W = XmlWriter(num_repr)
el, node = W.el, W.node


def _clip(parent, lo: float, hi: float) -> None:
    c = el(parent, "clipto")
    el(c, "min", lo)
    el(c, "max", hi)


def _function(channel, name: str, expr: ET.Element, clip: tuple[float, float] | None = None):
    f = el(channel, "fcs_function", name=name)
    fn = el(f, "function")
    fn.append(expr)
    if clip:
        _clip(f, *clip)
    return f


def _engage_switch(channel, name: str, auto: str, manual: str, output: str) -> None:
    sw = el(channel, "switch", name=name)
    el(sw, "default", value="0")
    t = el(sw, "test", "ap/manual == 1", value=manual)
    t.set("logic", "AND")
    t = el(sw, "test", "ap/engage == 1", value=auto)
    t.set("logic", "AND")
    el(sw, "output", output)


# The properties the vehicle sets (drivers/sitl_vehicle.py), with their start values.
_AUTOPILOT_PROPERTIES = (
    ("ap/engage", 0), ("ap/manual", 0), ("ap/loiter", 0),
    ("ap/altitude-hold-m", 0), ("ap/heading-hold-rad", 0),
    ("ap/theta-trim-rad", 0), ("ap/loiter-bank-rad", LOITER_BANK_RAD),
    ("ap/manual-elevator-norm", 0), ("ap/manual-aileron-norm", 0),
    ("ap/roll-mode", 0), ("ap/bank-cmd-rad", 0), ("ap/pitch-mode", 0),
    ("ap/pitch-cmd-rad", 0),
)


def _pitch_loop(pitch, theta_default: str, k_theta: float, k_q: float,
                rate: str = "velocities/q-rad_sec") -> None:
    """The pitch-attitude loop (module docstring), one law for every aircraft: θ_cmd is
    ``theta_default`` (the property of the outer loop) or the stick's ``ap/pitch-cmd-rad``
    (``ap/pitch-mode`` 1); gains ``k_theta`` [elevator per rad of pitch error], ``k_q``
    [elevator per rad/s of the pitch rate ``rate``]; the increment goes to
    ``fcs/elevator-cmd-norm``."""
    sw = el(pitch, "switch", name="ap/theta-cmd-rad")
    el(sw, "default", value=theta_default)
    t = el(sw, "test", "ap/pitch-mode == 1", value="ap/pitch-cmd-rad")
    t.set("logic", "AND")
    elevator = node(
        "sum",
        node("product", -k_theta,
              node("difference", "ap/theta-cmd-rad", "attitude/theta-rad")),
        node("product", k_q, rate),
    )
    _function(pitch, "ap/elevator-auto-norm", elevator, (-ELEVATOR_AUTHORITY, ELEVATOR_AUTHORITY))
    _engage_switch(pitch, "ap/elevator-out-norm", "ap/elevator-auto-norm",
                   "ap/manual-elevator-norm", "fcs/elevator-cmd-norm")


def _bank_command(root):
    """The roll channel (returned) with its bank command ``ap/phi-cmd-rad`` [rad]: the
    heading hold's (the heading error wrapped to ±π), the commanded bank in roll mode 1, the
    loiter's bank while loitering (module docstring)."""
    roll = el(root, "channel", name="AP roll")
    err = node("difference", "ap/heading-hold-rad", "attitude/psi-rad")
    _function(roll, "ap/heading-error-rad", node("atan2", node("sin", err), node("cos", err)))
    _function(roll, "ap/phi-heading-rad",
              node("product", K_HEADING_RAD_PER_RAD, "ap/heading-error-rad"),
              (-PHI_CMD_MAX_RAD, PHI_CMD_MAX_RAD))
    _function(roll, "ap/phi-bank-rad", node("product", 1.0, "ap/bank-cmd-rad"),
              (-BANK_CMD_MAX_RAD, BANK_CMD_MAX_RAD))
    sw = el(roll, "switch", name="ap/phi-cmd-rad")
    el(sw, "default", value="ap/phi-heading-rad")
    t = el(sw, "test", "ap/roll-mode == 1", value="ap/phi-bank-rad")
    t.set("logic", "AND")
    t = el(sw, "test", "ap/loiter == 1", value="ap/loiter-bank-rad")
    t.set("logic", "AND")
    return roll


def _aileron_law(k_phi: float, k_p: float):
    """The aileron [norm] of the bank hold: ``k_phi`` per rad of bank error, ``-k_p`` per
    rad/s of roll rate."""
    return node(
        "sum",
        node("product", k_phi, node("difference", "ap/phi-cmd-rad", "attitude/phi-rad")),
        node("product", -k_p, "velocities/p-rad_sec"),
    )


def _roll_channel(root, k_phi: float, k_p: float, output: str) -> None:
    """The heading/roll hold (module docstring), one law for every aircraft: gains
    ``k_phi`` [aileron per rad of bank error], ``k_p`` [aileron per rad/s of roll rate];
    the aileron increment goes to ``output``."""
    roll = _bank_command(root)
    _function(roll, "ap/aileron-auto-norm", _aileron_law(k_phi, k_p),
              (-AILERON_AUTHORITY, AILERON_AUTHORITY))
    _engage_switch(roll, "ap/aileron-out-norm", "ap/aileron-auto-norm",
                   "ap/manual-aileron-norm", output)


def render_autopilot() -> str:
    """Text of ``systems/bioflex_autopilot.xml`` (module docstring)."""
    root = ET.Element("system", name="bioflex-autopilot")
    for prop, value in _AUTOPILOT_PROPERTIES:
        el(root, "property", prop, value=repr(float(value)))

    pitch = el(root, "channel", name="AP pitch")
    climb = node("product", "velocities/h-dot-fps", U.M_PER_FT)
    theta_cmd = node(
        "sum", "ap/theta-trim-rad",
        node("product", K_ALTITUDE_RAD_PER_M,
              node("difference", "ap/altitude-hold-m", "position/h-sl-meters")),
        node("product", -K_CLIMB_RAD_PER_M_S, climb),
    )
    _function(pitch, "ap/theta-alt-rad", theta_cmd, (-THETA_CMD_MAX_RAD, THETA_CMD_MAX_RAD))
    _pitch_loop(pitch, "ap/theta-alt-rad", K_THETA_PER_RAD, K_Q_PER_RAD_S)

    _roll_channel(root, K_PHI_PER_RAD, K_P_PER_RAD_S, "fcs/roll-trim-cmd-norm")
    return serialise(root, _HEADER)


def render_glider_autopilot() -> str:
    """Text of the glider's autopilot system (the gains' comment above): the airspeed held
    with pitch (``ap/airspeed-hold-mps``), the heading/roll hold and the stick modes as the
    prototype's (:func:`render_autopilot`'s properties). A glider has no altitude hold: its
    ``ap/altitude-hold-m``, ``ap/autothrottle`` and ``ap/armed`` are declared (the vehicle
    writes them for every aircraft) and act on nothing."""
    root = ET.Element("system", name="bioflex-glider-autopilot")
    for prop, value in _AUTOPILOT_PROPERTIES + (
            ("ap/airspeed-hold-mps", 0), ("ap/autothrottle", 0), ("ap/armed", 1),
            ("ap/speed-integral-rad", 0)):
        el(root, "property", prop, value=repr(float(value)))
    pitch = el(root, "channel", name="AP pitch")
    speed = node("product", "velocities/vt-fps", U.M_PER_FT)
    _function(pitch, "ap/speed-error-mps", node("difference", speed, "ap/airspeed-hold-mps"))
    # the integral runs while the speed loop flies the aircraft, held at 0 in MANUAL, the
    # stick modes and disengaged; over JSBSim's own step (_integrator: JSBSim's <pid>
    # integrated with the step the aircraft was loaded with, 1/120 s, 8 times too fast)
    sw = el(pitch, "switch", name="ap/speed-integrating")
    el(sw, "default", value="0")
    t = el(sw, "test", "ap/engage == 1\nap/manual == 0\nap/pitch-mode == 0", value="1")
    t.set("logic", "AND")
    _integrator(pitch, "ap/speed-integral-rad", "ap/speed-error-mps",
                GLIDER_KI_AIRSPEED_RAD_PER_M, "ap/speed-integrating",
                (-GLIDER_THETA_SPAN_RAD, GLIDER_THETA_SPAN_RAD))
    _function(pitch, "ap/theta-speed-incr-rad",
              node("sum", node("product", GLIDER_K_AIRSPEED_RAD_PER_M_S, "ap/speed-error-mps"),
                   "ap/speed-integral-rad"), (-GLIDER_THETA_SPAN_RAD, GLIDER_THETA_SPAN_RAD))
    _function(pitch, "ap/theta-speed-rad",
              node("sum", "ap/theta-trim-rad", "ap/theta-speed-incr-rad"))
    # the pitch rate a steady turn has (q = r tan φ, body axes) is not damped
    _function(pitch, "ap/q-off-turn-rad_sec",
              node("difference", "velocities/q-rad_sec",
                   node("product", "velocities/r-rad_sec", node("tan", "attitude/phi-rad"))))
    _pitch_loop(pitch, "ap/theta-speed-rad", GLIDER_K_THETA_PER_RAD, GLIDER_K_Q_PER_RAD_S,
                "ap/q-off-turn-rad_sec")
    _roll_channel(root, GLIDER_K_PHI_PER_RAD, GLIDER_K_P_PER_RAD_S, GLIDER_AILERON_OUTPUT)
    yaw = el(root, "channel", name="AP yaw")
    _function(yaw, "ap/rudder-auto-norm", node("product", -GLIDER_K_BETA_PER_RAD, "aero/beta-rad"),
              (-RUDDER_AUTHORITY, RUDDER_AUTHORITY))
    _engage_switch(yaw, "ap/rudder-out-norm", "ap/rudder-auto-norm", "0",
                   "fcs/rudder-cmd-norm")
    return serialise(root, _HEADER)


# -- a powered aircraft's autopilot ------------------------------------------------------
POWERED_SYSTEM_FILE = "bioflex_powered_autopilot"
# The closed pitch-attitude loop: its stiffness twice the airframe's short period's
# (ω_c = √2 ω_sp), damped to ζ_c (the classical 0.7 of a second-order loop).
PITCH_LOOP_DAMPING = 0.7
# The altitude and airspeed loops' time constant [s]: ArduPlane's TECS_TIME_CONST default
# (5 s); the prototype's own altitude loop, tuned by hand (K_h 0.03 rad/m, K_ḣ 0.06 rad per
# m/s at 15 m/s), has 4.2 s. The airspeed integral's time constant is twice it.
ENERGY_TIME_CONSTANT_S = 5.0
# Climb-rate feedback: K_ḣ V = 1, a climb at γ is taken off θ_cmd as an equal angle (the
# prototype's K_ḣ V is 0.9).
CLIMB_DAMPING = 1.0
# Share of the full-throttle climb angle the altitude loop may command above (and below) θ
# at the trim, so that the autothrottle keeps a margin to hold the speed in a climb.
CLIMB_ANGLE_SHARE = 0.8
# The bank loop's time constant [s] (the glider's 1 s; ArduPlane's RLL2SRV_TCONST default
# is 0.5 s), and the roll-rate feedback's share of the roll's own damping.
ROLL_TIME_CONSTANT_S = 1.0
ROLL_RATE_SHARE = 0.25


@dataclass(frozen=True)
class PoweredGains:
    """A powered aircraft's autopilot gains (SI in, normalised command out) and the numbers
    they were chosen from (:func:`powered_gains`)."""

    theta_per_rad: float  # elevator per rad of pitch-attitude error (> 0)
    q_per_rad_s: float  # elevator per rad/s of pitch rate (> 0: nose-down elevator)
    altitude_rad_per_m: float  # θ_cmd per m of altitude error
    altitude_i_rad_per_m_s: float  # θ_cmd per m·s of integrated altitude error
    climb_rad_per_m_s: float  # θ_cmd per m/s of climb rate
    theta_span_rad: float  # θ_cmd within θ_trim ± this
    phi_per_rad: float  # aileron per rad of bank error
    p_per_rad_s: float  # aileron per rad/s of roll rate
    beta_per_rad: float  # rudder per rad of sideslip (signed)
    airspeed_per_m_s: float  # throttle per m/s of airspeed error
    airspeed_i_per_m: float  # throttle per m of integrated airspeed error
    climb_throttle_per_m_s: float  # throttle per unit ḣ/V (the climb's thrust W ḣ/V)
    source: dict  # what they were scaled from (the log, docs/sitl.md)

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def powered_gains(speed_m_s: float, short_period_rad_s: float, short_period_damping: float,
                  power) -> PoweredGains:
    """The gains of :func:`render_powered_autopilot` for an aircraft at ``speed_m_s`` [m/s]
    whose rigid short period has the natural frequency ``short_period_rad_s`` ω_sp [rad/s]
    and damping ``short_period_damping`` ζ_sp, with the control power ``power``
    (:class:`bioflex_jsb.runtime.control_power.ControlPower`: m_δe, l_δa, n_δr [rad/s² per
    unit], L_p [1/s], N_β [1/s²], a_δt [m/s² per unit], γ_full [rad]):

    * pitch attitude: K_θ = ω_sp²/|m_δe| (the loop's stiffness twice the airframe's),
      K_q = max(0, 2 ζ_c ω_c − 2 ζ_sp ω_sp)/|m_δe|, ω_c = √2 ω_sp, ζ_c = 0.7;
    * altitude: K_ḣ = 1/V (CLIMB_DAMPING), K_h = (1 + K_ḣ V)/(V τ) with τ = 5 s
      (θ ≈ θ_cmd and ḣ = V Δθ make the altitude error decay as e^(−t/τ)), an integral
      K_h/(4 τ) for the trim's change of θ with speed; θ_cmd within θ_trim ± 0.8 γ_full (at
      most 12°);
    * bank: p_ss = |l_δa/L_p| (steady roll rate per unit aileron), K_p = 0.25/p_ss,
      K_φ = (1 + p_ss K_p)/(p_ss τ_φ), τ_φ = 1 s (the bank's time constant with the roll
      taken as first order);
    * sideslip to rudder: N_β/n_δr (the rudder doubles the weathercock stiffness);
    * airspeed: K_V = 1/(a_δt τ) and K_i = K_V/(2 τ), τ = 5 s, with the climb's thrust
      fed forward: g/a_δt per unit ḣ/V (W sin γ over the thrust a unit of throttle adds).
    Raises ValueError when a number it needs is not positive and finite."""
    v, wn, zeta = float(speed_m_s), float(short_period_rad_s), float(short_period_damping)
    m_de, l_da, lp = abs(power.pitch_rad_s2), abs(power.roll_rad_s2), power.roll_damping_1_s
    a_dt = power.throttle_m_s2
    for name, value in (("speed", v), ("short-period frequency", wn), ("elevator power", m_de),
                        ("aileron power", l_da), ("roll damping", -lp),
                        ("thrust per throttle", a_dt), ("climb angle at full throttle",
                                                        power.climb_angle_full_rad)):
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"autopilot gains: the aircraft's {name} must be positive, got "
                             f"{value!r}")
    wc = math.sqrt(2.0) * wn
    k_theta = wn * wn / m_de
    k_q = max(0.0, 2.0 * PITCH_LOOP_DAMPING * wc - 2.0 * zeta * wn) / m_de
    k_hdot = CLIMB_DAMPING / v
    k_h = (1.0 + k_hdot * v) / (v * ENERGY_TIME_CONSTANT_S)
    span = min(THETA_CMD_MAX_RAD, CLIMB_ANGLE_SHARE * power.climb_angle_full_rad)
    p_ss = l_da / abs(lp)
    k_p = ROLL_RATE_SHARE / p_ss
    k_phi = (1.0 + p_ss * k_p) / (p_ss * ROLL_TIME_CONSTANT_S)
    k_beta = (power.yaw_stiffness_1_s2 / power.yaw_rad_s2
              if power.yaw_rad_s2 and power.yaw_stiffness_1_s2 > 0.0 else 0.0)
    k_v = 1.0 / (a_dt * ENERGY_TIME_CONSTANT_S)
    source = {"speed_m_s": v, "short_period_rad_s": wn, "short_period_damping": zeta,
              **{f"power_{k}": float(x) for k, x in power.as_dict().items()}}
    return PoweredGains(k_theta, k_q, k_h, k_h / (4.0 * ENERGY_TIME_CONSTANT_S), k_hdot,
                        span, k_phi, k_p, k_beta, k_v,
                        k_v / (2.0 * ENERGY_TIME_CONSTANT_S),
                        STANDARD_GRAVITY_M_S2 / a_dt, source)


def _integrator(channel, name: str, rate: str, gain: float, running: str,
                clip: tuple[float, float]) -> None:
    """``name`` = ∫ ``gain`` · ``rate`` dt over JSBSim's own step (``simulation/dt``) while
    the property ``running`` is 1, else 0, clipped to ``clip`` (no wind-up past it). The
    integral is a property declared by the caller's system (its previous value is read)."""
    step = node("sum", name, node("product", gain, "simulation/dt", rate))
    f = el(channel, "fcs_function", name=name + "-next")
    fn = el(f, "function")
    fn.append(node("ifthen", running, step, 0.0))
    _clip(f, *clip)
    el(f, "output", name)


def _trimmed_switch(channel, name: str, auto: str, manual: str, output: str) -> None:
    """The output switch of a powered aircraft's surface: engaged, ``auto``; in MANUAL,
    ``manual``; disengaged, the command's own value (JSBSim's trim moves it)."""
    sw = el(channel, "switch", name=name)
    el(sw, "default", value=output)
    t = el(sw, "test", "ap/manual == 1", value=manual)
    t.set("logic", "AND")
    t = el(sw, "test", "ap/engage == 1", value=auto)
    t.set("logic", "AND")
    el(sw, "output", output)


def _plus_trim(channel, name: str, trim: str, increment: str) -> None:
    _function(channel, name, node("sum", trim, increment), (-1.0, 1.0))


def render_powered_autopilot(gains: PoweredGains, engines: int) -> str:
    """Text of a powered aircraft's autopilot system (module docstring) with ``gains`` for
    ``engines`` engines (``fcs/throttle-cmd-norm[i]``, each its own trim lever)."""
    g = gains
    root = ET.Element("system", name="bioflex-powered-autopilot")
    trims = (("ap/elevator-trim-norm", 0), ("ap/aileron-trim-norm", 0),
             ("ap/rudder-trim-norm", 0))
    levers = tuple((f"ap/throttle-trim-norm[{i}]", 0) for i in range(engines))
    for prop, value in _AUTOPILOT_PROPERTIES + trims + levers + (
            ("ap/airspeed-hold-mps", 0), ("ap/autothrottle", 0), ("ap/armed", 1),
            ("ap/throttle-integral-norm", 0), ("ap/altitude-integral-rad", 0)):
        el(root, "property", prop, value=repr(float(value)))

    pitch = el(root, "channel", name="AP pitch")
    climb = node("product", "velocities/h-dot-fps", U.M_PER_FT)
    _function(pitch, "ap/altitude-error-m",
              node("difference", "ap/altitude-hold-m", "position/h-sl-meters"))
    # the altitude's integral takes the trim's change of θ with the speed (the attitude at
    # 50 m/s is not the cruise trim's: 5 m low without it, measured on the c172); it runs
    # while the loop flies and its command is inside the span (no wind-up in a climb)
    unclipped = node("sum", node("product", g.altitude_rad_per_m, "ap/altitude-error-m"),
                     node("product", -g.climb_rad_per_m_s, climb), "ap/altitude-integral-rad")
    _function(pitch, "ap/theta-alt-unclipped-rad", unclipped)
    sw = el(pitch, "switch", name="ap/altitude-integrating")
    el(sw, "default", value="0")
    t = el(sw, "test", "ap/engage == 1\nap/manual == 0\nap/pitch-mode == 0\n"
           f"ap/theta-alt-unclipped-rad lt {float(g.theta_span_rad)!r}\n"
           f"ap/theta-alt-unclipped-rad gt {-float(g.theta_span_rad)!r}", value="1")
    t.set("logic", "AND")
    _integrator(pitch, "ap/altitude-integral-rad", "ap/altitude-error-m",
                g.altitude_i_rad_per_m_s, "ap/altitude-integrating",
                (-g.theta_span_rad, g.theta_span_rad))
    _function(pitch, "ap/theta-alt-incr-rad", node("product", 1.0, "ap/theta-alt-unclipped-rad"),
              (-g.theta_span_rad, g.theta_span_rad))
    _function(pitch, "ap/theta-alt-rad", node("sum", "ap/theta-trim-rad",
                                              "ap/theta-alt-incr-rad"))
    sw = el(pitch, "switch", name="ap/theta-cmd-rad")
    el(sw, "default", value="ap/theta-alt-rad")
    t = el(sw, "test", "ap/pitch-mode == 1", value="ap/pitch-cmd-rad")
    t.set("logic", "AND")
    # the pitch rate a steady turn has (q = r tan φ, body axes) is not damped (as the glider)
    _function(pitch, "ap/q-off-turn-rad_sec",
              node("difference", "velocities/q-rad_sec",
                   node("product", "velocities/r-rad_sec", node("tan", "attitude/phi-rad"))))
    elevator = node(
        "sum",
        node("product", -g.theta_per_rad,
             node("difference", "ap/theta-cmd-rad", "attitude/theta-rad")),
        node("product", g.q_per_rad_s, "ap/q-off-turn-rad_sec"))
    _function(pitch, "ap/elevator-auto-incr-norm", elevator,
              (-ELEVATOR_AUTHORITY, ELEVATOR_AUTHORITY))
    _plus_trim(pitch, "ap/elevator-auto-norm", "ap/elevator-trim-norm",
               "ap/elevator-auto-incr-norm")
    _plus_trim(pitch, "ap/elevator-manual-norm", "ap/elevator-trim-norm",
               "ap/manual-elevator-norm")
    _trimmed_switch(pitch, "ap/elevator-out-norm", "ap/elevator-auto-norm",
                    "ap/elevator-manual-norm", "fcs/elevator-cmd-norm")

    roll = _bank_command(root)
    _function(roll, "ap/aileron-auto-incr-norm", _aileron_law(g.phi_per_rad, g.p_per_rad_s),
              (-AILERON_AUTHORITY, AILERON_AUTHORITY))
    _plus_trim(roll, "ap/aileron-auto-norm", "ap/aileron-trim-norm", "ap/aileron-auto-incr-norm")
    _plus_trim(roll, "ap/aileron-manual-norm", "ap/aileron-trim-norm", "ap/manual-aileron-norm")
    _trimmed_switch(roll, "ap/aileron-out-norm", "ap/aileron-auto-norm",
                    "ap/aileron-manual-norm", "fcs/aileron-cmd-norm")

    yaw = el(root, "channel", name="AP yaw")
    _function(yaw, "ap/rudder-auto-incr-norm", node("product", g.beta_per_rad, "aero/beta-rad"),
              (-RUDDER_AUTHORITY, RUDDER_AUTHORITY))
    _plus_trim(yaw, "ap/rudder-auto-norm", "ap/rudder-trim-norm", "ap/rudder-auto-incr-norm")
    _trimmed_switch(yaw, "ap/rudder-out-norm", "ap/rudder-auto-norm", "ap/rudder-trim-norm",
                    "fcs/rudder-cmd-norm")

    thr = el(root, "channel", name="AP throttle")
    speed = node("product", "velocities/vt-fps", U.M_PER_FT)
    _function(thr, "ap/speed-error-mps", node("difference", "ap/airspeed-hold-mps", speed))
    # the integral runs while the autothrottle flies, held at 0 otherwise; integrated with
    # the step JSBSim runs at (simulation/dt): JSBSim's <pid> takes the step the aircraft
    # was loaded with (1/120 s) and integrated 8 times too fast at the co-simulation's
    # 1/960 s (measured)
    sw = el(thr, "switch", name="ap/throttle-integrating")
    el(sw, "default", value="0")
    t = el(sw, "test", "ap/engage == 1\nap/autothrottle == 1\nap/armed == 1", value="1")
    t.set("logic", "AND")
    # the thrust a climb at ḣ needs, W ḣ/V, fed forward (the total energy's rate: the PI
    # is left with the model's errors, not the climbs', so it does not wind up on them)
    _function(thr, "ap/throttle-climb-norm",
              node("product", g.climb_throttle_per_m_s,
                   node("product", "velocities/h-dot-fps", U.M_PER_FT),
                   node("quotient", 1.0,
                        node("max", node("product", "velocities/vt-fps", U.M_PER_FT), 1.0))))
    # the first engine's lever before its 0..1 limits: while it is past one and the error
    # pushes further, the integral is held (no wind-up at full throttle or idle)
    _function(thr, "ap/throttle-unclipped-norm",
              node("sum", "ap/throttle-trim-norm[0]" if engines else 0.0,
                   node("product", g.airspeed_per_m_s, "ap/speed-error-mps"),
                   "ap/throttle-integral-norm", "ap/throttle-climb-norm"))
    sw = el(thr, "switch", name="ap/throttle-integrand-gate")
    el(sw, "default", value="1")
    t = el(sw, "test", "ap/throttle-unclipped-norm ge 1\nap/speed-error-mps gt 0", value="0")
    t.set("logic", "AND")
    t = el(sw, "test", "ap/throttle-unclipped-norm le 0\nap/speed-error-mps lt 0", value="0")
    t.set("logic", "AND")
    _function(thr, "ap/speed-error-gated-mps",
              node("product", "ap/speed-error-mps", "ap/throttle-integrand-gate"))
    _integrator(thr, "ap/throttle-integral-norm", "ap/speed-error-gated-mps",
                g.airspeed_i_per_m, "ap/throttle-integrating", (-1.0, 1.0))
    _function(thr, "ap/throttle-auto-incr-norm",
              node("sum", node("product", g.airspeed_per_m_s, "ap/speed-error-mps"),
                   "ap/throttle-integral-norm"), (-1.0, 1.0))
    for i in range(engines):
        lever = f"ap/throttle-trim-norm[{i}]"
        _function(thr, f"ap/throttle-auto-norm[{i}]",
                  node("sum", lever, "ap/throttle-auto-incr-norm", "ap/throttle-climb-norm"),
                  (0.0, 1.0))
        sw = el(thr, "switch", name=f"ap/throttle-out-norm[{i}]")
        el(sw, "default", value=f"fcs/throttle-cmd-norm[{i}]")
        t = el(sw, "test", "ap/armed == 0", value="0")  # disarmed: the engine at idle
        t.set("logic", "AND")
        t = el(sw, "test", "ap/engage == 1\nap/autothrottle == 1",
               value=f"ap/throttle-auto-norm[{i}]")
        t.set("logic", "AND")
        t = el(sw, "test", "ap/manual == 1", value=lever)
        t.set("logic", "AND")
        el(sw, "output", f"fcs/throttle-cmd-norm[{i}]")
    return serialise(root, _HEADER)


def render_autothrottle(engines: int) -> str:
    """Text of ``systems/bioflex_autothrottle.xml`` (module docstring: airspeed hold) for an
    aircraft with ``engines`` engines (one throttle position each)."""
    root = ET.Element("system", name="bioflex-autothrottle")
    for prop, value in (("ap/armed", 1), ("ap/autothrottle", 0), ("ap/airspeed-hold-mps", 0)):
        el(root, "property", prop, value=repr(float(value)))
    ch = el(root, "channel", name="AP throttle")
    speed = node("product", "velocities/vt-fps", U.M_PER_FT)
    auto = node("sum", "fcs/throttle-cmd-norm",
                node("product", K_AIRSPEED_PER_M_S,
                     node("difference", "ap/airspeed-hold-mps", speed)))
    _function(ch, "ap/throttle-auto-norm", auto, (0.0, 1.0))
    sw = el(ch, "switch", name="ap/throttle-out-norm")
    el(sw, "default", value="fcs/throttle-cmd-norm")
    t = el(sw, "test", "ap/armed == 0", value="0")
    t.set("logic", "AND")
    t = el(sw, "test", "ap/autothrottle == 1", value="ap/throttle-auto-norm")
    t.set("logic", "AND")
    for i in range(engines):
        el(sw, "output", f"fcs/throttle-pos-norm[{i}]")
    return serialise(root, _HEADER)


def _sitl_aircraft(trim_companion: bool) -> str:
    """The SITL aircraft (or its trim companion): the airframe's tree renamed, the autopilot
    system included ahead of the flight controls and the autothrottle after them (neither
    in the trim companion)."""
    root = AX.airframe_tree(trim_companion=trim_companion)
    root.set("name", SITL_TRIM_AIRCRAFT if trim_companion else SITL_AIRCRAFT)
    if not trim_companion:
        fcs = AX.flight_controls_include(root)
        at = list(root).index(fcs)
        root.insert(at + 1, ET.Element("system", file=THROTTLE_SYSTEM_FILE))
        root.insert(at, ET.Element("system", file=SYSTEM_FILE))
    return serialise(root, _AIRCRAFT_HEADER)


def render_all() -> dict[str, str]:
    """Every SITL file: path relative to the JSBSim root → text."""
    craft, comp = f"aircraft/{SITL_AIRCRAFT}", f"aircraft/{SITL_TRIM_AIRCRAFT}"
    engines = len(AX.airframe_tree(trim_companion=False).findall("propulsion/engine"))
    return {
        f"systems/{SYSTEM_FILE}.xml": render_autopilot(),
        f"systems/{THROTTLE_SYSTEM_FILE}.xml": render_autothrottle(engines),
        f"{craft}/{SITL_AIRCRAFT}.xml": _sitl_aircraft(False),
        f"{craft}/Engines/{AX.ENGINE_FILE}.xml": AX.render_engine(),
        f"{craft}/Engines/{AX.PROPELLER_FILE}.xml": AX.render_propeller(),
        f"{comp}/{SITL_TRIM_AIRCRAFT}.xml": _sitl_aircraft(True),
        f"{comp}/Engines/{AX.ENGINE_FILE}.xml": AX.render_engine(),
        f"{comp}/Engines/{AX.TRIM_PROPELLER_FILE}.xml": AX.render_propeller(trim_companion=True),
    }


def write_all(root_dir: Path) -> list[Path]:
    """Write the SITL files under ``root_dir`` (a JSBSim root); return the paths."""
    return AX.write_files(render_all(), root_dir)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bioflex_jsb.generators.autopilot",
        description="Regenerate the SITL aircraft and its autopilot system file.",
    )
    parser.add_argument("--root", type=Path, default=AX.default_output_root(),
                        help="JSBSim root (default: the repository)")
    args = parser.parse_args(argv)
    for path in write_all(args.root):
        print(path)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
