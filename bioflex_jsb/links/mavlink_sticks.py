"""Sticks from a ground station: MANUAL_CONTROL and RC_CHANNELS_OVERRIDE.

Who steers: the first (system, component) that sends sticks, until it is silent for
:data:`CONTROLLER_TIMEOUT_S` [wall s]; the vehicle obeys sticks only in its stick modes
(MANUAL, STABILIZE, FBWA).

RC_CHANNELS_OVERRIDE, per channel (MAVLink common.xml, message 70): channels 1-8, UINT16_MAX
(65535) = ignore this field (the channel keeps its value), 0 = release it back to the RC
radio; channels 9-18, 0 or UINT16_MAX = ignore, UINT16_MAX − 1 (65534) = release. This
vehicle has no radio: a released channel is centred. Channel 1 is roll (+ right), channel 2
pitch (+ nose down, as MANUAL_CONTROL x), PWM 1000..2000 µs about 1500 (values out to
:data:`PWM_RANGE_US` are clipped to full deflection). Each channel is applied on its own
and the others keep their values: MAVProxy's ``rc 1 1800`` (channel 1 = 1800, the others 0:
released) rolls right with the
pitch centred. Channels 1 and 2 both released: the sticks are released (the autopilot's, as
MANUAL_CONTROL stopping). Channels 3-18 are not used (the autothrottle holds the airspeed).

Refused, each said once per :data:`REFUSAL_REPEAT_S` [wall s] (STATUSTEXT WARNING, and an
event of the session log through ``Vehicle.refused``), the override applied to nothing: a
value outside :data:`PWM_RANGE_US` (that channel only); sticks from a station that is not
the controlling one; sticks in a mode that takes none; values on channels 3-18.
"""

from __future__ import annotations

import time

CONTROLLER_TIMEOUT_S = 3.0  # the stick-controlling station's claim lapses after [wall s]
REFUSAL_REPEAT_S = 5.0  # the same refusal is said again after [wall s]
PWM_RANGE_US = (800, 2200)  # accepted PWM [µs]; 1000..2000 is full travel
IGNORE = 65535  # UINT16_MAX
RELEASE_1_8 = 0
RELEASE_9_18 = 65534
STICK_CHANNELS = (1, 2)  # roll, pitch


def _unit(pwm: int) -> float:
    return max(-1.0, min(1.0, (pwm - 1500) / 500.0))


class Sticks:
    """The link's stick input: the controlling station and the override channels in force
    (``link.statustext(severity, text)`` and ``vehicle`` as in the module docstring)."""

    def __init__(self, link, vehicle) -> None:
        self.link, self.vehicle = link, vehicle
        self.controller: tuple[int, int] | None = None
        self._controller_seen = 0.0
        self._rc: dict[int, int | None] = dict.fromkeys(STICK_CHANNELS)  # PWM, None released
        self._said: dict[str, float] = {}

    def refuse(self, key: str, text: str) -> None:
        """Say ``text`` (unless the refusal ``key`` was said within REFUSAL_REPEAT_S)."""
        now = time.monotonic()
        if now - self._said.get(key, -REFUSAL_REPEAT_S) < REFUSAL_REPEAT_S:
            return
        self._said[key] = now
        self.link.statustext(4, text)
        self.vehicle.refused(text)

    def may_steer(self, msg) -> bool:
        """Whether ``msg``'s station has the sticks (it takes them if nobody has)."""
        if self.vehicle is None:
            return False
        src, now = (msg.get_srcSystem(), msg.get_srcComponent()), time.monotonic()
        if self.controller is None or now - self._controller_seen > CONTROLLER_TIMEOUT_S:
            if src != self.controller:  # a new station: nothing of the last one's holds
                self._rc = dict.fromkeys(STICK_CHANNELS)
            self.controller = src
        if src != self.controller:
            self.refuse(f"other:{src}", f"Sticks from {src[0]}:{src[1]} ignored: "
                        f"{self.controller[0]}:{self.controller[1]} has them")
            return False
        self._controller_seen = now
        return True

    def _apply(self, pitch: float, roll: float) -> None:
        if not self.vehicle.manual(pitch, roll):
            mode = getattr(self.vehicle, "mode_name", "this mode")
            self.refuse(f"mode:{mode}", f"Sticks ignored in {mode}: only MANUAL, STABILIZE, "
                        "FBWA take them")

    def manual_control(self, msg) -> None:
        """MANUAL_CONTROL x (pitch, forward = nose down), y (roll), −1000..1000."""
        if self.may_steer(msg):
            self._apply(max(-1.0, min(1.0, msg.x / 1000.0)),
                        max(-1.0, min(1.0, msg.y / 1000.0)))

    def rc_override(self, msg) -> None:
        """RC_CHANNELS_OVERRIDE, channel by channel (module docstring)."""
        if not self.may_steer(msg):
            return
        lo, hi = PWM_RANGE_US
        for ch in STICK_CHANNELS:
            pwm = int(getattr(msg, f"chan{ch}_raw"))
            if pwm == IGNORE:
                continue
            if pwm == RELEASE_1_8:
                self._rc[ch] = None
            elif lo <= pwm <= hi:
                self._rc[ch] = pwm
            else:
                self.refuse(f"pwm:{ch}", f"RC override channel {ch}: {pwm} us outside "
                            f"{lo}..{hi} (0 release, 65535 ignore)")
        unused = [ch for ch in range(3, 19) if _holds_value(ch, getattr(msg, f"chan{ch}_raw",
                                                                        IGNORE))]
        if unused:
            self.refuse("unused", f"RC override channel {unused[0]}: not used (1 roll, "
                        "2 pitch; the autothrottle holds the airspeed)")
        roll, pitch = self._rc[1], self._rc[2]
        if roll is None and pitch is None:
            self.vehicle.manual(None, None)  # released: back to the autopilot
            self.controller = None
            return
        self._apply(_unit(pitch) if pitch is not None else 0.0,
                    _unit(roll) if roll is not None else 0.0)


def _holds_value(ch: int, pwm: int) -> bool:
    """Whether channel ``ch`` of an override carries a value (not ignore / release)."""
    if ch <= 8:
        return pwm not in (IGNORE, RELEASE_1_8)
    return pwm not in (0, IGNORE, RELEASE_9_18)
