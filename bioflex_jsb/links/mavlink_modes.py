"""Flight modes of the SITL vehicle as MAVLink sees them: ArduPlane's custom modes.

Encoding (docs/sitl.md, "Modes"): the HEARTBEAT says ``type`` MAV_TYPE_FIXED_WING and
``autopilot`` MAV_AUTOPILOT_ARDUPILOTMEGA, ``base_mode`` has MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
(plus SAFETY_ARMED when armed and the STABILIZE/GUIDED/AUTO/MANUAL_INPUT flags of the mode),
and ``custom_mode`` is ArduPlane's mode number (``ArduPlane/mode.h``, ``enum Number``).
Ground stations name modes from that pair: MAVProxy and QGroundControl with ArduPlane's
table, MAVSDK (4.x) with its ArduPlane mapping (MANUAL → Manual, STABILIZE → Stabilized,
AUTO → Mission, RTL → ReturnToLaunch, LOITER → Hold, GUIDED → Offboard; the others are
Unknown to MAVSDK's telemetry). They set a mode the ArduPilot way: SET_MODE or
MAV_CMD_DO_SET_MODE with ``custom_mode`` (MAVProxy's ``mode RTL``, MAVSDK's ``hold()``,
``return_to_launch()``, ``start_mission()``).

Why not the standard modes protocol (AVAILABLE_MODES, MAV_STANDARD_MODE): MAVProxy 1.8.75 and
MAVSDK 4.1.0 do not name modes from it, and QGroundControl only for PX4 builds that send it;
ArduPlane's numbers are understood by all three.
"""

from __future__ import annotations

from types import MappingProxyType

# ArduPlane's numbers (ArduPlane/mode.h) of the modes this vehicle flies.
MANUAL = 0
CIRCLE = 1
STABILIZE = 2
FLY_BY_WIRE_A = 5
CRUISE = 7
AUTO = 10
RTL = 11
LOITER = 12
GUIDED = 15

MODE_NAMES = MappingProxyType({
    MANUAL: "MANUAL", CIRCLE: "CIRCLE", STABILIZE: "STABILIZE", FLY_BY_WIRE_A: "FBWA",
    CRUISE: "CRUISE", AUTO: "AUTO", RTL: "RTL", LOITER: "LOITER", GUIDED: "GUIDED",
})
MODE_NUMBERS = MappingProxyType({name: number for number, name in MODE_NAMES.items()})

# Modes in which MANUAL_CONTROL moves the aircraft (sticks on surfaces or on attitude).
STICK_MODES = frozenset({MANUAL, STABILIZE, FLY_BY_WIRE_A})
# Modes that navigate on their own (MAV_MODE_FLAG_GUIDED_ENABLED / AUTO_ENABLED).
GUIDED_MODES = frozenset({GUIDED, LOITER, RTL, CIRCLE})
AUTO_MODES = frozenset({AUTO})

# MAV_MODE_FLAG bits (MAVLink common.xml), so that the vehicle side needs no codec.
FLAG_CUSTOM_MODE_ENABLED = 1
FLAG_AUTO_ENABLED = 4
FLAG_GUIDED_ENABLED = 8
FLAG_STABILIZE_ENABLED = 16
FLAG_MANUAL_INPUT_ENABLED = 64
FLAG_SAFETY_ARMED = 128


def mode_name(number: int) -> str:
    """ArduPlane's name of ``number``, or ``MODE(n)`` for one this vehicle does not fly."""
    return MODE_NAMES.get(int(number), f"MODE({int(number)})")


def base_mode(number: int, armed: bool) -> int:
    """HEARTBEAT ``base_mode`` for the custom mode ``number``."""
    flags = FLAG_CUSTOM_MODE_ENABLED
    if armed:
        flags |= FLAG_SAFETY_ARMED
    if number != MANUAL:
        flags |= FLAG_STABILIZE_ENABLED
    if number in STICK_MODES:
        flags |= FLAG_MANUAL_INPUT_ENABLED
    if number in GUIDED_MODES:
        flags |= FLAG_GUIDED_ENABLED
    if number in AUTO_MODES:
        flags |= FLAG_AUTO_ENABLED
    return flags
