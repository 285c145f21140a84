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
command prints it beside the difference. JSON keys: speed_m_s, states, A, eigenvalues,
inputs, input_units, B, phugoid_comparison."""


def register(sub) -> None:
    p = sub.add_parser(
        "linearize", help="rigid longitudinal linear model from JSBSim", description=HELP
    )
    add_flight_condition_arguments(p)
    p.add_argument("--json", action="store_true", help="print JSON (SI) instead of a table")
    p.set_defaults(run=run)


def b_matrix(lin):
    """B [4 x 3] of the inputs (w_g [m/s], elevator [rad], throttle [-]) for the JSBSim
    model ``lin``: the gust column from JSBSim's A, the control columns analytic."""
    import numpy as np

    from bioflex_jsb.flight_dynamics.lti import control_columns
    from bioflex_jsb.flight_dynamics.rigid import level_flight_condition

    g_r = np.asarray(lin.a, dtype=float)[:, 1] / lin.speed_m_s
    return np.column_stack([g_r, control_columns(level_flight_condition(lin.speed_m_s))])


def phugoid_comparison(lin) -> dict:
    """JSBSim's phugoid and X_u against the analytic model's (``modes``), and the thrust
    term that makes the difference (SI: rad/s, 1/s)."""
    import numpy as np

    from bioflex_jsb.flight_dynamics.lti import build_state_space, thrust_speed_derivative_n_s_m
    from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
    from bioflex_jsb.parameters.airframe import MASS_PROPERTIES

    cond = level_flight_condition(lin.speed_m_s)
    a_an = build_state_space("rigid", cond).a
    lam = np.linalg.eigvals(a_an)
    ph = min((z for z in lam if z.imag >= 0.0), key=abs)
    return {
        "jsbsim_x_u_1_s": float(lin.a[0][0]),
        "analytic_x_u_1_s": float(a_an[0, 0]),
        "thrust_term_1_s": thrust_speed_derivative_n_s_m(cond) / MASS_PROPERTIES.mass_kg,
        "analytic_phugoid_re_rad_s": float(ph.real),
        "analytic_phugoid_im_rad_s": float(abs(ph.imag)),
    }


def linearization_payload(lin) -> dict:
    """JSON form: speed_m_s, states, A, eigenvalues, then inputs, input_units, B and
    phugoid_comparison."""
    b = b_matrix(lin)
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
        "inputs": ["w_g", "elevator", "throttle"],
        "input_units": ["m/s", "rad", "-"],
        "B": [[float(x) for x in row] for row in b],
        "phugoid_comparison": phugoid_comparison(lin),
    }


def run(args: argparse.Namespace) -> int:
    airframe = load_airframe(args)
    lin = airframe.linearize(args.speed, args.altitude)
    if args.json:
        print_json(linearization_payload(lin))
        return 0
    print(f"Rigid longitudinal model at {lin.speed_m_s:g} m/s (JSBSim FGLinearization)")
    header = "".join(f"{s:>12}" for s in lin.states)
    print(f"  A, x_R = [u m/s, alpha rad, q rad/s, theta rad]\n  {'':8}{header}")
    for name, row in zip(lin.states, lin.a, strict=True):
        print(f"  {name + ' dot':<8}" + "".join(f"{x:12.4g}" for x in row))
    b = b_matrix(lin)
    print("  B, u = [w_g m/s (JSBSim's A), elevator rad, throttle - (analytic)]")
    print(f"  {'':8}" + "".join(f"{s:>12}" for s in ("w_g", "elevator", "throttle")))
    for name, row in zip(lin.states, b, strict=True):
        print(f"  {name + ' dot':<8}" + "".join(f"{x:12.4g}" for x in row))
    print(f"  {'mode':<14}{'re':>10}{'im':>10}{'damping':>10}{'freq':>10}  [rad/s]")
    for ev in lin.eigenvalues:
        print(
            f"  {ev.mode:<14}{ev.re:10.3f}{ev.im:10.3f}{ev.damping:10.3f}{ev.frequency_rad_s:10.3f}"
        )
    c = phugoid_comparison(lin)
    print(f"  phugoid of `modes` (analytic A_RR, Table B2): {c['analytic_phugoid_re_rad_s']:.3f} "
          f"± {c['analytic_phugoid_im_rad_s']:.3f}i rad/s. The difference is X_u: JSBSim "
          f"{c['jsbsim_x_u_1_s']:.4f}, analytic {c['analytic_x_u_1_s']:.4f} 1/s; the "
          f"propeller's thrust change with airspeed dT/dV / m = {c['thrust_term_1_s']:.4f} 1/s "
          "is in JSBSim's model and not in Table B2")
    return 0
