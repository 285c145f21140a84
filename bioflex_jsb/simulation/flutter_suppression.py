"""Active flutter suppression: the unsteady LTI model with its elevator, a controller designed
on it, and the closed loop's flutter speed as the co-simulation flies it.

**The plant** (:func:`controlled_plant`): Eq. (4) on unsteady strips with Küssner's gust
(:func:`bioflex_jsb.aeroelasticity.free_aircraft.unsteady_descriptor`, the model the
unsteady co-simulation integrates: states u, α, q, θ, η, η̇ and four lag states per strip)
with the elevator and throttle columns of the rigid rows
(:func:`bioflex_jsb.flight_dynamics.lti.control_columns`: the tail's lift and moment; the
tail does not load the wing) put through the same descriptor, E ẋ = A x + B [w_g, δe, δt],
so that the apparent mass carries the elevator's pitch acceleration to the modes as it
carries the gust's; the load factor n_z = u₀ (q − α̇)/g from the α row (as
:func:`bioflex_jsb.flight_dynamics.lti.build_state_space` with ``controls``); the run's
signals as outputs (:func:`bioflex_jsb.simulation.closed_loop.signal_outputs`).

**The closed loop** (:func:`closed_loop_roots`): a linear controller closed at the run's step
Δt with the run's one step of delay (:func:`bioflex_jsb.simulation.closed_loop.close_loop`),
its discrete roots z mapped to s = ln z / Δt [1/s] (the delay's roots at z = 0 left out).
**Stability** is every root's: Re s ≤ :data:`GROWTH_TOL_1_S` (the phugoid included, unlike
the open-loop flutter search, which leaves it out as the paper does: a controller that
destabilised the phugoid would be no flutter suppressor; with the prototype's wings the
phugoid stays stable, Re s ≈ −0.04 to −0.1 1/s, open and closed loop).

**The closed-loop flutter speed** (:func:`closed_loop_flutter`): the first speed of a scan
at which the closed loop is unstable, bisected to a tolerance; with no controller (None),
the same search of the open loop (a zero gain through the same path), so that the two are
compared on one footing.

**The design** (:func:`design_static_feedback`): a static output feedback δe = Σ K_i s_i
[rad] from signals a controller reads (default the IMU's: the pitch-rate gyro ``q``
[rad/s] and the accelerometer's load factor ``n_z`` [-] at the centre of gravity), minimising
by Nelder-Mead the largest growth rate of the closed loop's oscillatory and fast roots
(|s| ≥ :data:`SLOW_ROOT_RAD_S`: the phugoid is held stable by a penalty, not pushed) over a
speed grid up to the design speed, plus a small weight on the gains (the elevator's travel:
the prototype's ±20°, ``systems/bioflex_flight_controls.xml``). The body-freedom flutter of
a backward-axis wing is the short period meeting the first wing mode
(docs/aeroelasticity.md); the pitch rate damps the short period and the load factor, which
the wing's bending moves through the body, feeds the coupled mode back to the elevator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from bioflex_jsb.aeroelasticity.free_aircraft import unsteady_descriptor
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import CONTROL_INPUT_UNITS, CONTROL_INPUTS, control_columns
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3, STANDARD_GRAVITY_M_S2
from bioflex_jsb.simulation.closed_loop import close_loop, signal_outputs
from bioflex_jsb.simulation.controller import LinearController, check_signals
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.state_space import StateSpace

# The IMU's signals at the centre of gravity: the pitch-rate gyro and the accelerometer.
DEFAULT_SIGNALS = ("q", "n_z")
# A root grows when Re s exceeds this [1/s] (the flutter engine's GROWTH_TOL_1_S).
GROWTH_TOL_1_S = 1e-9
# The design's roots below this magnitude [rad/s] are the slow ones (the phugoid, 0.74-0.95
# rad/s on the inertial-backward wing at 15-25 m/s; the short period is >= 12 rad/s and the
# strips' lag roots >= 7 1/s there, measured by closed_loop_roots): held stable, not pushed.
SLOW_ROOT_RAD_S = 2.0
# The closed-loop search's default range [m/s]: JSBSim trims the prototype at 9-32 m/s (the
# README's valid ranges), so the nonlinear runs that check the search fly within 10-30.
DEFAULT_RANGE_M_S = (10.0, 30.0)
DEFAULT_STEP_M_S = 0.25  # the scan's grid [m/s]; the crossing is bisected below it
DEFAULT_TOL_M_S = 1e-3  # bisection tolerance [m/s]


def controlled_plant(build, speed_m_s: float, *,
                     density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
                     a_rr: np.ndarray | None = None) -> StateSpace:
    """The unsteady coupled model of ``build`` (a WingBuild) at ``speed_m_s`` [m/s] with its
    controls (module docstring): inputs w_g [m/s], elevator [rad] (+ trailing edge down),
    throttle [-]; outputs the run's signals (``alpha``, ``q``, ``n_z``, ``eta<i>``, ...) as
    perturbations from the trim. ``a_rr``: JSBSim's rigid block at the trim in place of the
    analytic one (it moves only the phugoid: the flutter roots of the inertial-backward
    wing agree to 1e-3 1/s at 15-25 m/s)."""
    v = float(speed_m_s)
    desc = unsteady_descriptor(build, v, gust=True, density_kg_m3=density_kg_m3, a_rr=a_rr)
    cond = level_flight_condition(v, density_kg_m3, airframe=build.model.airframe)
    n_all = desc.a.shape[0]
    b_ctrl = np.zeros((n_all, len(CONTROL_INPUTS)))
    b_ctrl[:4] = control_columns(cond)
    a = np.linalg.solve(desc.e, desc.a)
    b = np.linalg.solve(desc.e, np.hstack([desc.b, b_ctrl]))
    ia, iq = desc.states.index("alpha"), desc.states.index("q")
    e_q = np.zeros(n_all)
    e_q[iq] = 1.0
    g = STANDARD_GRAVITY_M_S2
    c = np.vstack([np.eye(n_all), v / g * (e_q - a[ia])])
    d = np.vstack([np.zeros((n_all, b.shape[1])), -v / g * b[ia]])
    ss = StateSpace(
        model="coupled-unsteady", speed_m_s=v, a=a, b=b, c=c, d=d, states=desc.states,
        state_units=desc.state_units, inputs=desc.base.inputs + CONTROL_INPUTS,
        input_units=desc.base.input_units + CONTROL_INPUT_UNITS,
        outputs=desc.states + ("n_z",), output_units=desc.state_units + ("-",),
        notes=dict(desc.base.notes, aero="unsteady", gust="Küssner (Sears & Sparks)",
                   density_kg_m3=float(density_kg_m3),
                   controls="the rigid rows' elevator and throttle columns through the "
                            "unsteady descriptor (simulation/flutter_suppression.py)"))
    return signal_outputs(ss)


def zero_controller(signals=DEFAULT_SIGNALS) -> LinearController:
    """A zero gain from ``signals`` to the elevator: the open loop through the closed loop's
    path (the same discretisation and delay)."""
    return static_gain(np.zeros(len(tuple(signals))), signals, name="open loop")


def static_gain(gains, signals=DEFAULT_SIGNALS, name: str = "flutter_suppression",
                notes: dict | None = None) -> LinearController:
    """δe = Σ K_i s_i [rad] (``gains`` per signal in the signal's unit) as a continuous
    LinearController (it runs at the run's step)."""
    return LinearController.from_arrays(None, None, None, [list(map(float, gains))], None,
                                        check_signals(signals), ["elevator"], name, notes)


def closed_loop_roots(plant: StateSpace, controller: LinearController | None,
                      dt_s: float = DEFAULT_DT_S) -> np.ndarray:
    """The closed loop's roots s = ln z / ``dt_s`` [1/s] (module docstring) of ``plant``
    (:func:`controlled_plant`) with ``controller`` (None: the open loop), at the run's step
    ``dt_s`` [s] with its one step of delay; the roots at z = 0 (the delay's) left out."""
    ctrl = zero_controller() if controller is None else controller
    cl = close_loop(plant, ctrl, dt_s, delay_steps=1)
    z = np.linalg.eigvals(cl.a)
    z = z[np.abs(z) > 1e-12]
    return np.log(z.astype(complex)) / float(dt_s)


def growth_rate_1_s(plant: StateSpace, controller: LinearController | None,
                    dt_s: float = DEFAULT_DT_S) -> tuple[float, complex]:
    """(the largest Re s [1/s] of the closed loop, that root s [1/s], upper half plane)."""
    s = closed_loop_roots(plant, controller, dt_s)
    top = s[np.argmax(s.real)]
    return float(top.real), complex(top.real, abs(top.imag))


@dataclass(frozen=True)
class ClosedLoopFlutter:
    """The first instability of a closed loop (:func:`closed_loop_flutter`): ``speed_m_s``
    [m/s] (None: stable over the range, or unstable at its lower end:
    ``present_at_lower_end``), its root ``root_1_s`` [1/s] (frequency ``frequency_rad_s``
    [rad/s]; 0 a static divergence), the range, step and tolerance [m/s] and the
    controller's name ("open loop" for None)."""

    controller: str
    speed_m_s: float | None
    root_1_s: complex | None
    range_m_s: tuple[float, float]
    step_m_s: float
    tol_m_s: float
    present_at_lower_end: bool = False
    scan: dict = field(default_factory=dict, repr=False)

    @property
    def frequency_rad_s(self) -> float | None:
        return None if self.root_1_s is None else abs(self.root_1_s.imag)

    def as_dict(self) -> dict[str, object]:
        return {"controller": self.controller, "speed_m_s": self.speed_m_s,
                "frequency_rad_s": self.frequency_rad_s,
                "frequency_hz": (None if self.root_1_s is None
                                 else abs(self.root_1_s.imag) / (2.0 * math.pi)),
                "range_m_s": list(self.range_m_s), "step_m_s": self.step_m_s,
                "tol_m_s": self.tol_m_s, "present_at_lower_end": self.present_at_lower_end}


def closed_loop_flutter(build, controller: LinearController | None,
                        range_m_s: tuple[float, float] = DEFAULT_RANGE_M_S, *,
                        step_m_s: float = DEFAULT_STEP_M_S, tol_m_s: float = DEFAULT_TOL_M_S,
                        dt_s: float = DEFAULT_DT_S,
                        density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
                        rigid_block=None) -> ClosedLoopFlutter:
    """The closed loop's flutter speed (module docstring) of ``build`` with ``controller``
    (None: the open loop) over ``range_m_s`` [m/s]: the scan at ``step_m_s`` [m/s], the
    first unstable grid speed bisected against the last stable one to ``tol_m_s`` [m/s]
    (the bracket's unstable end reported). ``rigid_block``: a function of the speed [m/s]
    giving JSBSim's rigid block A_RR there (None: the analytic one). ``scan`` holds the
    grid's speeds and largest growth rates [1/s]."""
    lo, hi = (float(x) for x in range_m_s)
    if not 0.0 < lo < hi:
        raise InputError(f"closed-loop flutter range must satisfy 0 < low < high, got "
                         f"{lo:g}:{hi:g} m/s")
    if not step_m_s > 0.0 or not tol_m_s > 0.0:
        raise InputError("the scan step and the tolerance must be > 0 m/s")
    name = "open loop" if controller is None else controller.name

    def rate(v: float) -> tuple[float, complex]:
        a_rr = None if rigid_block is None else rigid_block(v)
        return growth_rate_1_s(controlled_plant(build, v, density_kg_m3=density_kg_m3,
                                                a_rr=a_rr), controller, dt_s)

    grid = np.append(np.arange(lo, hi, float(step_m_s)), hi)
    speeds, rates = [], []
    prev = None
    for v in grid:
        r, root = rate(float(v))
        speeds.append(float(v))
        rates.append(r)
        if r > GROWTH_TOL_1_S:
            scan = {"speeds_m_s": speeds, "growth_1_s": rates}
            if prev is None:
                return ClosedLoopFlutter(name, None, root, (lo, hi), float(step_m_s),
                                         float(tol_m_s), True, scan)
            a, b, root_b = prev, float(v), root
            while b - a > tol_m_s:
                mid = 0.5 * (a + b)
                r_mid, root_mid = rate(mid)
                if r_mid > GROWTH_TOL_1_S:
                    b, root_b = mid, root_mid
                else:
                    a = mid
            return ClosedLoopFlutter(name, b, root_b, (lo, hi), float(step_m_s),
                                     float(tol_m_s), False, scan)
        prev = float(v)
    return ClosedLoopFlutter(name, None, None, (lo, hi), float(step_m_s), float(tol_m_s),
                             False, {"speeds_m_s": speeds, "growth_1_s": rates})


def _static_loop(plant: StateSpace, signals: tuple[str, ...], dt_s: float):
    """A function of the gains [per signal] giving the closed loop's matrix of a static gain
    at the step ``dt_s`` with one step of delay, the plant discretised once: z = [x, v],
    x⁺ = Φ x + Γ v, v⁺ = K (C_s x + D_s v) (close_loop's, for a static gain)."""
    pd = plant.to_discrete(dt_s)
    ie = plant.inputs.index("elevator")
    isig = [plant.outputs.index(s) for s in signals]
    phi, gam = pd.a, pd.b[:, ie]
    c_s, d_s = plant.c[isig], plant.d[isig, ie]
    n = plant.n_states
    base = np.zeros((n + 1, n + 1))
    base[:n, :n], base[:n, n] = phi, gam

    def matrix(gains) -> np.ndarray:
        k = np.asarray(gains, dtype=float)
        m = base.copy()
        m[n, :n], m[n, n] = k @ c_s, k @ d_s
        return m

    return matrix


def _rates(matrix, gains, dt_s: float) -> tuple[float, float]:
    """(largest Re s of the fast roots, of the slow ones) [1/s] (module docstring)."""
    z = np.linalg.eigvals(matrix(gains))
    z = z[np.abs(z) > 1e-12]
    s = np.log(z.astype(complex)) / dt_s
    slow = np.abs(s) < SLOW_ROOT_RAD_S
    fast_re = float(np.max(s.real[~slow])) if np.any(~slow) else -np.inf
    slow_re = float(np.max(s.real[slow])) if np.any(slow) else -np.inf
    return fast_re, slow_re


def design_static_feedback(build, design_speed_m_s: float, signals=DEFAULT_SIGNALS, *,
                           low_speed_m_s: float = 15.0, grid_step_m_s: float = 0.5,
                           gain_weight: float = 0.1, initial=None,
                           dt_s: float = DEFAULT_DT_S,
                           density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
                           max_iterations: int = 600) -> tuple[LinearController, dict]:
    """A static output feedback δe = Σ K_i s_i from ``signals`` to the elevator for
    ``build`` (module docstring): Nelder-Mead on the gains minimising

        J(K) = max_V max Re s_fast(V; K) + gain_weight · Σ K_i² + 100 · max(0, Re s_slow)

    over the speeds ``low_speed_m_s``..``design_speed_m_s`` [m/s] every ``grid_step_m_s``
    (the loop at the step ``dt_s`` [s] with one step of delay). ``initial``: the starting
    gains (default 0.1 per signal). Returns (the LinearController, continuous; the design's
    record: gains by signal, J, the grid, iterations)."""
    signals = check_signals(signals)
    v_d = float(design_speed_m_s)
    if not low_speed_m_s < v_d:
        raise InputError(f"the design speed {v_d:g} m/s must be above {low_speed_m_s:g} m/s")
    grid = np.append(np.arange(float(low_speed_m_s), v_d, float(grid_step_m_s)), v_d)
    loops = [_static_loop(controlled_plant(build, float(v), density_kg_m3=density_kg_m3),
                          signals, dt_s) for v in grid]

    def cost(k: np.ndarray) -> float:
        worst_fast, worst_slow = -np.inf, -np.inf
        for loop in loops:
            fast, slow = _rates(loop, k, dt_s)
            worst_fast, worst_slow = max(worst_fast, fast), max(worst_slow, slow)
        return worst_fast + gain_weight * float(k @ k) + 100.0 * max(0.0, worst_slow)

    x0 = np.full(len(signals), 0.1) if initial is None else np.asarray(initial, dtype=float)
    res = minimize(cost, x0, method="Nelder-Mead",
                   options={"maxiter": int(max_iterations), "xatol": 1e-5, "fatol": 1e-5})
    gains = {s: float(k) for s, k in zip(signals, res.x, strict=True)}
    record = {"gains": gains, "cost_1_s": float(res.fun), "iterations": int(res.nit),
              "grid_m_s": [float(v) for v in grid], "design_speed_m_s": v_d,
              "gain_weight": float(gain_weight), "dt_s": float(dt_s)}
    return static_gain(res.x, signals), record


def growth_from_response(time_s, signal, frequency_rad_s: float, start_s: float,
                         stop_s: float | None = None) -> tuple[float, int]:
    """(the growth rate σ [1/s] of the oscillation at ``frequency_rad_s`` [rad/s] in
    ``signal`` between ``start_s`` and ``stop_s`` [s], the number of peaks it rests on) by
    the logarithmic decrement: the signal less its moving average over one period (the
    slow rigid-body motion taken out), its successive maxima's ln against time fitted by a
    straight line, σ its slope (σ = δ f, δ the decrement per cycle, f the frequency).
    Fewer than three peaks: InputError (the window holds no oscillation to measure)."""
    t = np.asarray(time_s, dtype=float)
    y = np.asarray(signal, dtype=float)
    keep = (t >= start_s) & (t <= (t[-1] if stop_s is None else stop_s)) & np.isfinite(y)
    t, y = t[keep], y[keep]
    dt = float(np.median(np.diff(t)))
    period_n = max(3, int(round(2.0 * math.pi / frequency_rad_s / dt)))
    if len(y) < 2 * period_n:
        raise InputError("the window is shorter than two periods of the oscillation")
    kernel = np.ones(period_n) / period_n
    trend = np.convolve(y, kernel, mode="same")
    half = period_n // 2
    osc = (y - trend)[half:len(y) - half]
    tt = t[half:len(t) - half]
    peaks = [i for i in range(1, len(osc) - 1)
             if osc[i] > osc[i - 1] and osc[i] >= osc[i + 1] and osc[i] > 0.0]
    # one maximum per period: the largest within each half period of a kept peak
    kept: list[int] = []
    for i in peaks:
        if kept and i - kept[-1] < period_n // 2:
            if osc[i] > osc[kept[-1]]:
                kept[-1] = i
            continue
        kept.append(i)
    if len(kept) < 3:
        raise InputError(f"{len(kept)} peaks of the oscillation in the window: too few for "
                         "a logarithmic decrement")
    slope = np.polyfit(tt[kept], np.log(osc[kept]), 1)[0]
    return float(slope), len(kept)
