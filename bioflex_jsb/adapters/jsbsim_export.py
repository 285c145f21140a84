"""The modal wing as JSBSim systems: the elastic wing flying in plain JSBSim, no Python in the loop.

:func:`render_system` writes the modal wing of one variant (``coupled`` or ``qsd``) as a JSBSim
``<system>``; :func:`render_aircraft_files` writes an aircraft, ``aircraft/bioflex_<variant>/``,
that is the generated rigid airframe of :mod:`bioflex_jsb.adapters.airframe_xml` (called
read-only, so both stay in step) with that system included. ``docs/native.md`` has the user's
view; this docstring has the numerics.

Same physics as :class:`bioflex_jsb.simulation.modal_wing.ModalWing`: modal coordinates Δη are
perturbations from the static deformation at trim, generalised forces from the current Q, V,
α (against the air, gusts included) and q, loads ΔL, ΔD, ΔM into the airframe's
``external_reactions`` (body axes: modal-lift = ΔL cos α + ΔD sin α, modal-drag =
ΔD cos α − ΔL sin α), converted once from SI with :mod:`bioflex_jsb.units`.

Integration (``coupled``): ModalWing's scheme, reference flow renewed at 5 % changes
--------------------------------------------------------------------------------------
The state x = [Δη, Δη̇] advances once per JSBSim step exactly as ``ModalWing._advance``:

    x_{k+1} = Φ_r x_k + Ψ_r g_k,   g = (Q − Q_r) K_a Δη + (Q/V − Q_r/V_r) D_a Δη̇
                                       + Q Δα b_α + (Q/V) q b_q + (Q − Q_0) b_0,

with Φ_r = e^{A_r Δt}, Ψ_r = ∫_0^Δt e^{A_r τ} dτ at the reference flow (Q_r, V_r), which is
renewed (Q_r ← Q, V_r ← V) when Q or V moves by more than :data:`REFRESH_REL` (ModalWing's
default, 5 %) — the same reference points as the co-simulation. The renewal is a JSBSim
channel run only when needed (``<channel execute="bioflex/modal/renew">``): its 54 table
lookups (Φ_r, Ψ_r against Q, rows every 0.5 m/s of V_ref(Q) = sqrt(2Q/ρ_ref) up to
:data:`GRID_SPEED_MAX_M_S`, computed here with ``scipy.linalg.expm``, linearly interpolated
by JSBSim) are latched into properties; a normal step is a few products and sums with no
table. Q_r/V_r is taken as Q_r/V_ref(Q_r), the table's, so away from ρ_ref the correction
term also carries the density difference.

The step is computed row by row in place (:func:`in_place_step`: the tabulated coefficients
are rewritten so that row k reads the rows already overwritten), so JSBSim needs neither
temporaries nor a commit. Exact at the reference flow for any step: the third mode
(≈ 107 Hz, ω Δt = 0.7 at 1/960 s, 5.6 at 1/120 s) has no stability limit.

Φ and Ψ hold for ONE step, the exported ``dt_s`` (default 1/960 s, the co-simulation's
step; ``--dt`` for others). ``bioflex/modal/active`` is 1 only when ``simulation/dt``
equals it. While it is 0 (JSBSim's initial-condition run and trim suspend integration with
dt = 0, or a host running another step) only the channel ``execute="bioflex/modal/idle"``
runs: it latches the trim reference α_0, Q_0 from JSBSim's air data, holds the modal state
and loads at zero and clears the reference flow (renewed at the first active step, as
ModalWing's first step).

Flow: JSBSim's air data of the previous step (``aero/alpha-rad``, ``velocities/vt-fps``;
Q = ρV²/2) — the state the co-simulation reads — and, in a step where the down wind
changed, the same quantities recomputed from ``velocities/{u,v,w}-aero-fps`` with this
step's change of the wind (the co-simulation writes the wind before the step); ``ifthen``
evaluates only that branch, so steady wind costs nothing extra.

``qsd``: Δη = K(Q)⁻¹ [Q Δα b_α + (Q/V) q b_q + (Q − Q_0) b_0], K(Q) = diag(ω²) − Q K_a, with
K(Q)⁻¹ tabulated on the same grid; Δη̇ = 0.

Order inside a JSBSim step: JSBSim runs its systems after integrating the state and before
the aerodynamics and the external reactions, and the systems read the flow computed at the
end of the previous step (with this step's wind change, above). The loads of step k come
from Δη_k in that flow; then Δη_{k+1} is computed from the same flow, as in the
co-simulation (its one-step coupling lag included). The loads: lift and pitching moment;
the modal drag is k₂ = 2kC_L0 times the modal lift, so the body-axis forces are the lift
times (cos α + k₂ sin α) and (k₂ cos α − sin α).

Properties (all under ``bioflex/modal/``): ``eta<i>``, ``eta<i>-dot`` [rad, rad/s] (state),
``alpha0-rad``, ``qbar0-pa`` (latched trim reference), ``qbar-ref-pa``, ``vt-ref-m_s``
(reference flow), ``active``, ``enabled`` (set 0 to fly the rigid airframe with the same
file), ``lift-n``, ``pitch-n_m`` (wind-axis loads, SI; ``qsd`` also ``drag-n``).
"""

from __future__ import annotations

import argparse
import inspect
import math
import re
import sys
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.linalg import expm

from bioflex_jsb import units as U
from bioflex_jsb.adapters import airframe_xml
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import RIGID_AERODYNAMICS
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S, ModalWing

EXPORT_MODELS = ("coupled", "qsd")
PREFIX = "bioflex/modal"
# Q grid of the tables: uniform in V_ref = sqrt(2Q/ρ_ref) from 0 to this speed [m/s], the
# aircraft's speed range with margin (Table 1 flies 10-25 m/s); JSBSim holds the end values
# beyond it.
GRID_SPEED_MAX_M_S = 40.0
GRID_SPEED_STEP_M_S = 0.5
# Named variants written into the repository's systems/ and aircraft/ (coupled model).
REPOSITORY_VARIANTS = ("original", "optimised", "inertial-forward", "elastic-forward",
                       "inertial-backward", "elastic-backward")  # fmt: skip
# Fig. 21: optimised wing, 15 m/s, 3 m/s sharp-edged gust at 0.5 s after trim.
FIG21_VARIANT = "optimised"
FIG21_GUST_START_S = 0.5
FIG21_DURATION_S = 5.0
FIG21_SCRIPT = "scripts/fig21_native.xml"
FIG21_OUTPUT = "fig21_native.csv"
FIG21_IC = "fig21_trim"
# Airframe held at the trim while the propellers spin up to the trim RPM [s] (the physical
# rotor's time constant is ≈ 0.3 s: 5 s leaves the RPM within 1e-7 of the trim's).
FIG21_SETTLE_S = 5.0
# |simulation/dt − dt_s| below this fraction of dt_s counts as the exported step.
DT_MATCH_REL = 1e-6
# Relative change of Q or V that renews the reference flow: ModalWing's default.
REFRESH_REL = float(inspect.signature(ModalWing).parameters["refresh_rel"].default)


class ExportError(ValueError):
    """A request the exporter cannot honour (one line)."""


def _num(x: float) -> str:
    x = float(x)
    if x == 0.0:
        return "0"
    return f"{x:.12g}"


def aircraft_name(variant: str, model: str = "coupled") -> str:
    """Aircraft (directory and file) name of an exported variant, e.g. ``bioflex_optimised``."""
    safe = re.sub(r"[^A-Za-z0-9_-]+", "_", variant)
    return f"{airframe_xml.AIRCRAFT_NAME}_{safe}" + ("" if model == "coupled" else f"_{model}")


def system_name(variant: str, model: str = "coupled") -> str:
    """System file name (without .xml) of an exported variant, e.g. ``bioflex_modal_original``."""
    safe = re.sub(r"[^A-Za-z0-9_-]+", "_", variant)
    return f"bioflex_modal_{safe}" + ("" if model == "coupled" else f"_{model}")


# ======================================================================================
# Numbers
# ======================================================================================


@dataclass(frozen=True)
class ModalNumbers:
    """The modal wing in per-unit form (SI), as ``ModalWing`` builds it."""

    n: int
    omega: np.ndarray  # [rad/s]
    zeta: np.ndarray
    k_aero: np.ndarray  # (n, n) generalised acceleration per unit Q per rad [1/(Pa s²)]
    d_aero: np.ndarray  # (n, n) per unit Q/V per rad/s [m/(Pa s²)]... per (Pa·s/m)
    b_alpha: np.ndarray  # per unit Q per rad
    b_q: np.ndarray  # per unit Q/V per rad/s
    b_0: np.ndarray  # per unit ΔQ
    load_eta: np.ndarray  # (3, n) [C_L, C_D, C_m·c̄ (m)] per rad
    load_etadot: np.ndarray  # (3, n) per unit η̇·c̄/(2V)

    def a_matrix(self, q_pa: float, q_over_v: float) -> np.ndarray:
        n = self.n
        k = np.diag(self.omega**2) - q_pa * self.k_aero
        d = np.diag(2.0 * self.zeta * self.omega) - q_over_v * self.d_aero
        return np.block([[np.zeros((n, n)), np.eye(n)], [-k, -d]])

    def discrete(self, q_pa: float, q_over_v: float, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Φ (2n×2n) and Ψ (2n×n, the η̈-forcing columns) of one step."""
        a = self.a_matrix(q_pa, q_over_v)
        n2 = a.shape[0]
        aug = np.zeros((2 * n2, 2 * n2))
        aug[:n2, :n2] = a
        aug[:n2, n2:] = np.eye(n2)
        e = expm(aug * dt_s)
        return e[:n2, :n2], e[:n2, n2 + self.n :]


def modal_numbers(wing: ElasticWingModel, cl_trim: float) -> ModalNumbers:
    """Per-unit modal matrices of ``wing`` with the trim lift coefficient ``cl_trim``."""
    c = wing.coefficients
    s, cb = P.REFERENCE_AREA_M2, P.MEAN_AERODYNAMIC_CHORD_M
    m = np.asarray(wing.generalised_masses_kg_m2, dtype=float)
    c_alpha = np.asarray(c.c_alpha_q, dtype=float)
    alpha_wing = cl_trim / wing.wing_lift_slope_per_rad
    c_0 = alpha_wing * c_alpha + wing.cm_ac * np.asarray(c.c_mac_q, dtype=float)
    k2 = 2.0 * RIGID_AERODYNAMICS.k_induced * cl_trim
    c_l_eta, c_l_etadot = np.asarray(c.c_l_eta, float), np.asarray(c.c_l_etadot, float)
    return ModalNumbers(
        n=wing.n_modes,
        omega=np.asarray(wing.frequencies_rad_s, dtype=float),
        zeta=np.asarray(wing.damping_ratios, dtype=float),
        k_aero=(s * cb / m)[:, None] * np.asarray(c.c_eta_q, dtype=float),
        d_aero=(s * cb**2 / (2.0 * m))[:, None] * np.asarray(c.c_etadot_q, dtype=float),
        b_alpha=s * cb / m * c_alpha,
        b_q=s * cb**2 / (2.0 * m) * np.asarray(c.c_q_q, dtype=float),
        b_0=s * cb * c_0 / m,
        load_eta=np.vstack([c_l_eta, k2 * c_l_eta, np.asarray(c.c_m_eta, float) * cb]),
        load_etadot=np.vstack([c_l_etadot, k2 * c_l_etadot, np.asarray(c.c_m_etadot, float) * cb]),
    )


def q_grid_pa(rho_ref: float = P.SEA_LEVEL_DENSITY_KG_M3) -> np.ndarray:
    """Dynamic pressures of the table rows [Pa] (uniform in V_ref)."""
    v = np.arange(0.0, GRID_SPEED_MAX_M_S + 0.5 * GRID_SPEED_STEP_M_S, GRID_SPEED_STEP_M_S)
    return 0.5 * rho_ref * v**2


def _q_over_v_ref(q_pa: float, rho_ref: float) -> float:
    return math.sqrt(max(q_pa, 0.0) * rho_ref / 2.0)


def schedule(nums: ModalNumbers, dt_s: float, rho_ref: float = P.SEA_LEVEL_DENSITY_KG_M3):
    """(Q grid, Φ stack, Ψ stack) of the coupled model's tables."""
    qs = q_grid_pa(rho_ref)
    phis, psis = [], []
    for q in qs:
        phi, psi = nums.discrete(q, _q_over_v_ref(q, rho_ref), dt_s)
        phis.append(phi)
        psis.append(psi)
    return qs, np.array(phis), np.array(psis)


def qsd_schedule(nums: ModalNumbers, rho_ref: float = P.SEA_LEVEL_DENSITY_KG_M3):
    """(Q grid, K(Q)⁻¹ stack) of the QSD model's tables."""
    qs = q_grid_pa(rho_ref)
    inv = [np.linalg.inv(np.diag(nums.omega**2) - q * nums.k_aero) for q in qs]
    return qs, np.array(inv)


def in_place_step(phi: np.ndarray, psi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients (C, D) of x⁺ = Φ x + Ψ g computed row by row in place: row k of the
    update reads v = [x⁺_0 … x⁺_{k−1}, x_k … x_{N−1}] (the rows before it already
    overwritten) and x⁺_k = C[k]·v + D[k]·g equals row k of Φ x + Ψ g exactly (the rows
    already written are solved back for the old state; Φ is near the identity, so the
    leading blocks are well conditioned). No temporaries and no commit step in JSBSim."""
    n2 = phi.shape[0]
    c = np.zeros_like(phi)
    d = np.zeros_like(psi)
    for k in range(n2):
        if k == 0:
            c[k], d[k] = phi[k], psi[k]
            continue
        inv = np.linalg.inv(phi[:k, :k])
        left = phi[k, :k] @ inv
        c[k, :k] = left
        c[k, k:] = phi[k, k:] - left @ phi[:k, k:]
        d[k] = psi[k] - left @ psi[:k]
    return c, d


def interpolation_error(
    nums: ModalNumbers, dt_s: float, rho_ref: float = P.SEA_LEVEL_DENSITY_KG_M3
) -> float:
    """Largest |Φ_interp − Φ_exact| (max-abs entry) at the grid midpoints up to 30 m/s."""
    qs, phis, _ = schedule(nums, dt_s, rho_ref)
    worst = 0.0
    for i in range(len(qs) - 1):
        v_mid = 0.5 * (math.sqrt(2 * qs[i] / rho_ref) + math.sqrt(2 * qs[i + 1] / rho_ref))
        if v_mid > 30.0:
            break
        q_mid = 0.5 * rho_ref * v_mid**2
        w = (q_mid - qs[i]) / (qs[i + 1] - qs[i])
        approx = (1 - w) * phis[i] + w * phis[i + 1]
        exact, _ = nums.discrete(q_mid, _q_over_v_ref(q_mid, rho_ref), dt_s)
        worst = max(worst, float(np.max(np.abs(approx - exact))))
    return worst


def spectral_radius_max(nums: ModalNumbers, dt_s: float, speed_max_m_s: float = 30.0,
                        rho_ref: float = P.SEA_LEVEL_DENSITY_KG_M3) -> float:
    """Largest |eigenvalue| of Φ over the grid up to ``speed_max_m_s`` (< 1: stable)."""
    qs, phis, _ = schedule(nums, dt_s, rho_ref)
    keep = qs <= 0.5 * rho_ref * speed_max_m_s**2
    return float(max(np.max(np.abs(np.linalg.eigvals(p))) for p in phis[keep]))


# ======================================================================================
# XML
# ======================================================================================


def _el(parent: ET.Element, tag: str, text: str | float | None = None, **attrib) -> ET.Element:
    e = ET.SubElement(parent, tag, {k: str(v) for k, v in attrib.items()})
    if text is not None:
        e.text = text if isinstance(text, str) else _num(text)
    return e


def _prop(parent: ET.Element, name: str) -> None:
    _el(parent, "property", name)


def _value(parent: ET.Element, x: float) -> None:
    _el(parent, "value", float(x))


def _product(parent: ET.Element, *terms) -> ET.Element:
    """<product> of terms: str → property, number → value, Element builder → callable."""
    p = _el(parent, "product")
    for t in terms:
        if isinstance(t, str):
            _prop(p, t)
        elif callable(t):
            t(p)
        else:
            _value(p, t)
    return p


def _fcs(channel: ET.Element, name: str, description: str, output: str | None = None):
    comp = _el(channel, "fcs_function", name=name)
    _el(comp, "description", description)
    fn = _el(comp, "function")
    if output:
        _el(comp, "output", output)
    return fn


def _linear(parent: ET.Element, pairs: list[tuple[float, str]]) -> None:
    """Σ coefficient·property, skipping zero coefficients, into ``parent`` (a <sum>)."""
    for coef, prop in pairs:
        if coef != 0.0:
            _product(parent, float(coef), prop)


def _table(parent: ET.Element, var: str, xs: np.ndarray, ys: np.ndarray) -> None:
    t = _el(parent, "table")
    _el(t, "independentVar", var, lookup="row")
    rows = "".join(f"\n          {_num(x):>20} {_num(y):>20}" for x, y in zip(xs, ys, strict=True))
    _el(t, "tableData", rows + "\n        ")


def _p(name: str) -> str:
    return f"{PREFIX}/{name}"


@dataclass(frozen=True)
class ExportSpec:
    """What to export: the wing, its name, the model, the step [s], the trim speed [m/s] of
    the trim lift coefficient (C_0^Q and the induced-drag slope), the reference density."""

    wing: ElasticWingModel
    variant: str
    model: str = "coupled"
    dt_s: float = DEFAULT_DT_S
    speed_m_s: float = P.CRUISE_SPEED_M_S
    rho_ref: float = P.SEA_LEVEL_DENSITY_KG_M3

    def __post_init__(self) -> None:
        if self.model not in EXPORT_MODELS:
            raise ExportError(f"unknown model {self.model!r}; accepted: {', '.join(EXPORT_MODELS)}")
        if not (math.isfinite(self.dt_s) and 0.0 < self.dt_s <= 0.1):
            raise ExportError(f"time step must be in (0, 0.1] s, got {self.dt_s!r}")
        if not (math.isfinite(self.speed_m_s) and 0.0 < self.speed_m_s <= GRID_SPEED_MAX_M_S):
            raise ExportError(
                f"speed must be in (0, {GRID_SPEED_MAX_M_S:g}] m/s, got {self.speed_m_s!r}"
            )

    @property
    def cl_trim(self) -> float:
        return level_flight_condition(self.speed_m_s, self.rho_ref).cl_trim


def render_system(spec: ExportSpec) -> str:
    """Text of ``systems/bioflex_modal_<variant>.xml``."""
    nums = modal_numbers(spec.wing, spec.cl_trim)
    n = nums.n
    root = ET.Element("system", name=system_name(spec.variant, spec.model))
    _el(root, "description",
        f"Modal wing '{spec.variant}' ({spec.model}, {n} modes) of the bioflex UAV, generated by "
        "bioflex_jsb.adapters.jsbsim_export (see its docstring and docs/native.md). "
        f"Exported for a time step of {_num(spec.dt_s)} s (simulation/dt must equal it; else "
        f"{PREFIX}/active = 0 and the wing is rigid), trim C_L {spec.cl_trim:.6g} "
        f"({spec.speed_m_s:g} m/s), reference density {spec.rho_ref:g} kg/m3.")
    eta = [_p(f"eta{i + 1}") for i in range(n)]
    etad = [_p(f"eta{i + 1}-dot") for i in range(n)]
    if spec.model == "coupled":
        _coupled_system(root, spec, nums, eta, etad)
        return _serialise(root)
    for name in eta:
        _el(root, "property", name, value="0")
    _el(root, "property", _p("alpha0-rad"), value="0")
    _el(root, "property", _p("qbar0-pa"), value="0")
    _el(root, "property", _p("enabled"), value="1")
    _el(root, "property", _p("wind-down-prev-fps"), value="0")

    ch = _el(root, "channel", name="Modal wing flow")
    _comment(ch, "flow at the wing in SI (wind of this step included)")
    fn = _fcs(ch, _p("active"), "1 when simulation/dt is the exported step, else 0 (IC, trim)")
    ift = _el(fn, "ifthen")
    lt = _el(ift, "lt")
    ab = _el(lt, "abs")
    diff = _el(ab, "difference")
    _prop(diff, "simulation/dt")
    _value(diff, spec.dt_s)
    _value(lt, DT_MATCH_REL * spec.dt_s)
    _value(ift, 1.0)
    _value(ift, 0.0)
    _flow(ch)
    for prop, src in (("alpha0-rad", _p("alpha-rad")), ("qbar0-pa", _p("qbar-pa"))):
        fn = _fcs(ch, _p(prop.replace("0-", "0-latch-")),
                  f"trim reference: latched from {src} while not active", output=_p(prop))
        ift = _el(fn, "ifthen")
        _prop(ift, _p("active"))
        _prop(ift, _p(prop))
        _prop(ift, src)
    fn = _fcs(ch, _p("dalpha-rad"), "angle of attack from trim, gust included [rad]")
    d = _el(fn, "difference")
    _prop(d, _p("alpha-rad"))
    _prop(d, _p("alpha0-rad"))
    fn = _fcs(ch, _p("dqbar-pa"), "dynamic pressure from trim [Pa]")
    d = _el(fn, "difference")
    _prop(d, _p("qbar-pa"))
    _prop(d, _p("qbar0-pa"))

    ch = _el(root, "channel", name="Modal wing")
    _qsd_state(ch, spec, nums, eta)
    _loads(ch, spec, nums, eta, [])
    _comment(ch, "this step's down wind, for the next step's change")
    g = _el(ch, "pure_gain", name=_p("wind-down-store"))
    _el(g, "input", "atmosphere/wind-down-fps")
    _el(g, "gain", 1.0)
    _el(g, "output", _p("wind-down-prev-fps"))
    return _serialise(root)


def _comment(parent: ET.Element, text: str) -> None:
    parent.append(ET.Comment(f" {text} "))


def _max(parent: ET.Element, prop: str, floor: float) -> None:
    m = _el(parent, "max")
    _prop(m, prop)
    _value(m, floor)


def _flow(ch: ET.Element) -> None:
    """α, V, Q, Q/V of this step: JSBSim's air-relative body velocities (computed at the end
    of the previous step) with this step's change of the vertical wind added, so a gust
    reaches the wing in the step it reaches the rigid aerodynamics (as in the co-simulation)."""
    fn = _fcs(ch, _p("dwind-down-fps"), "change of the down wind since the previous step [ft/s]")
    d = _el(fn, "difference")
    _prop(d, "atmosphere/wind-down-fps")
    _prop(d, _p("wind-down-prev-fps"))
    cos_t = lambda p: _prop(_el(p, "cos"), "attitude/theta-rad")  # noqa: E731
    sin_t = lambda p: _prop(_el(p, "sin"), "attitude/theta-rad")  # noqa: E731
    cos_f = lambda p: _prop(_el(p, "cos"), "attitude/phi-rad")  # noqa: E731
    sin_f = lambda p: _prop(_el(p, "sin"), "attitude/phi-rad")  # noqa: E731
    dwd = _p("dwind-down-fps")
    for axis, terms in (("u", [(1.0, sin_t)]), ("v", [(-1.0, sin_f, cos_t)]),
                        ("w", [(-1.0, cos_f, cos_t)])):  # fmt: skip
        s = _el(_fcs(ch, _p(f"{axis}-air-fps"), f"air-relative body {axis} [ft/s]"), "sum")
        _prop(s, f"velocities/{axis}-aero-fps")
        for sign, *factors in terms:
            _product(s, sign, dwd, *factors)
    fn = _fcs(ch, _p("alpha-rad"), "angle of attack against the air, gust included [rad]")
    at = _el(fn, "atan2")
    _prop(at, _p("w-air-fps"))
    _prop(at, _p("u-air-fps"))
    fn = _fcs(ch, _p("vt-m_s"), "true airspeed V [m/s] (at least 1 ft/s: no division by 0)")
    m = _el(_el(fn, "product"), "max")
    s = _el(_el(m, "sqrt"), "sum")
    for axis in "uvw":
        _product(s, _p(f"{axis}-air-fps"), _p(f"{axis}-air-fps"))
    _value(m, 1.0)
    fn.find("product").append(_value_el(U.M_PER_FT))
    fn = _fcs(ch, _p("qbar-pa"), "dynamic pressure Q = rho V^2/2 [Pa]")
    _product(fn, 0.5 * U.KG_M3_PER_SLUG_FT3, "atmosphere/rho-slugs_ft3", _p("vt-m_s"), _p("vt-m_s"))
    fn = _fcs(ch, _p("q-over-v"), "Q/V [Pa s/m]")
    q = _el(fn, "quotient")
    _prop(q, _p("qbar-pa"))
    _prop(q, _p("vt-m_s"))


def _flow_fast(ch: ET.Element) -> None:
    """α, V, Q, Q/V of this step, as :func:`_flow`, but JSBSim's own air data (``aero/*``,
    the same formulas) when the down wind did not change since the previous step: the
    body-axis correction is evaluated only in steps where the wind changed (``ifthen``
    evaluates one branch)."""
    fn = _fcs(ch, _p("wind-changed"), "1 when the down wind changed since the previous step")
    ne = _el(fn, "nq")
    _prop(ne, "atmosphere/wind-down-fps")
    _prop(ne, _p("wind-down-prev-fps"))

    def dwd(p):
        d = _el(p, "difference")
        _prop(d, "atmosphere/wind-down-fps")
        _prop(d, _p("wind-down-prev-fps"))

    cos_t = lambda p: _prop(_el(p, "cos"), "attitude/theta-rad")  # noqa: E731
    sin_t = lambda p: _prop(_el(p, "sin"), "attitude/theta-rad")  # noqa: E731
    cos_f = lambda p: _prop(_el(p, "cos"), "attitude/phi-rad")  # noqa: E731
    sin_f = lambda p: _prop(_el(p, "sin"), "attitude/phi-rad")  # noqa: E731
    terms = {"u": [(1.0, sin_t)], "v": [(-1.0, sin_f, cos_t)], "w": [(-1.0, cos_f, cos_t)]}

    def air(parent, axis):
        s = _el(parent, "sum")
        _prop(s, f"velocities/{axis}-aero-fps")
        for sign, *factors in terms[axis]:
            _product(s, sign, dwd, *factors)

    fn = _fcs(ch, _p("alpha-rad"), "angle of attack against the air, gust included [rad]")
    ift = _el(fn, "ifthen")
    _prop(ift, _p("wind-changed"))
    at = _el(ift, "atan2")
    air(at, "w")
    air(at, "u")
    _prop(ift, "aero/alpha-rad")
    fn = _fcs(ch, _p("vt-m_s"), "true airspeed V [m/s] (at least 1 ft/s: no division by 0)")
    m = _el(_product(fn, U.M_PER_FT), "max")
    ift = _el(m, "ifthen")
    _prop(ift, _p("wind-changed"))
    s = _el(_el(ift, "sqrt"), "sum")
    for axis in "uvw":
        p = _el(s, "pow")
        air(p, axis)
        _value(p, 2.0)
    _prop(ift, "velocities/vt-fps")
    _value(m, 1.0)
    fn = _fcs(ch, _p("qbar-pa"), "dynamic pressure Q = rho V^2/2 [Pa]")
    _product(fn, 0.5 * U.KG_M3_PER_SLUG_FT3, "atmosphere/rho-slugs_ft3", _p("vt-m_s"), _p("vt-m_s"))
    fn = _fcs(ch, _p("q-over-v"), "Q/V [Pa s/m]")
    _product(fn, 0.5 * U.KG_M3_PER_SLUG_FT3, "atmosphere/rho-slugs_ft3", _p("vt-m_s"))


def _value_el(x: float) -> ET.Element:
    e = ET.Element("value")
    e.text = _num(x)
    return e


def _forcing_terms(fn_sum: ET.Element, nums: ModalNumbers, i: int) -> None:
    """Q Δα b_α + (Q/V) q b_q + ΔQ b_0 for mode i (SI generalised acceleration)."""
    _product(fn_sum, float(nums.b_alpha[i]), _p("qbar-pa"), _p("dalpha-rad"))
    _product(fn_sum, float(nums.b_q[i]), _p("q-over-v"), "velocities/q-rad_sec")
    _product(fn_sum, float(nums.b_0[i]), _p("dqbar-pa"))


def _qsd_state(ch, spec: ExportSpec, nums: ModalNumbers, eta: list[str]) -> None:
    n = nums.n
    _comment(ch, "quasi-static deformation: eta = K(Q)^-1 r, K(Q) = diag(w^2) - Q K_a (tables)")
    for i in range(n):
        s = _el(_fcs(ch, _p(f"r{i + 1}"), f"static generalised force on mode {i + 1} [1/s2]"),
                "sum")
        _forcing_terms(s, nums, i)
    qs, inv = qsd_schedule(nums, spec.rho_ref)
    for i in range(n):
        fn = _fcs(ch, _p(f"eta{i + 1}-qsd"), f"quasi-static eta{i + 1} [rad]", output=eta[i])
        prod = _el(fn, "product")
        _prop(prod, _p("active"))
        s = _el(prod, "sum")
        for j in range(n):
            row = inv[:, i, j]
            _product(s, lambda p, row=row: _table(p, _p("qbar-pa"), qs, row), _p(f"r{j + 1}"))


def _loads(ch, spec: ExportSpec, nums: ModalNumbers, eta: list[str], etad: list[str]) -> None:
    s_ref, cb = P.REFERENCE_AREA_M2, P.MEAN_AERODYNAMIC_CHORD_M
    _comment(ch, "incremental loads: Q S (C_eta eta + C_etadot etadot cbar/(2V)), wind axes, SI")
    names = (("lift-n", "lift, up, normal to the air velocity [N]"),
             ("drag-n", "drag, aft, along the air velocity [N]"),
             ("pitch-n_m", "pitching moment about the CG, nose up [N m]"))  # fmt: skip
    for r, (name, text) in enumerate(names):
        prod = _el(_fcs(ch, _p(name), text), "product")
        _prop(prod, _p("enabled"))
        total = _el(prod, "sum")
        if any(nums.load_eta[r]):
            inner = _product(total, s_ref, _p("qbar-pa"))
            _linear(_el(inner, "sum"), list(zip(nums.load_eta[r], eta, strict=True)))
        if etad and any(nums.load_etadot[r]):
            inner = _product(total, s_ref * cb / 2.0, _p("q-over-v"))
            _linear(_el(inner, "sum"), list(zip(nums.load_etadot[r], etad, strict=True)))
    _comment(ch, "into the airframe's external reactions, body axes, JSBSim units")
    lift, drag = _p("lift-n"), _p("drag-n")
    cos_a = lambda p: _el(_el(p, "cos"), "property", _p("alpha-rad"))  # noqa: E731
    sin_a = lambda p: _el(_el(p, "sin"), "property", _p("alpha-rad"))  # noqa: E731
    for name, first, second, sign in (("modal-lift", lift, drag, 1.0),
                                      ("modal-drag", drag, lift, -1.0)):  # fmt: skip
        fn = _fcs(ch, _p(f"{name}-lbs"), f"{name} force [lbs]",
                  output=airframe_xml.external_property(name))
        s = _el(_product(fn, U.LBF_PER_N), "sum")
        _product(s, first, cos_a)
        _product(s, sign, second, sin_a)
    fn = _fcs(ch, _p("modal-pitch-lbsft"), "modal-pitch moment [lbs ft]",
              output=airframe_xml.external_property("modal-pitch"))
    _product(fn, U.LBF_FT_PER_N_M, _p("pitch-n_m"))


def _assign(ch: ET.Element, name: str, description: str, value, outputs: list[str]) -> None:
    """One fcs_function writing ``value`` (property name or number) to every output."""
    comp = _el(ch, "fcs_function", name=name)
    _el(comp, "description", description)
    fn = _el(comp, "function")
    if isinstance(value, str):
        _prop(fn, value)
    else:
        _value(fn, value)
    for out in outputs:
        _el(comp, "output", out)


def _coupled_system(root: ET.Element, spec: ExportSpec, nums: ModalNumbers, eta, etad) -> None:
    """Channels of the coupled model (module docstring): mode, trim reference (idle only),
    flow, reference renewal (only when the flow moved past ``REFRESH_REL``), step."""
    n = nums.n
    state = eta + etad
    coef_phi = [[_p(f"phi-{k + 1}-{j + 1}") for j in range(2 * n)] for k in range(2 * n)]
    coef_psi = [[_p(f"psi-{k + 1}-{m + 1}") for m in range(n)] for k in range(2 * n)]
    for name in state:
        _el(root, "property", name, value="0")
    for name in ("alpha0-rad", "qbar0-pa", "qbar-ref-pa", "vt-ref-m_s", "q-over-v-ref",
                 "renew", "idle", "wind-down-prev-fps"):  # fmt: skip
        _el(root, "property", _p(name), value="0")
    _el(root, "property", _p("enabled"), value="1")
    for row in coef_phi + coef_psi:
        for name in row:
            _el(root, "property", name, value="0")
    qs, phis, psis = schedule(nums, spec.dt_s, spec.rho_ref)
    steps = [in_place_step(phi, psi) for phi, psi in zip(phis, psis, strict=True)]
    phis = np.array([c for c, _ in steps])
    psis = np.array([d for _, d in steps])

    ch = _el(root, "channel", name="Modal wing mode")
    fn = _fcs(ch, _p("active"), "1 when simulation/dt is the exported step, else 0 (IC, trim)")
    ift = _el(fn, "ifthen")
    lt = _el(ift, "lt")
    diff = _el(_el(lt, "abs"), "difference")
    _prop(diff, "simulation/dt")
    _value(diff, spec.dt_s)
    _value(lt, DT_MATCH_REL * spec.dt_s)
    _value(ift, 1.0)
    _value(ift, 0.0)
    fn = _fcs(ch, _p("idle-flag"), "1 while not active", output=_p("idle"))
    d = _el(fn, "difference")
    _value(d, 1.0)
    _prop(d, _p("active"))

    ch = _el(root, "channel", name="Modal wing trim reference", execute=_p("idle"))
    _comment(ch, "while not active (IC, trim, another step): the trim reference latched from "
                 "the flow, the modal state and loads held at zero, the reference flow reset")
    _assign(ch, _p("alpha0-latch"), "trim angle of attack [rad]", "aero/alpha-rad",
            [_p("alpha0-rad")])
    fn = _fcs(ch, _p("qbar0-latch"), "trim dynamic pressure [Pa]", output=_p("qbar0-pa"))
    _product(fn, U.PA_PER_PSF, "aero/qbar-psf")
    _assign(ch, _p("reset"), "modal state, loads and reference flow to zero", 0.0,
            state + [_p("qbar-ref-pa"), _p("vt-ref-m_s"), _p("renew"), _p("lift-n"),
                     _p("pitch-n_m")]
            + [airframe_xml.external_property(x)
               for x in ("modal-lift", "modal-drag", "modal-pitch")])
    _assign(ch, _p("wind-down-hold"), "down wind [ft/s], for the first active step's change",
            "atmosphere/wind-down-fps", [_p("wind-down-prev-fps")])

    ch = _el(root, "channel", name="Modal wing flow", execute=_p("active"))
    _flow_fast(ch)
    fn = _fcs(ch, _p("renew-test"), f"1 when Q or V moved by more than {REFRESH_REL:g} of the "
              "reference flow (ModalWing's renewal)", output=_p("renew"))
    orr = _el(fn, "or")
    for cur, ref in (("qbar-pa", "qbar-ref-pa"), ("vt-m_s", "vt-ref-m_s")):
        gt = _el(orr, "gt")
        d = _el(_el(gt, "abs"), "difference")
        _prop(d, _p(cur))
        _prop(d, _p(ref))
        _product(gt, REFRESH_REL, _p(ref))

    ch = _el(root, "channel", name="Modal wing reference renewal", execute=_p("renew"))
    _comment(ch, f"exact step of {_num(spec.dt_s)} s at the new reference flow: "
                 "Phi = e^(A dt), Psi (tables in Q; run only at a renewal)")
    _assign(ch, _p("qbar-ref-latch"), "reference Q [Pa]", _p("qbar-pa"), [_p("qbar-ref-pa")])
    _assign(ch, _p("vt-ref-latch"), "reference V [m/s]", _p("vt-m_s"), [_p("vt-ref-m_s")])
    fn = _fcs(ch, _p("q-over-v-ref-latch"), "Q_r/V_ref(Q_r) of the tables [Pa s/m]",
              output=_p("q-over-v-ref"))
    _product(fn, math.sqrt(spec.rho_ref / 2.0), lambda p: _prop(_el(p, "sqrt"), _p("qbar-pa")))
    for k in range(2 * n):
        for j, name in enumerate(coef_phi[k]):
            fn = _fcs(ch, f"{name}-table", f"Phi[{k + 1},{j + 1}]", output=name)
            _table(fn, _p("qbar-pa"), qs, phis[:, k, j])
        for m_, name in enumerate(coef_psi[k]):
            fn = _fcs(ch, f"{name}-table", f"Psi[{k + 1},{m_ + 1}]", output=name)
            _table(fn, _p("qbar-pa"), qs, psis[:, k, m_])

    ch = _el(root, "channel", name="Modal wing", execute=_p("active"))
    _loads_fused(ch, nums, eta, etad)
    _comment(ch, "forcing held over the step [1/s2]: aerodynamic change since the reference "
                 "flow (Q - Q_r) K_a eta + (Q/V - Q_r/V_r) D_a etadot, and the flow inputs")
    fn = _fcs(ch, _p("dqbar-ref-pa"), "Q - Q_r [Pa]")
    d = _el(fn, "difference")
    _prop(d, _p("qbar-pa"))
    _prop(d, _p("qbar-ref-pa"))
    has_d = bool(np.any(nums.d_aero))
    if has_d:
        fn = _fcs(ch, _p("dq-over-v-ref"), "Q/V - Q_r/V_r [Pa s/m]")
        d = _el(fn, "difference")
        _prop(d, _p("q-over-v"))
        _prop(d, _p("q-over-v-ref"))
    fn = _fcs(ch, _p("q-dalpha"), "Q (alpha - alpha_0) [Pa rad]")
    d = _el(_product(fn, _p("qbar-pa")), "difference")
    _prop(d, _p("alpha-rad"))
    _prop(d, _p("alpha0-rad"))
    fn = _fcs(ch, _p("q-over-v-q"), "(Q/V) q [Pa rad/m]")
    _product(fn, _p("q-over-v"), "velocities/q-rad_sec")
    fn = _fcs(ch, _p("dqbar-pa"), "Q - Q_0 [Pa]")
    d = _el(fn, "difference")
    _prop(d, _p("qbar-pa"))
    _prop(d, _p("qbar0-pa"))
    g = [_p(f"f{i + 1}") for i in range(n)]
    for i in range(n):
        s = _el(_fcs(ch, g[i], f"forcing of mode {i + 1} [1/s2]"), "sum")
        _linear(_el(_product(s, _p("dqbar-ref-pa")), "sum"),
                list(zip(nums.k_aero[i], eta, strict=True)))
        if has_d and any(nums.d_aero[i]):
            _linear(_el(_product(s, _p("dq-over-v-ref")), "sum"),
                    list(zip(nums.d_aero[i], etad, strict=True)))
        _linear(s, [(nums.b_alpha[i], _p("q-dalpha")), (nums.b_q[i], _p("q-over-v-q")),
                    (nums.b_0[i], _p("dqbar-pa"))])
    _comment(ch, "x+ = Phi x + Psi f, row by row in place (coefficients rewritten for the rows "
                 "already updated; in_place_step)")
    for k in range(2 * n):
        s = _el(_fcs(ch, f"{state[k]}-step", f"{state[k].rsplit('/', 1)[1]} after the step",
                     output=state[k]), "sum")
        for j in range(2 * n):
            _product(s, coef_phi[k][j], state[j])
        for m_ in range(n):
            _product(s, coef_psi[k][m_], g[m_])
    _comment(ch, "this step's down wind, for the next step's change")
    _assign(ch, _p("wind-down-store"), "down wind of this step [ft/s]",
            "atmosphere/wind-down-fps", [_p("wind-down-prev-fps")])

def _loads_fused(ch, nums: ModalNumbers, eta, etad) -> None:
    """Lift and pitching moment of the modal state (wind axes, SI), the drag being k2 times
    the lift (C_D_eta = 2 k C_L0 C_L_eta), into the external reactions in body axes."""
    s_ref, cb = P.REFERENCE_AREA_M2, P.MEAN_AERODYNAMIC_CHORD_M
    k2 = float(nums.load_eta[1, 0] / nums.load_eta[0, 0]) if nums.load_eta[0, 0] else 0.0
    if not (np.allclose(nums.load_eta[1], k2 * nums.load_eta[0])
            and np.allclose(nums.load_etadot[1], k2 * nums.load_etadot[0])):
        raise ExportError("the modal drag is not proportional to the modal lift")
    _comment(ch, "incremental loads: Q S (C_eta eta + C_etadot etadot cbar/(2V)), SI; "
                 f"drag = {_num(k2)} lift")
    for r, name, text in ((0, "lift-n", "lift, up, normal to the air velocity [N]"),
                          (2, "pitch-n_m", "pitching moment about the CG, nose up [N m]")):
        prod = _el(_fcs(ch, _p(name), text), "product")
        _prop(prod, _p("enabled"))
        total = _el(prod, "sum")
        if any(nums.load_eta[r]):
            _linear(_el(_product(total, _p("qbar-pa")), "sum"),
                    [(s_ref * c, e) for c, e in zip(nums.load_eta[r], eta, strict=True)])
        if any(nums.load_etadot[r]):
            _linear(_el(_product(total, _p("q-over-v")), "sum"),
                    [(s_ref * cb / 2.0 * c, e)
                     for c, e in zip(nums.load_etadot[r], etad, strict=True)])
    _comment(ch, "into the airframe's external reactions, body axes, JSBSim units")
    cos_a = lambda p: _prop(_el(p, "cos"), _p("alpha-rad"))  # noqa: E731
    sin_a = lambda p: _prop(_el(p, "sin"), _p("alpha-rad"))  # noqa: E731
    for name, a, b in (("modal-lift", (1.0, cos_a), (k2, sin_a)),
                       ("modal-drag", (k2, cos_a), (-1.0, sin_a))):
        fn = _fcs(ch, _p(f"{name}-lbs"), f"{name} force [lbs]",
                  output=airframe_xml.external_property(name))
        s = _el(_product(fn, U.LBF_PER_N, _p("lift-n")), "sum")
        for coef, f in (a, b):
            if coef == 1.0:
                f(s)
            else:
                _product(s, coef, f)
    fn = _fcs(ch, _p("modal-pitch-lbsft"), "modal-pitch moment [lbs ft]",
              output=airframe_xml.external_property("modal-pitch"))
    _product(fn, U.LBF_FT_PER_N_M, _p("pitch-n_m"))


def _collapse(parent: ET.Element) -> None:
    """Replace every <sum>/<product> with one argument by that argument (JSBSim warns)."""
    for i, child in enumerate(list(parent)):
        _collapse(child)
        if child.tag in ("sum", "product") and len(child) == 1:
            parent.remove(child)
            parent.insert(i, child[0])


def _serialise(root: ET.Element) -> str:
    _collapse(root)
    ET.indent(root, space="  ")
    body = ET.tostring(root, encoding="unicode", short_empty_elements=True)
    header = (
        '<?xml version="1.0" encoding="utf-8"?>\n'
        "<!-- GENERATED by bioflex_jsb.adapters.jsbsim_export (bioflex-jsb export-jsbsim):\n"
        "     do not edit; run `python -m bioflex_jsb.adapters.jsbsim_export` to regenerate. -->\n"
    )
    return header + body + "\n"


# ======================================================================================
# Aircraft and script
# ======================================================================================

_SYSTEM_INCLUDE = re.compile(
    r'^(?P<indent>[ \t]*)<system file="' + re.escape(airframe_xml.SYSTEM_FILE) + r'"\s*/>[ \t]*$',
    re.MULTILINE,
)


def render_aircraft_files(spec: ExportSpec, include_shared: bool = True) -> dict[str, str]:
    """Files of ``aircraft/bioflex_<variant>/`` (the generated rigid airframe with the modal
    system included) and ``systems/``: path relative to the JSBSim root → text.
    ``include_shared``: also the airframe's own systems (flight controls), for a new root."""
    base = airframe_xml.AIRCRAFT_NAME
    craft = aircraft_name(spec.variant, spec.model)
    sysname = system_name(spec.variant, spec.model)
    out: dict[str, str] = {}
    for rel, text in airframe_xml.render_all().items():
        parts = rel.split("/")
        if parts[0] == "aircraft" and parts[1].startswith(base):
            # the flying aircraft and its companions (the trim companion ``<name>_trim``)
            suffix = parts[1][len(base):]
            new_dir = craft + suffix
            tail = "/".join(parts[2:])
            if tail == f"{parts[1]}.xml":
                tail = f"{new_dir}.xml"
                text = _renamed(text, parts[1], new_dir)
                if not suffix:
                    text = _modal_aircraft(text, sysname, spec)
            out[f"aircraft/{new_dir}/{tail}"] = text
        elif parts[0] == "systems" and include_shared:
            out[rel] = text
    out[f"systems/{sysname}.xml"] = render_system(spec)
    return out


def _renamed(text: str, old: str, new: str) -> str:
    text = text.replace(f'<fdm_config name="{old}"', f'<fdm_config name="{new}"', 1)
    note = (f"<!-- {new}: the {old} aircraft of airframe_xml, renamed"
            " by bioflex_jsb.adapters.jsbsim_export -->\n")
    head, sep, rest = text.partition("\n")
    return head + sep + note + rest


def _modal_aircraft(text: str, sysname: str, spec: ExportSpec) -> str:
    if len(_SYSTEM_INCLUDE.findall(text)) != 1:
        raise ExportError("the generated airframe has no single flight-control system include")
    return _SYSTEM_INCLUDE.sub(
        lambda m: f"{m.group(0)}\n{m['indent']}<!-- modal wing '{spec.variant}' ({spec.model}), "
        f"step {_num(spec.dt_s)} s: bioflex_jsb.adapters.jsbsim_export -->\n"
        f'{m["indent"]}<system file="{sysname}" />',
        text,
    )


@dataclass(frozen=True)
class TrimState:
    """The flying aircraft's trimmed state and controls, JSBSim units, for an IC file."""

    ic: dict[str, tuple[str, float]]  # IC element → (unit, value)
    controls: dict[str, float]  # control command property → value


def fig21_trim_state(dt_s: float = DEFAULT_DT_S) -> TrimState:
    """Trim of the Fig. 21 case by :meth:`Airframe.trim` (the co-simulation's trim: same
    integrators and step), read from the flying instance."""
    from bioflex_jsb.adapters.cosim import INTEGRATORS
    from bioflex_jsb.adapters.jsbsim_fdm import _TRIM_CONTROLS, Airframe

    af = Airframe()
    for name, value in INTEGRATORS.items():
        af[name] = value
    af.set_dt(dt_s)
    af.trim(P.SECTION5_AIRSPEED_M_S)
    ic = {
        "ubody": ("FT/SEC", af["velocities/u-fps"]),
        "vbody": ("FT/SEC", af["velocities/v-fps"]),
        "wbody": ("FT/SEC", af["velocities/w-fps"]),
        "p": ("RAD/SEC", af["velocities/p-rad_sec"]),
        "q": ("RAD/SEC", af["velocities/q-rad_sec"]),
        "r": ("RAD/SEC", af["velocities/r-rad_sec"]),
        "elevation": ("FT", af["position/terrain-elevation-asl-ft"]),
        "altitudeMSL": ("FT", af["position/h-sl-ft"]),
        "phi": ("RAD", af["attitude/phi-rad"]),
        "theta": ("RAD", af["attitude/theta-rad"]),
        "psi": ("RAD", af["attitude/psi-rad"]),
        "latitude": ("RAD", af["position/lat-geod-rad"]),
        "longitude": ("RAD", af["position/long-gc-rad"]),
    }
    names = _TRIM_CONTROLS + tuple(f"fcs/throttle-cmd-norm[{i}]" for i in range(af.engine_count))
    return TrimState(ic, {name: af[name] for name in names})


def _trim_num(x: float) -> str:
    """Trim values to 10 significant digits (regeneration stays byte-stable)."""
    x = float(x)
    return "0" if abs(x) < 1e-13 else f"{x:.10g}"


def render_fig21_initial_condition(state: TrimState) -> str:
    """Text of ``aircraft/bioflex_optimised/fig21_trim.xml``: the trimmed state."""
    root = ET.Element("initialize", name=FIG21_IC)
    root.append(ET.Comment(f" trim at {P.SECTION5_AIRSPEED_M_S:g} m/s, ISA sea level, by "
                           "Airframe.trim (bioflex_jsb.adapters.jsbsim_fdm); JSBSim reads "
                           "<elevation> before <altitudeMSL> "))
    for name, (unit, value) in state.ic.items():
        _el(root, name, _trim_num(value), unit=unit)
    _el(root, "running", "-1")
    ET.indent(root, space="  ")
    return ('<?xml version="1.0" encoding="utf-8"?>\n'
            "<!-- GENERATED by bioflex_jsb.adapters.jsbsim_export: do not edit. -->\n"
            + ET.tostring(root, encoding="unicode", short_empty_elements=True) + "\n")


def render_fig21_script(state: TrimState, dt_s: float = DEFAULT_DT_S) -> str:
    """Text of ``scripts/fig21_native.xml``: the Fig. 21 case in the plain JSBSim program.

    JSBSim's own trim cannot trim the flying aircraft (physical rotor inertia: module
    docstring of jsbsim_fdm), so the script starts from the Python trim written as an initial
    condition (:func:`render_fig21_initial_condition`), sets the trim controls, holds the
    airframe (integrators off) for ``FIG21_SETTLE_S`` while the propellers spin up to their
    trim RPM, then flies with the co-simulation's integrators; the gust comes
    ``FIG21_GUST_START_S`` later."""
    from bioflex_jsb.adapters.cosim import INTEGRATORS

    craft = aircraft_name(FIG21_VARIANT)
    amp = P.SECTION5_GUST_AMPLITUDE_M_S
    speed = P.SECTION5_AIRSPEED_M_S
    t_fly = FIG21_SETTLE_S
    t_gust = t_fly + FIG21_GUST_START_S
    root = ET.Element("runscript", name="bioflex Fig. 21, native modal wing")
    _el(root, "description",
        f"Optimised wing at {speed:g} m/s through a {amp:g} m/s sharp-edged vertical gust "
        f"{FIG21_GUST_START_S:g} s after the trim (paper Fig. 21), the modal wing flown by "
        f"JSBSim ({system_name(FIG21_VARIANT)}). Run: jsbsim --root=REPO --script={FIG21_SCRIPT} "
        f"--simulation-rate={_num(1.0 / dt_s)} (the console program of jsbsim 1.3.3 replaces "
        "the script's dt by its own, 1/120 s by default, at which the wing stays rigid: "
        f"{PREFIX}/active = 0). Writes {FIG21_OUTPUT} (one row per step) in the JSBSim root, "
        "or in --outputpath. Trimmed state "
        f"from {FIG21_IC}.xml; the airframe is held for the first {t_fly:g} s (propeller "
        f"spin-up to the trim RPM); the flight starts at t = {t_fly:g} s.")
    _el(root, "use", aircraft=craft, initialize=FIG21_IC)
    run = _el(root, "run", start="0", end=_num(t_gust + FIG21_DURATION_S - FIG21_GUST_START_S),
              dt=_num(dt_s))
    ev = _el(run, "event", name="trim controls, airframe held")
    _el(ev, "description", "trim controls of the Python trim; JSBSim's integrators of the "
                           "airframe state off (0): the state stays at the trim while the "
                           "propellers spin up to the trim RPM")
    _el(ev, "condition", "simulation/sim-time-sec ge 0")
    for name, value in state.controls.items():
        _el(ev, "set", name=name, value=_trim_num(value))
    for name in INTEGRATORS:
        _el(ev, "set", name=name, value="0")
    ev = _el(run, "event", name="fly")
    _el(ev, "description", "airframe released: the co-simulation's integrators")
    _el(ev, "condition", f"simulation/sim-time-sec ge {_num(t_fly - 0.5 * dt_s)}")
    for name, value in INTEGRATORS.items():
        _el(ev, "set", name=name, value=str(value))
    ev = _el(run, "event", name="gust")
    _el(ev, "description", f"sharp-edged gust, {amp:g} m/s up (wind-down = -w_g)")
    _el(ev, "condition", f"simulation/sim-time-sec ge {_num(t_gust - 0.5 * dt_s)}")
    _el(ev, "set", name="atmosphere/wind-down-fps", value=_num(-amp * U.FT_PER_M))
    out = _el(root, "output", name=FIG21_OUTPUT, type="CSV", rate=_num(1.0 / dt_s))
    for prop in ("velocities/vt-fps", "velocities/u-fps", "velocities/w-fps",
                 "velocities/q-rad_sec", "attitude/theta-rad", "aero/alpha-rad",
                 "atmosphere/wind-down-fps", "propulsion/engine[0]/propeller-rpm",
                 _p("eta1"), _p("eta2"), _p("eta3"), _p("active")):
        _el(out, "property", prop)
    ET.indent(root, space="  ")
    body = ET.tostring(root, encoding="unicode", short_empty_elements=True)
    return ('<?xml version="1.0" encoding="utf-8"?>\n'
            "<!-- GENERATED by bioflex_jsb.adapters.jsbsim_export: do not edit. -->\n"
            + body + "\n")


# ======================================================================================
# Writing
# ======================================================================================


def export(spec: ExportSpec, out_dir: Path, include_shared: bool = True) -> list[Path]:
    """Write the system and aircraft files under the JSBSim root ``out_dir``; paths written.
    Raises OSError when the directory cannot be written."""
    return airframe_xml.write_files(render_aircraft_files(spec, include_shared), out_dir)


def repository_files() -> dict[str, str]:
    """Every file this module owns in the repository: path → text."""
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

    files: dict[str, str] = {}
    for name in REPOSITORY_VARIANTS:
        spec = ExportSpec(build_wing(VARIANTS[name]).model, name)
        files.update(render_aircraft_files(spec, include_shared=False))
    state = fig21_trim_state()
    files[f"aircraft/{aircraft_name(FIG21_VARIANT)}/{FIG21_IC}.xml"] = (
        render_fig21_initial_condition(state))
    files[FIG21_SCRIPT] = render_fig21_script(state)
    return files


def write_repository(root: Path) -> list[Path]:
    """Write :func:`repository_files` under the JSBSim root ``root``; return the paths."""
    return airframe_xml.write_files(repository_files(), root)


# ======================================================================================
# Running the native aircraft (driven from Python: JSBSim only stepping)
# ======================================================================================


def run_native_gust(airframe, setup, n_modes: int = 3, trim=None):
    """Fly ``setup`` with a native modal-wing aircraft (an :class:`Airframe` loaded with
    ``aircraft_name(...)``): Python only writes the gust and steps JSBSim. Channels as the
    co-simulation's (u, alpha, q, theta, eta<i>, w_g), sampled the same way. The aircraft
    must have been exported for ``setup.dt_s``."""
    from bioflex_jsb.adapters.cosim import INTEGRATORS
    from bioflex_jsb.simulation.gusts import GustField
    from bioflex_jsb.simulation.results import TimeHistory

    for name, value in INTEGRATORS.items():
        airframe[name] = value
    airframe.set_dt(setup.dt_s)
    if trim is None:
        trim = airframe.trim(setup.speed_m_s, setup.altitude_m)
    dt = airframe.dt_s
    gust = GustField(setup.gust, setup.speed_m_s, setup.gust_start_s, setup.duration_s, dt)
    n_steps = int(round(setup.duration_s / dt))
    node = airframe.property_node
    wind = node("atmosphere/wind-down-fps")
    u_n, v_n, w_n = node("velocities/u-fps"), node("velocities/v-fps"), node("velocities/w-fps")
    th_n, ph_n, q_n = node("attitude/theta-rad"), node("attitude/phi-rad"), node(
        "velocities/q-rad_sec")
    eta_n = [node(_p(f"eta{i + 1}")) for i in range(n_modes)]
    names = ["u", "alpha", "q", "theta", "w_g"] + [f"eta{i + 1}" for i in range(n_modes)]
    data = {k: np.full(n_steps, np.nan) for k in names}
    for k in range(n_steps):
        w_g = gust.vertical_m_s(k * dt)
        wd = -w_g * U.FT_PER_M
        wind.set_double_value(wd)
        u, v, w = u_n.get_double_value(), v_n.get_double_value(), w_n.get_double_value()
        th, ph = th_n.get_double_value(), ph_n.get_double_value()
        ua = u + wd * math.sin(th)
        va = v - wd * math.sin(ph) * math.cos(th)
        wa = w - wd * math.cos(ph) * math.cos(th)
        data["u"][k] = math.sqrt(ua * ua + va * va + wa * wa) * U.M_PER_FT - setup.speed_m_s
        data["alpha"][k] = math.atan2(wa, ua) - trim.alpha_rad
        data["q"][k] = q_n.get_double_value()
        data["theta"][k] = th - trim.theta_rad
        data["w_g"][k] = w_g
        for i, e in enumerate(eta_n):
            data[f"eta{i + 1}"][k] = e.get_double_value()
        airframe.run(1)
    units = {"u": "m/s", "alpha": "rad", "q": "rad/s", "theta": "rad", "w_g": "m/s"}
    units.update({f"eta{i + 1}": "rad" for i in range(n_modes)})
    return TimeHistory(model="native", time_s=np.arange(n_steps) * dt, channels=data,
                       units=units, meta={"source": "jsbsim-native", "dt_s": dt})


_BENCH: dict[str, object] = {}


def bench_native(steps: int, variant: str = "original", speed_m_s: float = 15.0) -> float:
    """µs per step of the native modal-wing aircraft of the repository (trimmed at
    ``speed_m_s``, JSBSim only stepping), for ``bioflex-jsb bench``."""
    from bioflex_jsb.adapters.jsbsim_fdm import Airframe

    craft = aircraft_name(variant)
    if craft not in _BENCH:
        af = Airframe(aircraft=craft)
        af.set_dt(DEFAULT_DT_S)
        _BENCH[craft] = af
    af = _BENCH[craft]
    af.trim(speed_m_s)
    t0 = time.perf_counter()
    af.run(int(steps))
    return (time.perf_counter() - t0) / int(steps) * 1e6


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bioflex_jsb.adapters.jsbsim_export",
        description="Regenerate the repository's native modal-wing systems, aircraft and script.",
    )
    parser.add_argument("--root", type=Path, default=airframe_xml.default_output_root())
    args = parser.parse_args(argv)
    for path in write_repository(args.root):
        print(path)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
