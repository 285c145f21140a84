"""The MAVLink mission protocol of the SITL vehicle (https://mavlink.io/en/services/mission.html).

Upload (MISSION_COUNT → MISSION_REQUEST_INT × n → MISSION_ITEM_INT × n → MISSION_ACK),
download (MISSION_REQUEST_LIST → MISSION_COUNT → MISSION_REQUEST_INT/MISSION_REQUEST →
MISSION_ITEM_INT/MISSION_ITEM → MISSION_ACK), MISSION_CLEAR_ALL, MISSION_SET_CURRENT. One
transfer at a time, with the partner (system, component) that began it; items are requested
again after :data:`RETRY_S` of silence, up to :data:`RETRIES` times, then the upload is
abandoned (MISSION_ACK MAV_MISSION_OPERATION_CANCELLED) and the vehicle's mission is left as
it was. Only ``mission_type`` MISSION is stored: fence and rally lists download empty and
their uploads are answered MAV_MISSION_UNSUPPORTED.

ArduPilot's convention (the vehicle presents itself as ArduPlane): item 0 is the home
position — uploaded by ground stations, ignored in flight, downloaded as the current home.

Validation at upload (the ACK's result): the frames of :data:`FRAMES`, the commands of
:data:`NAV_COMMANDS` and :data:`DO_COMMANDS`; latitudes within ±90°, longitudes within ±180°;
anything else is rejected with MAV_MISSION_UNSUPPORTED_FRAME, MAV_MISSION_UNSUPPORTED or
MAV_MISSION_INVALID_PARAM5_X / PARAM6_Y, naming the item in a STATUSTEXT; the vehicle then
checks altitudes, radii, turns, times and speeds against its ranges (``item_problem``,
MAV_MISSION_INVALID_PARAMn naming the field and the range).

Not an upload: an item with ``current`` = 2 is ArduPilot's guided "fly to" (GUIDED to its
position and altitude), ``current`` = 3 changes the altitude only; either is answered by one
MISSION_ACK (ACCEPTED, or DENIED with a STATUSTEXT giving the reason).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

from pymavlink.dialects.v20 import common as M

RETRY_S = 0.5  # wall seconds before an item is requested again
RETRIES = 5
MAX_ITEMS = 500

# frames: global AMSL, relative to home, above terrain (the flat ground at home's
# elevation: the same as relative), and the frame of commands without a position
FRAMES = frozenset({
    M.MAV_FRAME_GLOBAL, M.MAV_FRAME_GLOBAL_INT, M.MAV_FRAME_GLOBAL_RELATIVE_ALT,
    M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, M.MAV_FRAME_GLOBAL_TERRAIN_ALT,
    M.MAV_FRAME_GLOBAL_TERRAIN_ALT_INT, M.MAV_FRAME_MISSION,
})
AMSL_FRAMES = frozenset({M.MAV_FRAME_GLOBAL, M.MAV_FRAME_GLOBAL_INT})
RELATIVE_FRAMES = FRAMES - AMSL_FRAMES - {M.MAV_FRAME_MISSION}
INVALID_PARAM = {1: M.MAV_MISSION_INVALID_PARAM1, 2: M.MAV_MISSION_INVALID_PARAM2,
                 3: M.MAV_MISSION_INVALID_PARAM3, 4: M.MAV_MISSION_INVALID_PARAM4}
INVALID_PARAM7 = M.MAV_MISSION_INVALID_PARAM7
# MISSION_ITEM(_INT) ``current`` values that are not uploads (ArduPilot's convention, which
# MAVProxy's ``guided`` uses with guided_use_reposition off): 2 fly there in GUIDED, 3 change
# the altitude only
GUIDED_CURRENT = 2
ALTITUDE_CURRENT = 3
NAV_WAYPOINT = M.MAV_CMD_NAV_WAYPOINT
NAV_LOITER_UNLIM = M.MAV_CMD_NAV_LOITER_UNLIM
NAV_LOITER_TURNS = M.MAV_CMD_NAV_LOITER_TURNS
NAV_LOITER_TIME = M.MAV_CMD_NAV_LOITER_TIME
NAV_RETURN_TO_LAUNCH = M.MAV_CMD_NAV_RETURN_TO_LAUNCH
NAV_TAKEOFF = M.MAV_CMD_NAV_TAKEOFF
DO_CHANGE_SPEED = M.MAV_CMD_DO_CHANGE_SPEED
NAV_COMMANDS = frozenset({NAV_WAYPOINT, NAV_LOITER_UNLIM, NAV_LOITER_TURNS, NAV_LOITER_TIME,
                          NAV_RETURN_TO_LAUNCH, NAV_TAKEOFF})
DO_COMMANDS = frozenset({DO_CHANGE_SPEED})


@dataclass(frozen=True)
class MissionItem:
    """One item as MISSION_ITEM_INT carries it: x, y latitude/longitude [degE7], z altitude
    [m] in ``frame``."""

    seq: int
    frame: int
    command: int
    current: int = 0
    autocontinue: int = 1
    param1: float = 0.0
    param2: float = 0.0
    param3: float = 0.0
    param4: float = 0.0
    x: int = 0
    y: int = 0
    z: float = 0.0

    @property
    def lat_rad(self) -> float:
        return math.radians(self.x * 1e-7)

    @property
    def lon_rad(self) -> float:
        return math.radians(self.y * 1e-7)

    @property
    def has_position(self) -> bool:
        return self.command in NAV_COMMANDS and self.command not in (NAV_RETURN_TO_LAUNCH,
                                                                     NAV_TAKEOFF)


def check_item(item: MissionItem) -> tuple[int, str] | None:
    """(MAV_MISSION_RESULT, reason) when ``item`` cannot be flown; None when it can."""
    if item.command not in NAV_COMMANDS | DO_COMMANDS:
        return M.MAV_MISSION_UNSUPPORTED, f"item {item.seq}: command {item.command} unsupported"
    if item.frame not in FRAMES:
        return (M.MAV_MISSION_UNSUPPORTED_FRAME,
                f"item {item.seq}: frame {item.frame} unsupported")
    if item.has_position or item.seq == 0:
        if not -90e7 <= item.x <= 90e7:
            return M.MAV_MISSION_INVALID_PARAM5_X, f"item {item.seq}: latitude out of range"
        if not -180e7 <= item.y <= 180e7:
            return M.MAV_MISSION_INVALID_PARAM6_Y, f"item {item.seq}: longitude out of range"
        if not math.isfinite(item.z):
            return M.MAV_MISSION_INVALID_PARAM7, f"item {item.seq}: altitude not finite"
    return None


def item_from_message(msg) -> MissionItem:
    """A MISSION_ITEM_INT, or a legacy MISSION_ITEM (float degrees), as a MissionItem (a
    legacy latitude/longitude that is not finite, or beyond the int32 range of degE7,
    becomes a value :func:`check_item` rejects)."""
    if msg.get_type() == "MISSION_ITEM":
        x, y = (_deg_e7(float(v)) for v in (msg.x, msg.y))
    else:
        x, y = int(msg.x), int(msg.y)
    return MissionItem(int(msg.seq), int(msg.frame), int(msg.command), int(msg.current),
                       int(msg.autocontinue), float(msg.param1), float(msg.param2),
                       float(msg.param3), float(msg.param4), x, y, float(msg.z))


def _deg_e7(deg: float) -> int:
    """Degrees as degE7, out-of-range (or NaN) values clamped to beyond ±180° (rejected)."""
    if not math.isfinite(deg) or abs(deg) > 200.0:
        return 2_000_000_001 if not deg < 0 else -2_000_000_001
    return int(round(deg * 1e7))


class MissionProtocol:
    """The vehicle's side of the mission protocol, serviced by the link.

    ``send(msg)`` sends a message built with ``mav`` (the link's encoder); ``vehicle`` has
    ``mission_items()`` (the stored list), ``set_mission(items)`` (returns None or a
    one-line reason for rejecting it), ``set_mission_current(seq)`` (None or a reason),
    ``item_problem(item)`` ((MAV_MISSION_RESULT, reason) or None: the check of each item
    uploaded), ``guided_item(item)`` (None or a reason: an item with ``current`` 2 or 3,
    answered by a MISSION_ACK), ``refusals`` (a count) and ``status(severity, text)``.
    """

    def __init__(self, mav, send: Callable[[object], None], vehicle) -> None:
        self._mav, self._send, self.vehicle = mav, send, vehicle
        self._up: dict | None = None  # upload in progress
        self._down: tuple[int, int] | None = None  # download partner

    def handle(self, msg, t: str) -> bool:
        """Handle ``msg`` (type ``t``) if it belongs to the mission protocol."""
        src = (msg.get_srcSystem(), msg.get_srcComponent())
        mtype = getattr(msg, "mission_type", M.MAV_MISSION_TYPE_MISSION)
        if t == "MISSION_COUNT":
            if mtype != M.MAV_MISSION_TYPE_MISSION:
                self._ack(src, M.MAV_MISSION_UNSUPPORTED, mtype)
            elif msg.count > MAX_ITEMS:
                self._ack(src, M.MAV_MISSION_NO_SPACE, mtype)
            elif msg.count == 0:
                self._up = None
                self._finish_upload(src, [])
            else:
                self._up = {"src": src, "n": int(msg.count), "items": [], "tries": 0,
                            "asked": 0.0, "int": True}
                self._request(0)
        elif t in ("MISSION_ITEM_INT", "MISSION_ITEM") and msg.current in (GUIDED_CURRENT,
                                                                          ALTITUDE_CURRENT):
            if mtype != M.MAV_MISSION_TYPE_MISSION:
                self._ack(src, M.MAV_MISSION_UNSUPPORTED, mtype)
                return True
            reason = self.vehicle.guided_item(item_from_message(msg))
            if reason is not None:
                self.refuse(reason)
            self._ack(src, M.MAV_MISSION_ACCEPTED if reason is None else M.MAV_MISSION_DENIED,
                      mtype)
        elif t in ("MISSION_ITEM_INT", "MISSION_ITEM"):
            up = self._up
            if up is None or up["src"] != src or mtype != M.MAV_MISSION_TYPE_MISSION:
                return True
            k = len(up["items"])
            if msg.seq != k:
                self._request(k)  # out of order or repeated: ask again for the one wanted
                return True
            up["int"] = t == "MISSION_ITEM_INT"
            item = item_from_message(msg)
            bad = None if k == 0 else self.vehicle.item_problem(item)
            if bad is not None:
                self._up = None
                self.refuse(f"Mission rejected: {bad[1]}")
                self._ack(src, bad[0], mtype)
                return True
            up["items"].append(item)
            if len(up["items"]) == up["n"]:
                self._up = None
                self._finish_upload(src, up["items"])
            else:
                up["tries"] = 0
                self._request(len(up["items"]))
        elif t == "MISSION_REQUEST_LIST":
            items = self.vehicle.mission_items() if mtype == M.MAV_MISSION_TYPE_MISSION else []
            self._down = src
            self._send(self._mav.mission_count_encode(src[0], src[1], len(items), mtype))
        elif t in ("MISSION_REQUEST_INT", "MISSION_REQUEST"):
            items = self.vehicle.mission_items() if mtype == M.MAV_MISSION_TYPE_MISSION else []
            if 0 <= msg.seq < len(items):
                self._send_item(src, items[msg.seq], t == "MISSION_REQUEST_INT", mtype)
            else:
                self._ack(src, M.MAV_MISSION_INVALID_SEQUENCE, mtype)
        elif t == "MISSION_CLEAR_ALL":
            if mtype == M.MAV_MISSION_TYPE_MISSION:
                reason = self.vehicle.set_mission([])
                self._ack(src, M.MAV_MISSION_ACCEPTED if reason is None else M.MAV_MISSION_DENIED,
                          mtype)
            else:
                self._ack(src, M.MAV_MISSION_ACCEPTED, mtype)
        elif t == "MISSION_SET_CURRENT":
            reason = self.vehicle.set_mission_current(int(msg.seq))
            if reason is not None:
                self.refuse(reason)
        elif t == "MISSION_ACK":
            if self._down == src:
                self._down = None
        else:
            return False
        return True

    def refuse(self, text: str) -> None:
        """A refusal: STATUSTEXT WARNING (queued by the vehicle) and an event of the log."""
        self.vehicle.status(4, text)
        self.vehicle.refusals += 1

    def service(self, now: float | None = None) -> None:
        """Re-request the awaited item of an upload that went quiet; give up after RETRIES."""
        up = self._up
        if up is None:
            return
        now = time.monotonic() if now is None else now
        if now - up["asked"] >= RETRY_S:
            if up["tries"] >= RETRIES:
                self._up = None
                self.vehicle.status(4, "Mission upload timed out")
                self._ack(up["src"], M.MAV_MISSION_OPERATION_CANCELLED,
                          M.MAV_MISSION_TYPE_MISSION)
                return
            up["tries"] += 1
            self._request(len(up["items"]))

    def _request(self, seq: int) -> None:
        up = self._up
        up["asked"] = time.monotonic()
        s, c = up["src"]
        if up["int"]:
            msg = self._mav.mission_request_int_encode(s, c, seq, M.MAV_MISSION_TYPE_MISSION)
        else:
            msg = self._mav.mission_request_encode(s, c, seq, M.MAV_MISSION_TYPE_MISSION)
        self._send(msg)

    def _finish_upload(self, src, items: list[MissionItem]) -> None:
        reason = self.vehicle.set_mission(items)
        if reason is None:
            self._ack(src, M.MAV_MISSION_ACCEPTED, M.MAV_MISSION_TYPE_MISSION)
            self.vehicle.status(6, f"Mission: {max(0, len(items) - 1)} items received")
        else:
            self.refuse(f"Mission rejected: {reason}")
            self._ack(src, M.MAV_MISSION_ERROR, M.MAV_MISSION_TYPE_MISSION)

    def _ack(self, src, result: int, mtype: int) -> None:
        self._send(self._mav.mission_ack_encode(src[0], src[1], result, mtype))

    def _send_item(self, src, it: MissionItem, as_int: bool, mtype: int) -> None:
        if as_int:
            msg = self._mav.mission_item_int_encode(
                src[0], src[1], it.seq, it.frame, it.command, it.current, it.autocontinue,
                it.param1, it.param2, it.param3, it.param4, it.x, it.y, it.z, mtype)
        else:
            msg = self._mav.mission_item_encode(
                src[0], src[1], it.seq, it.frame, it.command, it.current, it.autocontinue,
                it.param1, it.param2, it.param3, it.param4, it.x * 1e-7, it.y * 1e-7, it.z,
                mtype)
        self._send(msg)
