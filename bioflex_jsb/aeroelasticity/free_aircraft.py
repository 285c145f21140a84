"""Unsteady strip aerodynamics for the paper's free aircraft: Eq. (4) with named lag states.

The paper's elastic wing (Eq. 3, Table B1) carries quasi-steady strips: lift
L_qs = ½ρV² C_lα c · α_qs at each strip's aerodynamic centre, with the angle

    α_qs = α + Σ θ_i η_i + Σ φ_i η̇_i / V − d q / V      (d = x_cg − x_ac, AC ahead of CG),

and work arms (e θ_i − φ_i) on mode i and d on the pitching moment (e = x_E − x_ac, after
the C_η1^Q1 pin's shift). This module adds to Eq. (4), strip by strip (the lattice's own
strips, starboard half doubled: symmetric modes), the difference between Theodorsen's
loads and those quasi-steady ones:

* circulatory: L_c = ½ρV C_lα c · [C(k) w_¾], with the three-quarter-chord upwash of the
  section's own kinematics (physical chord: x_¾ = x_le + ¾ c),

      w_¾ = V(α + Σ θ_i η_i) + Σ [φ_i + (x_¾ − x_E) θ_i] η̇_i − (x_cg − x_¾) q,

  and C(k) by R. T. Jones's two exponentials (Wagner's function; Jones 1940, NACA Rep. 681),
  i.e. two lag states per strip (named ``lag1[k]``, ``lag2[k]``, units m/s):
  ẋ_j = −β_j V/b x_j + A_j β_j V/b w_¾ and C w_¾ → (1 − A_1 − A_2) w_¾ + x_1 + x_2.
  The increment L_c − L_qs is applied with the paper's arms (e θ_i − φ_i, d), so in a
  steady state (no rates, lags at rest) it vanishes: trim, the static deflection and the
  divergence speed are the paper model's.
* non-circulatory (apparent mass, thin aerofoil, about the physical elastic axis
  a = 2 x_E,frac − 1 semichords aft of mid-chord): Theodorsen's L_nc and M_nc on the
  section's heave acceleration ḧ_E = u_0(α̇ − q) − (x_cg − x_E) q̇ + Σ φ_i η̈_i (down) and
  pitch α_s with α̇_s = q + Σ θ_i η̇_i, α̈_s = q̇ + Σ θ_i η̈_i; applied with physical arms.

Rigid rows: the strips' lift and moment about the CG enter Ż/M like Table B2's elastic
rows (Δα̇ = ΔZ/(m u_0), Δq̇ = ΔM/I_yy + M_ẇ ΔZ/m, Δu̇ = the induced drag of the lift
increment, 2 k C_L0 ΔL); generalised forces over the m_i of the wing model's mass basis.
The accelerations the apparent mass brings (α̇, q̇, η̈) are moved to the left:
(I − R F_ẋ) ẋ = (A_4 + R F_x) x. Gust: by default the paper's input (G_R, G_E: the gust
lift at once); ``gust=True`` replaces the wing strips' share by Küssner's function (Sears &
Sparks's two exponentials, states ``kussner1[k]``, ``kussner2[k]`` [m/s]; the gust reaches
every strip at once, no penetration along the chord of the aircraft; the tail's share stays
the paper's). Strips are normal to y: the outer panel's sweep is not corrected for.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from bioflex_jsb.aeroelasticity.strip_increments import strip_increments
from bioflex_jsb.flight_dynamics import eigen
from bioflex_jsb.flight_dynamics import flutter_engine as engine
from bioflex_jsb.flight_dynamics.lti import StateSpace, build_state_space
from bioflex_jsb.flight_dynamics.modal_coefficients import shifted, spanwise_geometry
from bioflex_jsb.flight_dynamics.rigid import (
    alpha_rate_scale,
    level_flight_condition,
    rigid_derivatives,
)
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3

AERO_MODELS = engine.AERO_MODELS
EXCLUDED = eigen.EXCLUDED_FROM_FLUTTER


@dataclass(frozen=True)
class StripGeometry:
    """Per-strip data of a built paper wing (starboard strips; ``weights_m`` whole span)."""

    weights_m: np.ndarray
    chord_m: np.ndarray
    cl_alpha_c_m: np.ndarray
    e_m: np.ndarray  # x_E − x_ac after the pin's shift (the paper's arm)
    d_m: np.ndarray  # x_cg − x_ac (the paper's arm)
    d_e_m: np.ndarray  # x_cg − x_E (physical)
    d_34_m: np.ndarray  # x_cg − x_¾ (physical)
    e_34_m: np.ndarray  # x_¾ − x_E (physical)
    a: np.ndarray  # physical elastic axis, semichords aft of mid-chord
    phi: np.ndarray  # (n, K) bending per unit η (down) [m]
    theta: np.ndarray  # (n, K) twist per unit η (LE up) [rad]


def strip_geometry(build, planform=None) -> StripGeometry:
    """The η → (h, α) per-strip projection of a :class:`WingBuild` (its modes sampled at the
    lattice's strips) and the strips' arms; ``planform`` (default the build's) replaces the
    wing's planform and CG (aeroelasticity/parameter_set.py)."""
    planform = build.planform if planform is None else planform
    modes = build.modes
    strips = spanwise_geometry(build.aero, planform, modes.x_elastic_frac, modes.stations_m)
    pinned = shifted(strips, build.e_shift_frac * planform.chord_m)
    y = strips.stations_m
    c = strips.chord_m
    xe_frac = np.interp(y, modes.stations_m, np.asarray(modes.x_elastic_frac, dtype=float))
    x_le = planform.leading_edge_x_at(y)
    x_e = x_le + xe_frac * c
    x_34 = x_le + 0.75 * c
    phi = np.array([np.interp(y, modes.stations_m, b) for b in modes.bending_m])
    theta = np.array([np.interp(y, modes.stations_m, t) for t in modes.twist_rad])
    return StripGeometry(
        weights_m=2.0 * strips.weights_m, chord_m=c, cl_alpha_c_m=strips.cl_alpha_c_m,
        e_m=pinned.e_m, d_m=strips.d_m, d_e_m=planform.x_cg_m - x_e,
        d_34_m=planform.x_cg_m - x_34, e_34_m=x_34 - x_e, a=2.0 * xe_frac - 1.0,
        phi=phi, theta=theta,
    )


def with_damping(build, structural_damping: float | None):
    """The build's ElasticWingModel, with every mode's ζ set when given."""
    model = build.model
    if structural_damping is None:
        return model
    return replace(model, damping_ratios=np.full(model.n_modes, float(structural_damping)))


@dataclass(frozen=True, eq=False)
class DescriptorSystem:
    """E ẋ = A x + B w_g before E is inverted (states as :func:`unsteady_state_space`).

    Its rows and columns without u, α, q, θ are the clamped wing's aeroelastic system: the
    body's accelerations only reach the modes through E's off-diagonal blocks."""

    e: np.ndarray
    a: np.ndarray
    b: np.ndarray
    base: StateSpace
    states: tuple[str, ...]
    state_units: tuple[str, ...]


def unsteady_state_space(build, speed_m_s: float, *, structural_damping: float | None = None,
                         density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
                         geometry: StripGeometry | None = None,
                         gust: bool = False, a_rr: np.ndarray | None = None) -> StateSpace:
    """Eq. (4) of ``build`` (a WingBuild) at ``speed_m_s`` with unsteady strips
    (module docstring): states u, α, q, θ, η, η̇, then lag1[k], lag2[k] [m/s]; with
    ``gust`` also kussner1[k], kussner2[k] [m/s]: the wing's gust lift through Küssner's
    function (Sears & Sparks's two exponentials) instead of the paper's instantaneous one.
    ``geometry`` replaces :func:`strip_geometry` (tests: its ``e_m`` must be the one the
    build's Table B1 coefficients were computed with). ``a_rr`` replaces the analytic rigid
    block (JSBSim's linearization at the same trim, as ``compare`` does; G_R follows it)."""
    d = unsteady_descriptor(build, speed_m_s, structural_damping=structural_damping,
                            density_kg_m3=density_kg_m3, geometry=geometry, gust=gust,
                            a_rr=a_rr)
    a = np.linalg.solve(d.e, d.a)
    b_in = np.linalg.solve(d.e, d.b)
    n_all = a.shape[0]
    notes = dict(d.base.notes, aero="unsteady", lag_states=n_all - d.base.n_states,
                 gust="Küssner (Sears & Sparks) on the wing's strips" if gust
                 else "quasi-steady (paper's G_R, G_E)")
    return StateSpace(model="coupled-unsteady", speed_m_s=float(speed_m_s), a=a, b=b_in,
                      c=np.eye(n_all), d=np.zeros((n_all, 1)), states=d.states,
                      state_units=d.state_units, inputs=d.base.inputs,
                      input_units=d.base.input_units, outputs=d.states,
                      output_units=d.state_units, notes=notes)


def unsteady_descriptor(build, speed_m_s: float, *, structural_damping: float | None = None,
                        density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
                        geometry: StripGeometry | None = None,
                        gust: bool = False, a_rr: np.ndarray | None = None
                        ) -> DescriptorSystem:
    """The :class:`DescriptorSystem` of :func:`unsteady_state_space`: Eq. (4) plus the
    strips' increments (:func:`~bioflex_jsb.aeroelasticity.strip_increments.strip_increments`)
    through the rigid and modal equations."""
    model = with_damping(build, structural_damping)
    cond = level_flight_condition(float(speed_m_s), density_kg_m3, airframe=model.airframe)
    base = build_state_space("coupled", cond, model, a_rr=a_rr)
    g = strip_geometry(build) if geometry is None else geometry
    n = model.n_modes
    inc = strip_increments(g, n, speed_m_s, density_kg_m3, gust=gust)
    n0, n_all = 4 + 2 * n, inc.n_states
    v = float(speed_m_s)
    ia, iq = 1, 2
    ied = slice(4 + n, 4 + 2 * n)
    af = cond.airframe
    mass, iyy = af.mass.mass_kg, af.mass.iyy_kg_m2
    rd = rigid_derivatives(cond)
    _div, f = alpha_rate_scale(rd)  # the lift of α̇ (C_Lα̇), where the derivatives have it
    mi = np.asarray(model.generalised_masses_kg_m2, dtype=float)
    k_ind = af.aero.k_induced

    def rates(z, m, q) -> np.ndarray:
        """Rows of ẋ from loads: u̇, α̇, q̇ and η̈ (θ̇, η̇ kinematic rows untouched)."""
        z, m = np.atleast_1d(z), np.atleast_1d(m)
        q = q.reshape(n, -1)
        out = np.zeros((n_all, z.size))
        out[0] = 2.0 * k_ind * cond.cl_trim * z / mass
        out[ia] = z / (mass * v) * f
        out[iq] = m / iyy + rd.m_wdot * z / mass * f
        out[ied] = q / mi[:, None]
        return out

    a_full = np.zeros((n_all, n_all))
    a_full[:n0, :n0] = base.a
    a_full += rates(inc.z_x, inc.m_x, inc.q_x)
    a_full[inc.lag_slice] += inc.lag_a
    e_mat = np.eye(n_all) - rates(inc.z_xd, inc.m_xd, inc.q_xd)
    b_in = np.zeros((n_all, 1))
    b_in[:n0] = base.b
    b_in[inc.lag_slice, 0] += inc.lag_b
    if gust:
        b_in += rates(inc.z_w, inc.m_w, inc.q_w)
    units = base.state_units + ("m/s",) * (n_all - n0)
    return DescriptorSystem(e_mat, a_full, b_in, base, inc.states, units)


def _quasi_steady_a(build, v, zeta, rho):
    cond = level_flight_condition(float(v), rho, airframe=build.model.airframe)
    return build_state_space("coupled", cond, with_damping(build, zeta)).a


def _system(build, v, aero, zeta, rho) -> np.ndarray:
    if aero == "unsteady":
        return unsteady_state_space(build, v, structural_damping=zeta, density_kg_m3=rho).a
    return _quasi_steady_a(build, v, zeta, rho)


def wing_divergence_speed_m_s(build, *, density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
                              range_m_s: tuple[float, float] = (2.0, 60.0)) -> float | None:
    """:func:`bioflex_jsb.flight_dynamics.eigen.wing_divergence_speed_m_s` of ``build``'s
    model: the wing's divergence with the body held [m/s] (None in range)."""
    return eigen.wing_divergence_speed_m_s(build.model, density_kg_m3, range_m_s)


def free_family(build, *, aero: str = "unsteady", structural_damping: float | None = None,
                density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
                start_m_s: float = eigen.SCAN_START_M_S,
                divergence_range_m_s: tuple[float, float] = (2.0, 60.0)) -> engine.EigenFamily:
    """The free aircraft (Eq. 4, ``aero`` strips) as the engine's family. Labels: the
    quasi-steady Eq. (4)'s at ``start_m_s`` (:func:`eigen.track`), given to the nearest
    roots of this system there; the strips' lag roots are ``lag``."""
    if aero not in AERO_MODELS:
        raise ValueError(f"aero must be one of {AERO_MODELS}, not {aero!r}")
    model = with_damping(build, structural_damping)
    ref = eigen.track("coupled", [float(start_m_s)], model, density_kg_m3)
    fam = engine.EigenFamily(
        lambda v: _system(build, v, aero, structural_damping, density_kg_m3),
        ref.eigenvalues[0], ref.labels, rest_label="lag", excluded=EXCLUDED,
        rigid_labels=eigen.RIGID_LABELS, paired_labels=eigen.RIGID_LABELS,
        partition=eigen.mode_labels_of_roots,
        natural_frequencies_rad_s=tuple(float(w) for w in model.frequencies_rad_s),
        mode_labels=eigen.structural_mode_labels(model.frequencies_rad_s),
        reference_semichord_m=model.airframe.reference.mean_chord_m / 2.0,
        method="state-space", aero=aero, name=build.variant.name)
    fam.divergence_speed_m_s = wing_divergence_speed_m_s(build, density_kg_m3=density_kg_m3,
                                                         range_m_s=divergence_range_m_s)
    return fam


@dataclass(frozen=True, eq=False)
class FreeTrack:
    """Tracked roots of the free aircraft: ``eigenvalues[k, j]`` at ``speeds_m_s[k]``,
    ``labels[j]`` (the quasi-steady Eq. 4's names at the first speed; ``lag`` otherwise)."""

    speeds_m_s: np.ndarray
    eigenvalues: np.ndarray
    labels: tuple[str, ...]
    last_vectors: np.ndarray

    def mode(self, k: int, name: str) -> complex:
        """The root called ``name`` at grid point ``k`` (upper one of a pair, or the less
        stable of a real pair)."""
        lam = self.eigenvalues[k][[i for i, lab in enumerate(self.labels) if lab == name]]
        upper = lam[lam.imag > 1e-6]
        return complex(upper[0] if upper.size else lam[np.argmax(lam.real)])


def track_free(build, speeds_m_s, *, aero: str = "unsteady",
               structural_damping: float | None = None,
               density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3) -> FreeTrack:
    """Eigenvalues over increasing ``speeds_m_s``, labels carried by the engine's tracker
    (eigenvector correlation + eigenvalue continuity)."""
    speeds = np.asarray(speeds_m_s, dtype=float)
    fam = free_family(build, aero=aero, structural_damping=structural_damping,
                      density_kg_m3=density_kg_m3, start_m_s=float(speeds[0]))
    tr = engine.scan(fam, speeds)
    return FreeTrack(tr.speeds_m_s, tr.roots, tr.labels, tr.points[-1].vectors)


def unsteady_mode_sets(build, speeds_m_s, structural_damping: float | None = None,
                       density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3) -> list:
    """The coupled model on unsteady strips at ``speeds_m_s`` [m/s]: its labelled roots
    (short period, phugoid, aeroelastic_i; the strips' lag roots left out) as
    :class:`eigen.ModeSet`s (labels tracked from 2 m/s on a 0.25 m/s grid)."""
    grid = eigen.sweep_grid(list(speeds_m_s))
    tr = track_free(build, grid, aero="unsteady", structural_damping=structural_damping,
                    density_kg_m3=density_kg_m3)
    index = {float(v): k for k, v in enumerate(tr.speeds_m_s)}
    names = [lab for lab in dict.fromkeys(tr.labels) if lab != "lag"]
    out = []
    for v in speeds_m_s:
        k = index[float(v)]
        modes = []
        for name in names:
            lam = tr.mode(k, name)
            unstable_real = lam.real > eigen.UNSTABLE_RE_RAD_S and abs(lam.imag) < 1e-6
            modes.append(eigen.Mode("divergence" if unstable_real else name, lam.real,
                                    abs(lam.imag), branch=name))
        out.append(eigen.ModeSet(float(v), "coupled-unsteady", tuple(modes)))
    return out


# Bisection tolerance of the free aircraft's search [m/s].
FREE_TOL_M_S = 1e-4
# The free aircraft's flutter is analysed on unsteady strips unless asked otherwise
# (api.flutter, the flutter command): quasi-steady strips (the paper's) have no aerodynamic
# pitch damping, and their single-mode torsion instability moves with the assumed structural
# damping (inertial-backward: <= 5 m/s at zeta 0, 16.6 m/s at 0.05) where the unsteady
# strips' body-freedom flutter stays at 18.9 m/s (docs/aeroelasticity.md).
FREE_DEFAULT_AERO = "unsteady"
# The free aircraft's scan step [m/s]: eigen.SCAN_STEP_M_S (0.1, the prototype's 5-40 m/s in
# 350 steps), or the range in this many steps where it is wider (the SGS's derived 9.1-182
# m/s: 0.49 m/s, where the unsteady scan finds the same 138.93 m/s as at 0.1 m/s in a fifth
# of the time; tests/test_second_aircraft.py).
FREE_SCAN_STEPS = 350


def free_scan_step_m_s(range_m_s: tuple[float, float]) -> float:
    """The scan step [m/s] of the free aircraft's flutter search over ``range_m_s``."""
    lo, hi = range_m_s
    return max(eigen.SCAN_STEP_M_S, (float(hi) - float(lo)) / FREE_SCAN_STEPS)


def free_flutter(build, *, aero: str = "unsteady", structural_damping: float | None = None,
                 range_m_s: tuple[float, float] = (5.0, 40.0),
                 step_m_s: float = eigen.SCAN_STEP_M_S,
                 density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3, progress=None,
                 full_scan: bool = False) -> engine.FlutterResult:
    """First instability of the free aircraft (phugoid left out, as in the paper): the
    engine's scan from 2 m/s in ``step_m_s``, bisection to :data:`FREE_TOL_M_S`;
    mechanism by the engine's rule (body-freedom when the short period goes unstable).
    ``progress``, ``full_scan``:
    :func:`~bioflex_jsb.flight_dynamics.flutter_engine.first_instability`'s."""
    lo, hi = range_m_s
    top = max(eigen.DIVERGENCE_SEARCH_TOP_M_S, eigen.DIVERGENCE_TOP_OVER_RANGE * hi)
    fam = free_family(build, aero=aero, structural_damping=structural_damping,
                      density_kg_m3=density_kg_m3, start_m_s=min(eigen.SCAN_START_M_S, lo),
                      divergence_range_m_s=(2.0, top))
    return engine.first_instability(
        fam, engine.default_grid((lo, hi), step_m_s, eigen.SCAN_START_M_S), (lo, hi),
        tol_m_s=FREE_TOL_M_S, structural_damping=structural_damping,
        density_kg_m3=density_kg_m3, progress=progress, full_scan=full_scan)


# --------------------------------------------------------------------------------------
# Section 4 re-analysed: the six named wings, quasi-steady vs unsteady
# --------------------------------------------------------------------------------------
PAPER_STATEMENT = {  # what the paper states (Section 4; scripts/paper_tables.py)
    "original": "no flutter up to 25 m/s; Table 3 coupled SP -5.3+8.5j (15), -7.0+10.9j (20)",
    "optimised": "no flutter up to 25 m/s",
    "inertial-forward": "no flutter up to 25 m/s; Table 6 coupled SP -5.0+7.2j (15), "
                        "-6.3+8.1j (20)",
    "elastic-forward": "no flutter up to 25 m/s",
    "inertial-backward": "body-freedom flutter above 20 m/s (short period + 1st aeroelastic)",
    "elastic-backward": "body-freedom flutter above 20 m/s (short period + 1st aeroelastic)",
}


def section4_table(zetas=(0.0, 0.02), speeds=(15.0, 20.0)) -> list[dict]:
    """Per named wing and aerodynamic model: the short-period and first aeroelastic roots at
    ``speeds`` (ζ = 0.02) and the flutter point at each ζ in ``zetas`` (5-40 m/s)."""
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

    rows = []
    grid = np.arange(2.0, max(speeds) + 0.125, 0.25)
    for name, variant in VARIANTS.items():
        build = build_wing(variant)
        for aero in AERO_MODELS:
            tr = track_free(build, grid, aero=aero, structural_damping=0.02)
            roots = {}
            for v in speeds:
                k = int(np.argmin(np.abs(tr.speeds_m_s - v)))
                roots[f"{v:g}"] = {m: [tr.mode(k, m).real, tr.mode(k, m).imag]
                                   for m in ("short_period", "aeroelastic_1")}
            flutter = {f"{z:g}": free_flutter(build, aero=aero, structural_damping=z).as_dict()
                       for z in zetas}
            rows.append({"wing": name, "aero": aero, "roots": roots, "flutter": flutter,
                         "paper": PAPER_STATEMENT[name]})
    return rows


def _print_table(rows: list[dict]) -> None:
    def root(r):
        return f"{r[0]:.2f}{r[1]:+.2f}j"

    def fl(f):
        if f["present_at_lower_end"]:
            return (f"<= {f['unstable_at_and_below_m_s']:g} m/s (unstable at the range's "
                    f"start), {f['frequency_rad_s']:.1f} rad/s {f['mode']} {f['mechanism']}")
        if f["speed_m_s"] is None:
            return "none <= 40"
        return (f"{f['speed_m_s']:.2f} m/s {f['frequency_rad_s']:.1f} rad/s "
                f"{f['mode']} {f['mechanism']}")

    for r in rows:
        print(f"{r['wing']:18} {r['aero']:12} SP15 {root(r['roots']['15']['short_period']):>14}"
              f" AE1_15 {root(r['roots']['15']['aeroelastic_1']):>15}"
              f" SP20 {root(r['roots']['20']['short_period']):>14}"
              f" AE1_20 {root(r['roots']['20']['aeroelastic_1']):>15}")
        for z, f in r["flutter"].items():
            print(f"{'':31} zeta {z:>4}: {fl(f)}")
        print(f"{'':31} paper: {r['paper']}")


def main(argv=None) -> int:
    import argparse
    import json
    import sys

    parser = argparse.ArgumentParser(
        description="Section 4 re-analysed: six named wings, quasi-steady vs unsteady strips "
        "(docs/aeroelasticity.md). Roots [rad/s] at 15, 20 m/s with zeta 0.02; flutter "
        "5-40 m/s at zeta 0 and 0.02.")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    rows = section4_table()
    if args.json:
        json.dump(rows, sys.stdout, indent=2, allow_nan=False)
        sys.stdout.write("\n")
    else:
        _print_table(rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
