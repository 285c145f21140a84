"""The co-simulation loop: JSBSim's rigid airframe with the Python modal wing, through a gust.

Per JSBSim step k (time t_k, airframe state x_k):

1. the gust w_g(t_k) is written to JSBSim's wind (``atmosphere/wind-down-fps`` = −w_g);
2. the airframe's state x_k is read in one snapshot (:func:`state_reader`: attitude, rates,
   position, velocities, n_z, controls) with the flow at the wing (α, β, V, Q against the
   air, q) computed from x_k and that wind, the same way JSBSim's FGAuxiliary computes it;
3. the wing advances η_k → η_{k+1} with that flow held over the step (exact discretisation,
   ``ModalWing``), and the loads of η_{k+1} in that flow go into ``external_reactions``
   (lift/drag turned from wind to body axes with α_k);
4. JSBSim runs one step: it integrates x_k → x_{k+1} and computes the forces of x_{k+1},
   which it applies over the next step — with the wing's loads of η_{k+1}, the same time, so
   the elastic loads do not lag the rigid aerodynamics; the row of t_k (the snapshot of 2,
   the loads of 3, η_k and η̇_k: :func:`row_values`) is stored and logged.

The Fig. 21 run is within 1 % NRMSE of the same run at a quarter of the step
(``tests/test_cosim.py``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.generators.airframe import alpha_peak_rad
from bioflex_jsb.parameters.airframe import POST_STALL
from bioflex_jsb.runtime.fdm import Airframe, TrimResult
from bioflex_jsb.simulation.gusts import GustField, GustSpec
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S, FlowState, ModalWing, TrimReference
from bioflex_jsb.simulation.results import TimeHistory

# A modal coordinate beyond this is outside the linear (small-twist) range of the model:
# the modes are normalised on twist, and at 0.52 rad (30°) of twist sin η differs from η by
# 4.5 %, the limit we accept for the small-angle kinematics behind Eq. (3).
ETA_LIMIT_RAD = 0.52
# The run stops when α leaves the airframe's aerodynamic tables (no data beyond). Between the
# lift peak and the table end JSBSim's post-stall model holds while the modal derivatives,
# linear in α, do not: that time is reported (``time_beyond_stall_s``), not stopped, so that
# a transient excursion past the lift peak (the paper's 3 m/s gust at 15 m/s reaches
# 13.1° against a 12.8° peak) is shown rather than hidden or fatal.
ALPHA_TABLE_RANGE_RAD = (POST_STALL.alpha_table_min_rad, POST_STALL.alpha_table_max_rad)


class Divergence(Exception):
    """The run left the model's valid range; the message names cause, time and mode."""


# JSBSim integrators for the run (FGPropagate; 3 = Adams-Bashforth 2 for the rates and the
# positions): JSBSim's default rectangular Euler for the rotational rate is first order and
# alone moves the pitch-rate peak of a sharp-edged gust by 1.3 % when the step is halved.
INTEGRATORS = {
    "simulation/integrator/rate/rotational": 3,
    "simulation/integrator/rate/translational": 3,
    "simulation/integrator/position/rotational": 3,
    "simulation/integrator/position/translational": 3,
}


@dataclass(frozen=True)
class RunSetup:
    """What a gust run needs: trim speed [m/s], gust, duration [s], gust start [s], altitude
    [m], co-simulation step [s]."""

    speed_m_s: float
    gust: GustSpec
    duration_s: float = 6.0
    gust_start_s: float = 0.5
    altitude_m: float = 0.0
    dt_s: float = DEFAULT_DT_S


class StepRecorder(Protocol):
    """Something that keeps a run's steps as they complete (an MCAP log), reading them from
    the run's own table rather than being handed each step's numbers.

    ``start`` is called once before the first step with the channel names, the times [s] of
    every step the run may take and the (steps × channels) table the run fills row by row
    (units: ``base_channels``); ``step(k)`` after row k is complete; ``stop(n)`` once at
    the end, however the run ends (finished, stopped, interrupted, failed), with the number
    of complete rows.
    """

    def start(self, names: tuple[str, ...], time_s: np.ndarray, table: np.ndarray) -> None: ...

    def step(self, k: int) -> None: ...

    def stop(self, n: int) -> None: ...


_READ = {
    "u": "velocities/u-fps",
    "v": "velocities/v-fps",
    "w": "velocities/w-fps",
    "q": "velocities/q-rad_sec",
    "theta": "attitude/theta-rad",
    "phi": "attitude/phi-rad",
    "rho": "atmosphere/rho-slugs_ft3",
    "nz": "accelerations/Nz",
    "h": "position/h-sl-ft",
    "agl": "position/h-agl-ft",
    "lat": "position/lat-geod-rad",
    "lon": "position/long-gc-rad",
    "psi": "attitude/psi-rad",
    "p": "velocities/p-rad_sec",
    "r": "velocities/r-rad_sec",
    "elevator": "fcs/elevator-pos-rad",
    "throttle": "fcs/throttle-pos-norm",
    "vn": "velocities/v-north-fps",
    "ve": "velocities/v-east-fps",
    "vd": "velocities/v-down-fps",
}


class Sensed(NamedTuple):
    """The airframe at one instant, as the wing and the logs see it (SI; aerospace frames:
    NED Euler angles, FRD body rates, NED velocities; ``docs/conventions.md``). ``flow``:
    the air data at the wing with the current wind (α, q, V, Q); β likewise against the
    air."""

    flow: FlowState
    theta_rad: float
    phi_rad: float
    psi_rad: float
    beta_rad: float
    p_rad_s: float
    r_rad_s: float
    n_z: float
    altitude_m: float
    latitude_rad: float
    longitude_rad: float
    v_north_m_s: float
    v_east_m_s: float
    v_down_m_s: float
    elevator_rad: float
    throttle: float


def state_reader(get: dict) -> Callable[[float], Sensed]:
    """``read(wind_down_fps)``: the airframe's state now and the flow the wing sees with the
    NED vertical wind ``wind_down_fps`` [ft/s, down], as JSBSim's FGAuxiliary computes it.

    ``get`` maps the keys of ``_READ`` to JSBSim property readers (bound once, here, for
    the per-step call). Everything is read at the same instant: the state JSBSim reached at
    the end of its last step (its n_z is that of this state), so a logged row is one
    consistent snapshot.
    """
    g_u, g_v, g_w, g_q = get["u"], get["v"], get["w"], get["q"]
    g_theta, g_phi, g_psi, g_p, g_r = get["theta"], get["phi"], get["psi"], get["p"], get["r"]
    g_rho, g_nz, g_h, g_lat, g_lon = get["rho"], get["nz"], get["h"], get["lat"], get["lon"]
    g_vn, g_ve, g_vd = get["vn"], get["ve"], get["vd"]
    g_elevator, g_throttle = get["elevator"], get["throttle"]
    m_per_ft, rho_si = U.M_PER_FT, U.KG_M3_PER_SLUG_FT3
    sin, cos, make = math.sin, math.cos, tuple.__new__

    def read(wind_down_fps: float) -> Sensed:
        theta, phi = g_theta(), g_phi()
        # air-relative body velocity: subtract the NED wind seen in body axes
        ua = g_u() + wind_down_fps * sin(theta)
        va = g_v() - wind_down_fps * sin(phi) * cos(theta)
        wa = g_w() - wind_down_fps * cos(phi) * cos(theta)
        vt_fps = math.sqrt(ua * ua + va * va + wa * wa)
        vt = vt_fps * m_per_ft
        flow = FlowState(math.atan2(wa, ua), g_q(), vt, 0.5 * g_rho() * rho_si * vt * vt)
        return make(Sensed, (
            flow, theta, phi, g_psi(), math.asin(va / vt_fps) if vt_fps > 0.0 else 0.0,
            g_p(), g_r(), g_nz(), g_h() * m_per_ft, g_lat(), g_lon(), g_vn() * m_per_ft,
            g_ve() * m_per_ft, g_vd() * m_per_ft, g_elevator(), g_throttle()))

    return read


def row_values(s: Sensed, w_g_m_s: float, loads, eta, eta_dot, trim, speed_m_s: float
               ) -> tuple[float, ...]:
    """The logged row of one step (``base_channels`` order): the snapshot ``s`` at t_k, the
    gust then, the wing loads applied over the step (those of η_{k+1}) and the modal state
    η_k, η̇_k [rad, rad/s]."""
    f, theta, phi, psi, beta, p, r, n_z, h, lat, lon, vn, ve, vd, elevator, throttle = s
    alpha, v = f.alpha_rad, f.airspeed_m_s
    return (
        v - speed_m_s, alpha - trim.alpha_rad, f.q_rad_s, theta - trim.theta_rad, n_z,
        w_g_m_s, v, h, loads.lift_n, loads.drag_n, loads.pitch_moment_n_m, lat, lon, phi,
        theta, psi, p, r, elevator, throttle, alpha, beta, vn, ve, vd, *eta, *eta_dot,
    )


def base_channels(n_modes: int) -> dict[str, str]:
    """Channel names of a gust run and their units."""
    units = {
        "u": "m/s", "alpha": "rad", "q": "rad/s", "theta": "rad", "n_z": "-", "w_g": "m/s",
        "airspeed_m_s": "m/s", "altitude_m": "m",
        "lift_n": "N", "drag_n": "N", "pitch_moment_n_m": "N*m",
        # absolute pose and the rest of the state, for logs and ground stations
        "latitude_rad": "rad", "longitude_rad": "rad", "phi_rad": "rad",
        "theta_rad": "rad", "psi_rad": "rad", "p_rad_s": "rad/s", "r_rad_s": "rad/s",
        "elevator_rad": "rad", "throttle": "-",
        "alpha_rad": "rad", "beta_rad": "rad", "v_north_m_s": "m/s", "v_east_m_s": "m/s",
        "v_down_m_s": "m/s",
    }
    for i in range(n_modes):  # order matters: the loop writes η_1..η_n, then η̇_1..η̇_n
        units[f"eta{i + 1}"] = "rad"
    for i in range(n_modes):
        units[f"eta{i + 1}_dot"] = "rad/s"
    return units


def run_gust(
    airframe: Airframe,
    wing: ElasticWingModel,
    model: str,
    setup: RunSetup,
    on_sample: Callable[[int, float, tuple[float, ...]], None] | None = None,
    trim: TrimResult | None = None,
    recorder: StepRecorder | None = None,
) -> TimeHistory:
    """Trim, then fly ``setup`` with the wing ``model`` (rigid/coupled/qsd).

    ``on_sample(k, t_s, values)`` is called after every step (progress), ``values`` the
    step's numbers as a tuple in the order of ``base_channels(wing.n_modes)``; ``recorder``
    (a log) reads the steps from the run's table (:class:`StepRecorder`). A run that leaves
    the valid range stops: the returned history holds every step up to then and its
    ``stopped`` field says why. ``trim``: the airframe was just trimmed to this (skip it).
    """
    airframe.set_external_reactions()  # the trim is the rigid airframe's: no modal loads
    for name, value in INTEGRATORS.items():
        airframe[name] = value
    airframe.set_dt(setup.dt_s)  # before the trim: JSBSim's multistep integrators and the
    # propeller start from a history at the step they will run with
    if trim is None:
        trim = airframe.trim(setup.speed_m_s, setup.altitude_m)
    dt = airframe.dt_s
    cond = level_flight_condition(setup.speed_m_s)
    nodes = {k: airframe.property_node(v) for k, v in _READ.items()}
    wind_node = airframe.property_node("atmosphere/wind-down-fps")
    # The reference dynamic pressure is JSBSim's own at trim (same density as the run).
    rho0 = nodes["rho"].get_double_value() * U.KG_M3_PER_SLUG_FT3
    ref = TrimReference(trim.alpha_rad, 0.5 * rho0 * setup.speed_m_s**2, cond.cl_trim)
    mw = ModalWing(wing, ref, model=model, dt_s=dt)
    gust = GustField(setup.gust, setup.speed_m_s, setup.gust_start_s, setup.duration_s, dt)
    n_steps = int(round(setup.duration_s / dt))
    units = base_channels(wing.n_modes)
    names = tuple(units)
    table = np.full((n_steps, len(names)), np.nan)  # row k: step k, columns in names' order
    time_s = np.arange(n_steps) * dt
    alpha_min, alpha_max = ALPHA_TABLE_RANGE_RAD
    alpha_peak = alpha_peak_rad()
    stall_steps = 0
    stopped = None
    interrupted = False
    k = 0
    write_reactions = airframe.external_reaction_writer()  # nodes looked up once
    step = airframe.step
    get = {name: node.get_double_value for name, node in nodes.items()}
    read_state = state_reader(get)
    done = 0  # complete rows of the table
    if recorder is not None:
        recorder.start(names, time_s, table)
        record = recorder.step

    def sense(t: float):
        """Write the gust at ``t`` to JSBSim's wind and return it and the airframe's state
        with the flow the wing sees then (:func:`state_reader`)."""
        w_g = gust.vertical_m_s(t)
        wind_down_fps = -w_g * U.FT_PER_M
        wind_node.set_double_value(wind_down_fps)
        return w_g, read_state(wind_down_fps)

    try:
        with airframe.capturing():  # JSBSim's output captured once for the loop
            w_g, state = sense(0.0)
            for k in range(n_steps):
                t = k * dt
                flow = state.flow
                eta, eta_dot = mw.eta, mw.eta_dot
                mw.step(flow)  # η_k → η_{k+1} over [t_k, t_k+1] with the flow of t_k held
                loads = mw.loads(flow)
                alpha = flow.alpha_rad
                ca, sa = math.cos(alpha), math.sin(alpha)
                write_reactions(
                    loads.lift_n * ca + loads.drag_n * sa,
                    loads.drag_n * ca - loads.lift_n * sa,
                    loads.pitch_moment_n_m,
                )
                step()
                values = row_values(state, w_g, loads, eta, eta_dot, trim, setup.speed_m_s)
                table[k] = values
                done = k + 1
                if recorder is not None:
                    record(k)
                if on_sample is not None:
                    on_sample(k, t, values)
                stall_steps += alpha > alpha_peak
                stopped = _check_range(values, names, t, alpha, alpha_min, alpha_max, mw.eta,
                                       get["agl"]())
                if stopped:
                    break
                w_g, state = sense(t + dt)
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM (the CLI maps it): keep what was flown
        interrupted = True
        stopped = f"interrupted at t = {done * dt:.3f} s"
    finally:
        airframe.set_external_reactions()  # leave no modal loads behind for the next user
        if recorder is not None:
            recorder.stop(done)  # also when the loop failed: keep every complete step
    n = done
    run = TimeHistory(
        model=model,
        time_s=time_s[:n],
        channels={name: table[:n, i].copy() for i, name in enumerate(names)},
        units=units,
        meta={
            "source": "jsbsim-cosim",
            "speed_m_s": setup.speed_m_s,
            "dt_s": dt,
            "gust": setup.gust.text(),
            "gust_start_s": setup.gust_start_s,
            "trim_alpha_rad": trim.alpha_rad,
            "trim_theta_rad": trim.theta_rad,
            "trim_elevator_rad": trim.elevator_rad,
            "trim_throttle": trim.throttle,
            "alpha_peak_rad": alpha_peak,
            "time_beyond_stall_s": stall_steps * dt,
            "interrupted": interrupted,
        },
        stopped=stopped,
    )
    return run


def _check_range(values, names, t, alpha, alpha_min, alpha_max, eta, agl_ft) -> str | None:
    """Why the run must stop at this sample, or None."""
    if not all(map(math.isfinite, values)):
        bad = next(n for n, v in zip(names, values, strict=True) if not math.isfinite(v))
        return f"the state became non-finite ({bad}) at t = {t:.3f} s"
    if not alpha_min <= alpha <= alpha_max:
        return (
            f"angle of attack {math.degrees(alpha):.1f} deg left the aerodynamic model "
            f"({math.degrees(alpha_min):.0f}..{math.degrees(alpha_max):.0f} deg, deep stall) "
            f"at t = {t:.3f} s"
        )
    etas = [abs(e) for e in eta]
    if etas and max(etas) > ETA_LIMIT_RAD:
        i = int(np.argmax(etas))
        return (
            f"mode aeroelastic_{i + 1} diverged: |eta{i + 1}| = {etas[i]:.2f} rad > "
            f"{ETA_LIMIT_RAD} rad (beyond the linear range) at t = {t:.3f} s"
        )
    if agl_ft <= 0.0:
        return f"the aircraft reached the ground at t = {t:.3f} s"
    return None
