"""How many fixed physics steps one ArduPilot JSON frame advances (ArduPilot's frame rate).

ArduPilot SITL tells its JSON physics the rate it runs at in every servo packet's
``frame_rate`` field [Hz]; the physics here steps at a fixed rate (the co-simulation's
1/960 s), so a frame advances k of its steps and the reply's timestamp k·dt: ArduPilot's
clock adopts 1/Δtimestamp = 1/(k·dt) as its rate. This module decides k; it imports nothing
of the co-simulation.

What ArduPilot sends (ArduPilot master, ``libraries/SITL/SIM_JSON.cpp`` and
``SIM_Aircraft.cpp``/``.h``): ``frame_rate`` is its ``rate_hz`` truncated to uint16.
``rate_hz`` starts at 1200 Hz; every reply sets it to 1/Δtimestamp (``JSON::recv_fdm``,
``adjust_frame_time``) and ``JSON::update`` then moves it by at most 1 Hz towards
``SIM_RATE_HZ`` (its parameter, default 1200 in SITL: ``libraries/SITL/SITL.cpp``). So a
live ArduPilot reports the rate our timestamps set, ±1 Hz (±2 with the truncation), the sign
saying on which side its SIM_RATE_HZ lies; a client that reports a fixed rate (the stand-in
in ``tests/ardupilot_standin.py``, another JSON client) reports that rate itself.

:class:`FrameRate` rules, per frame (``frame_rate_hz`` = r, the current rate R = 1/(k·dt)):

* r within :data:`NUDGE_BAND_HZ` of R (ArduPilot's ±1 Hz nudge): r < R − 0.5 Hz (its
  SIM_RATE_HZ is lower) → k + 1; r > R + 0.5 Hz (higher) → k − 1 (if k > 1) and k is then
  *settled*: no more k + 1 from a nudge until a reset (SIM_RATE_HZ lies between two of our
  rates, 960/k and 960/(k−1); without this the two nudges would alternate every frame).
  SIM_RATE_HZ = 240 is reached in three frames (960 → 480 → 320 → 240 Hz), 1200 stays
  at k = 1 (960 Hz, the step's own rate: the fastest there is);
* any other r in [:data:`MIN_FRAME_RATE_HZ`, :data:`MAX_FRAME_RATE_HZ`]: a direct request,
  k = max(1, ⌊R_physics/r + ½⌋) (1200 → 1, 960 → 1, 480 → 2, 240 → 4), not settled;
* r = 0 (ArduPilot never sends it: its rate_hz is never below 1/Δt − 1): k is kept;
* r > :data:`MAX_FRAME_RATE_HZ`: k = 1 (what rounding gives for any r above 1.5 × 960 Hz);
* 0 < r < :data:`MIN_FRAME_RATE_HZ`: clamped to the largest k whose rate is at least
  MIN_FRAME_RATE_HZ (19 at 960 Hz: 50.5 Hz).

Each change of k is reported (INFO) with the rate behind it, and each frame rate out of range
(WARNING) when it first appears and again whenever the reported rate changes: never silent.
A change of SIM_RATE_HZ in flight is followed by the nudges (one step of k per frame) unless
k has settled, which only a reset (ArduPilot restarted) lifts.
"""

from __future__ import annotations

import math

# ArduPlane's main loop: SCHED_LOOP_RATE default 50 Hz for planes, and AP_Scheduler raises
# any lower setting to 50 (libraries/AP_Scheduler/AP_Scheduler.cpp,
# SCHEDULER_DEFAULT_LOOP_RATE and AP_Scheduler::init). Frames slower than the autopilot's
# own loop would hand it the same IMU sample on consecutive loops.
MIN_FRAME_RATE_HZ = 50
# DEFINITION: no SITL runs its physics faster than this [Hz]; above it the field is taken
# for garbage (ArduPilot's default is 1200, the copter examples use up to 2000-4000).
MAX_FRAME_RATE_HZ = 10_000
# ArduPilot's nudge is at most 1 Hz (JSON::update, constrain_float(SIM_RATE_HZ, rate_hz - 1,
# rate_hz + 1)) and the uint16 truncation of rate_hz takes up to 1 Hz more; 0.5 Hz margin.
NUDGE_BAND_HZ = 2.5
NUDGE_DEAD_HZ = 0.5  # |r − R| at or under this is ArduPilot at our rate: no nudge


class FrameRate:
    """The steps per frame k (module docstring) for a physics of step ``dt_s`` [s].

    :meth:`steps` takes each new frame's ``frame_rate_hz`` and returns k with an event
    (level, text) or None; :meth:`reset` starts again at k = 1 (ArduPilot restarted).
    """

    def __init__(self, dt_s: float) -> None:
        if not (math.isfinite(dt_s) and dt_s > 0.0):
            raise ValueError(f"physics step must be > 0 s, got {dt_s!r}")
        self.physics_rate_hz = 1.0 / dt_s
        # the largest k whose rate 1/(k·dt) is still >= MIN_FRAME_RATE_HZ
        self.max_k = max(1, math.floor(self.physics_rate_hz / MIN_FRAME_RATE_HZ + 1e-9))
        self.reset()

    def reset(self) -> None:
        """k = 1, not settled, no rate seen."""
        self.k = 1
        self.settled = False
        self._last_rate: int | None = None

    @property
    def rate_hz(self) -> float:
        """The frame rate k gives [Hz]: 1/(k·dt)."""
        return self.physics_rate_hz / self.k

    def direct_k(self, frame_rate_hz: int) -> int:
        """k for a rate requested as it is: the nearest whole number of steps (halves up),
        clamped to 1..:attr:`max_k`."""
        return min(self.max_k, max(1, math.floor(self.physics_rate_hz / frame_rate_hz + 0.5)))

    def steps(self, frame_rate_hz: int) -> tuple[int, tuple[str, str] | None]:
        """k for this frame and the event to report (or None)."""
        r = frame_rate_hz
        changed = r != self._last_rate
        self._last_rate = r
        k0, rate0 = self.k, self.rate_hz
        warning = None
        if r == 0:
            if changed:
                warning = (f"ArduPilot's frame rate is 0 Hz (not a rate): keeping {k0} "
                           f"step(s) of {1e3 / self.physics_rate_hz:.4g} ms per frame")
            return k0, None if warning is None else ("WARNING", warning)
        off = r - rate0
        if abs(off) <= NUDGE_BAND_HZ and abs(off) > NUDGE_DEAD_HZ:
            if off < 0.0 and not self.settled and k0 < self.max_k:
                self.k = k0 + 1
            elif off > 0.0 and k0 > 1:
                self.k = k0 - 1
                self.settled = True
        elif abs(off) > NUDGE_BAND_HZ:
            self.k = self.direct_k(r)
            self.settled = False
        if changed and r > MAX_FRAME_RATE_HZ:
            warning = (f"ArduPilot's frame rate {r} Hz is above {MAX_FRAME_RATE_HZ} Hz: "
                       f"taken as {self.rate_hz:.4g} Hz ({self.k} step(s) per frame)")
        elif changed and r < MIN_FRAME_RATE_HZ:
            warning = (f"ArduPilot's frame rate {r} Hz is below ArduPlane's loop rate "
                       f"({MIN_FRAME_RATE_HZ} Hz): clamped to {self.rate_hz:.4g} Hz "
                       f"({self.k} steps per frame)")
        if warning is not None:
            return self.k, ("WARNING", warning)
        if self.k != k0:
            return self.k, ("INFO", f"ArduPilot's frame rate {r} Hz: {self.k} step(s) of "
                            f"{1e3 / self.physics_rate_hz:.4g} ms per frame, "
                            f"{self.rate_hz:.4g} Hz (was {k0}, {rate0:.4g} Hz)")
        return self.k, None
