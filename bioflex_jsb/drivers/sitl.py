"""The SITL loop: the one coupled step paced to the wall clock.

The one coupled step (:class:`~bioflex_jsb.runtime.coupled_step.CoupledStep`), on the
``bioflex_sitl`` aircraft, whose autopilot (``systems/bioflex_autopilot.xml``, see
:mod:`bioflex_jsb.generators.autopilot`) keeps it flying level on its own, for as long as
asked (or until stopped).

Pacing: step k is due at wall time W_0 + (t_k − t_0)/speedup. The loop sleeps until a step is
due and runs late steps at once (catch-up); the *pacing error* of a step is its start minus
its due time [s] (:class:`PacingStats`; ``sitl_p99_ms`` in ``bioflex-jsb bench``). A loop
more than :data:`RESYNC_S` behind (a stall: debugger, swapped-out process) starts a new
schedule from now instead of racing to catch up; the number of such resyncs is reported.
Changing the time scale (parameter ``SIM_SPEEDUP``) starts a new schedule too.

The MAVLink link (:mod:`bioflex_jsb.links.mavlink`) is serviced every
:data:`LINK_PERIOD_S` of simulated time (≥ 50 Hz of wall time up to a speed-up of 4); its
reads are bounded per call, so a flood costs at most a fixed time per call.

Parameters a ground station sees (:class:`SitlParameters`, all REAL32 in MAVLink):

=============== =========================================================================
AP_ENABLE       1: autopilot engaged (altitude and heading hold); 0: controls at trim
AP_LOITER       1: loiter circle at a fixed bank instead of heading hold
AP_ALT_M        altitude held [m above sea level]
AP_HDG_RAD      heading held [rad, from north, clockwise]
GUST_AMP_MS     peak of the 1-cosine vertical gust [m/s, up]
GUST_LEN_M      length of that gust [m]
GUST_TRIG       write 1: the gust starts now; reads 1 while it blows, then 0
WING_COUPLED    1: the elastic wing's modal loads act (coupled); 0: rigid wing
SIM_SPEEDUP     simulated seconds per wall-clock second
=============== =========================================================================
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.generators.autopilot import SITL_AIRCRAFT
from bioflex_jsb.links.mavlink import VehicleState
from bioflex_jsb.runtime.coupled_step import CoupledStep
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import GustField, GustSpecError, parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S

LINK_PERIOD_S = 1.0 / 200.0  # simulated time between link services [s]
RESYNC_S = 0.25  # a loop this far behind its schedule starts a new one [s]
SLEEP_MARGIN_S = 50e-6  # steps due within this are started at once (sleep overshoot)
MANUAL_TIMEOUT_S = 1.0  # manual input older than this [wall s] gives control back
SPEEDUP_RANGE = (0.1, 50.0)


@dataclass
class PacingStats:
    """Step start minus due time [s] of every paced step, and the resyncs."""

    errors_s: list[float] = field(default_factory=list)
    resyncs: int = 0

    def percentile_ms(self, q: float) -> float:
        if not self.errors_s:
            return math.nan
        return float(np.percentile(np.abs(np.asarray(self.errors_s)), q) * 1e3)

    def summary(self) -> dict[str, float]:
        return {"p50_ms": self.percentile_ms(50), "p99_ms": self.percentile_ms(99),
                "max_ms": self.percentile_ms(100), "steps": len(self.errors_s),
                "resyncs": self.resyncs}


class SitlParameters:
    """The parameter set of the module docstring; ``set`` applies to the running sim."""

    names = ("AP_ENABLE", "AP_LOITER", "AP_ALT_M", "AP_HDG_RAD", "GUST_AMP_MS", "GUST_LEN_M",
             "GUST_TRIG", "WING_COUPLED", "SIM_SPEEDUP")

    def __init__(self, sim: SitlSim) -> None:
        self._sim = sim

    def get(self, name: str) -> float:
        s = self._sim
        return float({
            "AP_ENABLE": s.airframe["ap/engage"],
            "AP_LOITER": s.airframe["ap/loiter"],
            "AP_ALT_M": s.airframe["ap/altitude-hold-m"],
            "AP_HDG_RAD": s.airframe["ap/heading-hold-rad"],
            "GUST_AMP_MS": s.gust_amplitude_m_s,
            "GUST_LEN_M": s.gust_length_m,
            "GUST_TRIG": 1.0 if s.gust_active else 0.0,
            "WING_COUPLED": 1.0 if s.wing.model == "coupled" else 0.0,
            "SIM_SPEEDUP": s.speedup,
        }[name])

    def set(self, name: str, value: float) -> float:
        s = self._sim
        if not math.isfinite(value):
            raise ValueError(f"{name}: not a finite number")
        if name in ("AP_ENABLE", "AP_LOITER", "WING_COUPLED", "GUST_TRIG"):
            if value not in (0.0, 1.0):
                raise ValueError(f"{name} must be 0 or 1")
        if name == "AP_ENABLE":
            s.airframe["ap/engage"] = value
        elif name == "AP_LOITER":
            s.airframe["ap/loiter"] = value
        elif name == "AP_ALT_M":
            lo, hi = s.altitude_hold_range_m
            if not lo <= value <= hi:
                raise ValueError(f"AP_ALT_M must be in {lo:g}..{hi:g} m")
            s.airframe["ap/altitude-hold-m"] = value
        elif name == "AP_HDG_RAD":
            s.airframe["ap/heading-hold-rad"] = math.remainder(value, 2.0 * math.pi)
        elif name == "GUST_AMP_MS":
            if abs(value) > 5.0:
                raise ValueError("GUST_AMP_MS must be within ±5 m/s")
            s.gust_amplitude_m_s = value
        elif name == "GUST_LEN_M":
            if not 1.0 <= value <= 500.0:
                raise ValueError("GUST_LEN_M must be in 1..500 m")
            s.gust_length_m = value
        elif name == "GUST_TRIG":
            if value == 1.0:
                s.trigger_gust()
        elif name == "WING_COUPLED":
            s.set_wing_model("coupled" if value == 1.0 else "rigid")
        elif name == "SIM_SPEEDUP":
            lo, hi = SPEEDUP_RANGE
            if not lo <= value <= hi:
                raise ValueError(f"SIM_SPEEDUP must be in {lo:g}..{hi:g}")
            s.speedup = value
            s.resync = True
        else:
            raise KeyError(name)
        return self.get(name)


class SitlSim:
    """The co-simulation state between steps: the one coupled step (airframe trimmed,
    autopilot engaged, modal wing) and the gust in progress."""

    def __init__(self, wing_model, modes, model: str = "coupled", speed_m_s: float = 15.0,
                 altitude_m: float = 0.0, dt_s: float = DEFAULT_DT_S, speedup: float = 1.0,
                 airframe: Airframe | None = None) -> None:
        self.airframe = airframe or Airframe(aircraft=SITL_AIRCRAFT)
        a = self.airframe

        def disengage(af: Airframe) -> None:
            af["ap/engage"] = 0.0  # the trim and the RPM settling see no autopilot

        self.core = CoupledStep(a, wing_model, model, speed_m_s, altitude_m, dt_s,
                                before_trim=disengage)
        core = self.core
        self.trim = core.trim
        self.speed_m_s = speed_m_s
        self.dt_s = core.dt_s
        self.speedup = float(speedup)
        self.resync = False
        self._get = core.get
        self.wing = core.wing
        self.n_modes = core.n_modes
        twist = np.asarray(modes.twist_rad, dtype=float)
        tip = int(np.argmax(np.abs(np.asarray(modes.stations_m, dtype=float))))
        self._tip_twist_per_mode = np.abs(twist[:, tip]) / np.max(np.abs(twist), axis=1)
        self.h0_m = self._get["h"]() * U.M_PER_FT
        self.altitude_hold_range_m = (self.h0_m - 250.0, self.h0_m + 1000.0)
        a["ap/theta-trim-rad"] = self.trim.theta_rad
        a["ap/altitude-hold-m"] = self.h0_m
        a["ap/heading-hold-rad"] = self._get["psi"]()
        a["ap/engage"] = 1.0
        self.gust_amplitude_m_s = 1.0
        self.gust_length_m = 30.0
        self._gust: GustField | None = None
        self._gust_start_k = 0
        self._gust_end_s = 0.0
        self.units = core.units
        self.names = list(core.names)
        self._manual_wall_s: float | None = None
        self.stopped: str | None = None
        core.prepare(0.0)
        self._state = core.sense(0.0)

    @property
    def k(self) -> int:
        """Steps flown."""
        return self.core.k

    @property
    def t_s(self) -> float:
        """Simulated time now [s]."""
        return self.core.k * self.dt_s

    # -- commands from the link -------------------------------------------------------------
    @property
    def gust_active(self) -> bool:
        return self._gust is not None and self.t_s < self._gust_end_s

    def trigger_gust(self) -> None:
        """Start the 1-cosine gust (GUST_AMP_MS, GUST_LEN_M) now."""
        if self.gust_amplitude_m_s == 0.0:
            return
        try:
            spec = parse_gust(f"1cos:{self.gust_amplitude_m_s!r}:{self.gust_length_m!r}")
        except GustSpecError as exc:
            raise ValueError(str(exc)) from None
        # the gust's own clock starts at this step (step 0 of the field)
        self._gust = GustField(spec, self.speed_m_s, 0.0, 60.0, self.dt_s)
        self._gust_start_k = self.k
        self._gust_end_s = self.t_s + self.gust_length_m / self.speed_m_s

    def set_wing_model(self, model: str) -> None:
        self.core.set_model(model)

    def manual(self, pitch: float | None, roll: float | None) -> None:
        """Stick increments on the trim (−1..1; pitch + = nose down), or None: release."""
        a = self.airframe
        if pitch is None or roll is None:
            a["ap/manual"] = 0.0
            self._manual_wall_s = None
            return
        a["ap/manual-elevator-norm"] = pitch
        a["ap/manual-aileron-norm"] = roll
        a["ap/manual"] = 1.0
        self._manual_wall_s = time.monotonic()

    # -- the step -----------------------------------------------------------------------
    def step(self) -> tuple:
        """One co-simulation step (the one coupled step); returns the logged row's values
        (in ``self.names`` order) and sets ``self.stopped`` when the run left its valid
        range."""
        core = self.core
        values = core.advance(self._w_g(core.k))
        self._state = None  # the snapshot of t_k+1 is read when asked for (vehicle_state)
        self.stopped = core.stopped
        if self._manual_wall_s is not None and \
                time.monotonic() - self._manual_wall_s > MANUAL_TIMEOUT_S:
            self.manual(None, None)
        return values

    def _w_g(self, k: int) -> float:
        """The gust [m/s, up] at step ``k``."""
        gust = self._gust
        return gust.at_step(k - self._gust_start_k) if gust is not None else 0.0

    def vehicle_state(self) -> VehicleState:
        """The vehicle now (t_k, k steps flown), with the flow of this step's gust."""
        get, a = self._get, self.airframe
        if self._state is None:
            self._state = self.core.sense(self._w_g(self.core.k))
        h = get["h"]() * U.M_PER_FT
        eta = self.core.eta
        named = {f"eta{i + 1}": float(eta[i]) for i in range(min(3, self.n_modes))}
        named["tip_twist"] = float(np.asarray(self._tip_twist_per_mode) @ eta)
        return VehicleState(
            time_s=self.t_s, roll_rad=self._state.phi_rad, pitch_rad=self._state.theta_rad,
            yaw_rad=get["psi"](),
            p_rad_s=get["p"](), q_rad_s=get["q"](), r_rad_s=get["r"](),
            latitude_rad=get["lat"](), longitude_rad=get["lon"](), altitude_m=h,
            relative_altitude_m=h - self.h0_m,
            v_north_m_s=get["vn"]() * U.M_PER_FT, v_east_m_s=get["ve"]() * U.M_PER_FT,
            v_down_m_s=get["vd"]() * U.M_PER_FT, airspeed_m_s=self._state.flow.airspeed_m_s,
            throttle=get["throttle"](), named=named,
            autopilot=a["ap/engage"] == 1.0, manual=a["ap/manual"] == 1.0,
        )


def run_paced(
    sim: SitlSim,
    duration_s: float | None,
    link=None,
    on_sample: Callable[[float, str, tuple], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    clock: Callable[[], float] = time.perf_counter,
    sleep: Callable[[float], None] = time.sleep,
    idle: Callable[[float], None] | None = None,
) -> PacingStats:
    """Fly ``sim`` paced to the wall clock for ``duration_s`` simulated seconds (None: until
    ``should_stop()`` or a stop of the run; Ctrl-C raises KeyboardInterrupt). ``link``: a
    :class:`~bioflex_jsb.links.mavlink.MavlinkLink`, serviced every LINK_PERIOD_S;
    ``on_sample(t_s, model, values)`` after every step (logging); ``idle(slack_s)`` when the
    next step is not due for ``slack_s`` [s] (a place for work that may wait, such as writing
    a log chunk, without delaying a step)."""
    stats = PacingStats()
    errors = stats.errors_s
    dt = sim.dt_s
    n_end = None if duration_s is None else sim.k + int(round(duration_s / dt))
    link_every = max(1, int(round(LINK_PERIOD_S / dt)))
    wall0, k0, speedup = clock(), sim.k, sim.speedup
    with sim.airframe.capturing():
        while n_end is None or sim.k < n_end:
            if sim.resync or sim.speedup != speedup:
                sim.resync = False
                wall0, k0, speedup = clock(), sim.k, sim.speedup
            due = wall0 + (sim.k - k0) * dt / speedup
            now = clock()
            if idle is not None and due - now > SLEEP_MARGIN_S:
                idle(due - now)
                now = clock()
            if due - now > SLEEP_MARGIN_S:
                sleep(due - now - SLEEP_MARGIN_S * 0.5)
                now = clock()
                while now < due - SLEEP_MARGIN_S:  # woke early: wait the rest
                    now = clock()
            late = now - due
            if late > RESYNC_S:
                stats.resyncs += 1
                wall0, k0 = now, sim.k
                late = 0.0
            errors.append(late)
            t = sim.t_s
            values = sim.step()
            if on_sample is not None:
                on_sample(t, sim.wing.model, values)
            if sim.stopped:
                break
            if link is not None and sim.k % link_every == 0:
                link.service(sim.vehicle_state())
            if should_stop is not None and sim.k % link_every == 0 and should_stop():
                break
    return stats


def measure_pacing(duration_s: float = 2.0, speedup: float = 1.0, wing: str = "optimised",
                   speed_m_s: float = 15.0, mavlink: str = "udpin:127.0.0.1:0") -> dict:
    """Pacing error of a real-time SITL run (for ``bioflex-jsb bench``: ``sitl_p50_ms``,
    ``sitl_p99_ms``): ``duration_s`` simulated seconds of the coupled wing at ``speedup``,
    with the MAVLink link serviced as in a session (default: listening on a loopback port,
    telemetry at its default rates, 50 Hz ATTITUDE). Returns :meth:`PacingStats.summary`
    ([ms] and counts) with ``dt_s`` and ``speedup``."""
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.links.mavlink import MavlinkLink

    build = build_wing(VARIANTS[wing])
    sim = SitlSim(build.model, build.modes, speed_m_s=speed_m_s, speedup=speedup)
    link = MavlinkLink(mavlink, SitlParameters(sim), sim.manual)
    try:
        stats = run_paced(sim, duration_s, link)
    finally:
        link.close()
    return {**stats.summary(), "dt_s": sim.dt_s, "speedup": speedup}
