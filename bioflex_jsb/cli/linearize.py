"""``bioflex-jsb linearize``: JSBSim's linear model of the rigid airframe at a trim."""

from __future__ import annotations

import argparse

from bioflex_jsb.cli.common import print_json
from bioflex_jsb.cli.trim import add_flight_condition_arguments, load_airframe

HELP = """Trim the rigid JSBSim airframe at --speed, linearize it with JSBSim's
FGLinearization and reduce the model to the paper's longitudinal states x_R = [u, alpha,
q, theta]: u the airspeed perturbation in m/s, alpha and theta in rad, q in rad/s (the
propeller RPM is eliminated as quasi-static, the lateral states are dropped). Units:
--speed in m/s (valid range and default as for trim), --altitude in m above sea level
(default 0, ISA). A is printed row by row (row i = d x_i/dt), then B for the inputs w_g
[m/s] (gust, up: G_R = A[:, alpha]/u_0, the paper's definition, from JSBSim's A), elevator
[rad] and throttle [-] (these two columns from the analytic model of `bioflex-jsb export`:
JSBSim's own input matrix is not read here). Eigenvalues (re, im) and natural frequencies in
rad/s, damping ratio dimensionless, one entry per conjugate pair (im >= 0), labelled
short_period or phugoid by frequency. The phugoid differs from `bioflex-jsb modes` (the
paper's analytic A_RR from Table B2): JSBSim's X_u includes the fixed-pitch propeller's
thrust falling with airspeed (dT/dV / m, about -0.06 1/s at 15 m/s), which Table B2 leaves
out (thrust speed-independent); that term alone doubles the phugoid damping, and the
command prints it beside the difference. --aircraft NAME|FILE.toml, an aircraft definition
(docs/aircraft.md): its own JSBSim aircraft at its cruise speed (default) within its speeds,
the analytic columns and phugoid from its [airframe] numbers (a glider: A by central
differences of JSBSim's state derivatives, no thrust term); a JSBSim aircraft name of
another --jsbsim-root: JSBSim's A and the gust column only (its analytic model is not known).
JSON keys: speed_m_s, states, A, eigenvalues, inputs, input_units, B, phugoid_comparison
(null without the analytic model)."""


def register(sub) -> None:
    p = sub.add_parser(
        "linearize", help="rigid longitudinal linear model from JSBSim", description=HELP
    )
    add_flight_condition_arguments(p)
    from bioflex_jsb.cli.aircraft_option import cruise_speed_default

    # DEFAULT_SPEED_M_S, marked: an aircraft definition's cruise speed replaces it
    p.set_defaults(speed=cruise_speed_default())
    p.add_argument("--json", action="store_true", help="print JSON (SI) instead of a table")
    p.set_defaults(run=run)


def _condition(lin, airframe_data):
    """The analytic model's level-flight condition at the linearisation's speed for the
    aircraft ``airframe_data`` (its :class:`~bioflex_jsb.parameters.airframe.AirframeData`;
    the linear model's own, sea-level density)."""
    from bioflex_jsb.flight_dynamics.rigid import level_flight_condition

    return level_flight_condition(lin.speed_m_s, airframe=airframe_data)


def b_matrix(lin, airframe_data=None):
    """B of the inputs for the JSBSim model ``lin``: the gust column w_g [m/s] from
    JSBSim's A, then, with the aircraft's ``airframe_data`` (None: not known, the gust
    column alone), the elevator [rad] and throttle [-] columns of its analytic model."""
    import numpy as np

    from bioflex_jsb.flight_dynamics.lti import control_columns

    g_r = np.asarray(lin.a, dtype=float)[:, 1] / lin.speed_m_s
    if airframe_data is None:
        return g_r[:, None]
    return np.column_stack([g_r, control_columns(_condition(lin, airframe_data))])


def phugoid_comparison(lin, airframe_data) -> dict:
    """JSBSim's phugoid and X_u against the analytic model's of ``airframe_data`` (``modes``),
    and the propeller's thrust term that makes the difference (SI: rad/s, 1/s; 0 for an
    aircraft without the prototype's propeller model, a glider)."""
    import numpy as np

    from bioflex_jsb.flight_dynamics.lti import build_state_space, thrust_speed_derivative_n_s_m

    cond = _condition(lin, airframe_data)
    a_an = build_state_space("rigid", cond).a
    lam = np.linalg.eigvals(a_an)
    ph = min((z for z in lam if z.imag >= 0.0), key=abs)
    thrust = (0.0 if airframe_data.propulsion is None
              else thrust_speed_derivative_n_s_m(cond) / airframe_data.mass.mass_kg)
    return {
        "jsbsim_x_u_1_s": float(lin.a[0][0]),
        "analytic_x_u_1_s": float(a_an[0, 0]),
        "thrust_term_1_s": thrust,
        "analytic_phugoid_re_rad_s": float(ph.real),
        "analytic_phugoid_im_rad_s": float(abs(ph.imag)),
    }


def linearization_payload(lin, airframe_data=None) -> dict:
    """JSON form: speed_m_s, states, A, eigenvalues, then inputs, input_units, B and
    phugoid_comparison (without ``airframe_data``, the aircraft's analytic model: B the gust
    column only and phugoid_comparison null)."""
    b = b_matrix(lin, airframe_data)
    return {
        "speed_m_s": lin.speed_m_s,
        "states": list(lin.states),
        "A": [[float(x) for x in row] for row in lin.a],
        "eigenvalues": [
            {
                "mode": ev.mode,
                "re": ev.re,
                "im": ev.im,
                "damping": ev.damping,
                "frequency_rad_s": ev.frequency_rad_s,
            }
            for ev in lin.eigenvalues
        ],
        "inputs": ["w_g", "elevator", "throttle"][:b.shape[1]],
        "input_units": ["m/s", "rad", "-"][:b.shape[1]],
        "B": [[float(x) for x in row] for row in b],
        "phugoid_comparison": (None if airframe_data is None
                               else phugoid_comparison(lin, airframe_data)),
    }


def _airframe(args: argparse.Namespace):
    """(the JSBSim airframe, the aircraft's AirframeData or None) of the options:
    ``--aircraft`` an aircraft definition (NAME|FILE.toml: its JSBSim aircraft, its speeds
    and its airframe numbers), else a JSBSim aircraft of the root (the prototype's
    numbers for the generated ``bioflex`` aircraft and its native variants; None for any
    other: its analytic model is not known here)."""
    from bioflex_jsb.cli.trim import aircraft_definition, definition_airframe

    aircraft = aircraft_definition(args)
    if aircraft is None:
        from bioflex_jsb.cli.aircraft_option import default_airframe
        from bioflex_jsb.runtime.fdm import DEFAULT_AIRCRAFT

        airframe = load_airframe(args)
        args.speed = float(args.speed)
        name = airframe.aircraft
        prototype = name == DEFAULT_AIRCRAFT or name.startswith(DEFAULT_AIRCRAFT + "_")
        return airframe, default_airframe() if prototype else None
    airframe = definition_airframe(args, aircraft)
    return airframe, (None if aircraft.linear_problem() else aircraft.airframe_data())


def run(args: argparse.Namespace) -> int:
    airframe, data = _airframe(args)
    lin = airframe.linearize(args.speed, args.altitude)
    if args.json:
        print_json(linearization_payload(lin, data))
        return 0
    how = ("central differences of JSBSim's state derivatives: a glider" if airframe.glider
           else "JSBSim FGLinearization")
    print(f"Rigid longitudinal model of {airframe.aircraft} at {lin.speed_m_s:g} m/s ({how})")
    header = "".join(f"{s:>12}" for s in lin.states)
    print(f"  A, x_R = [u m/s, alpha rad, q rad/s, theta rad]\n  {'':8}{header}")
    for name, row in zip(lin.states, lin.a, strict=True):
        print(f"  {name + ' dot':<8}" + "".join(f"{x:12.4g}" for x in row))
    b = b_matrix(lin, data)
    if data is None:
        print("  B, u = [w_g m/s (JSBSim's A)]; the elevator and throttle columns and the "
              "phugoid of `modes` need the aircraft's analytic model: give its definition, "
              "--aircraft FILE.toml with [airframe.derivatives] (docs/aircraft.md)")
    else:
        print("  B, u = [w_g m/s (JSBSim's A), elevator rad, throttle - (analytic)]")
    inputs = ("w_g", "elevator", "throttle")[:b.shape[1]]
    print(f"  {'':8}" + "".join(f"{s:>12}" for s in inputs))
    for name, row in zip(lin.states, b, strict=True):
        print(f"  {name + ' dot':<8}" + "".join(f"{x:12.4g}" for x in row))
    print(f"  {'mode':<14}{'re':>10}{'im':>10}{'damping':>10}{'freq':>10}  [rad/s]")
    for ev in lin.eigenvalues:
        print(
            f"  {ev.mode:<14}{ev.re:10.3f}{ev.im:10.3f}{ev.damping:10.3f}{ev.frequency_rad_s:10.3f}"
        )
    if data is None:
        return 0
    c = phugoid_comparison(lin, data)
    source = "Table B2" if data.propulsion is not None else "the aircraft's derivatives"
    print(f"  phugoid of `modes` (analytic A_RR, {source}): {c['analytic_phugoid_re_rad_s']:.3f} "
          f"± {c['analytic_phugoid_im_rad_s']:.3f}i rad/s. X_u: JSBSim "
          f"{c['jsbsim_x_u_1_s']:.4f}, analytic {c['analytic_x_u_1_s']:.4f} 1/s", end="")
    if data.propulsion is None:
        print(" (no engine: no thrust term)")
    else:
        print(f"; the propeller's thrust change with airspeed dT/dV / m = "
              f"{c['thrust_term_1_s']:.4f} 1/s is in JSBSim's model and not in Table B2")
    return 0
