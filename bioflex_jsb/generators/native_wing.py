"""The modal wing as JSBSim systems: the elastic wing flying in plain JSBSim, no Python in the loop.

:func:`render_system` writes the modal wing of one variant (``coupled`` or ``qsd``) as a JSBSim
``<system>``; :func:`render_aircraft_files` writes an aircraft, ``aircraft/bioflex_<variant>/``,
that is the generated rigid airframe of :mod:`bioflex_jsb.generators.airframe` (called
read-only, so both stay in step) with that system included. ``docs/native.md`` has the user's
view; this docstring has the numerics.

Same physics as :class:`bioflex_jsb.simulation.modal_wing.ModalWing`: modal coordinates Δη are
perturbations from the static deformation at trim, the generalised force on mode i from the
current Q, V, α (against the air, gusts included) and q,

    Δη̈ = −[diag(ω²) − Q K_a] Δη − [diag(2ζω) − (Q/V) D_a] Δη̇
          + b_α Q (α − α_0) + b_q (Q/V) q + b_0 (Q − Q_0),

and the incremental loads ΔL, ΔD = k₂ ΔL (k₂ = 2kC_L0), ΔM; JSBSim units at the boundary only
(:mod:`bioflex_jsb.units`; Q enters as ``aero/qbar-psf`` times ``units.PA_PER_PSF``, Q/V as
Q (2/c̄) ``aero/ci2vel``, JSBSim's c̄/(2V), the airframe's c̄ being the paper's).

Integration (``coupled``): leapfrog (Strang) splitting, exact structure
-----------------------------------------------------------------------
Per mode i, the part A_i = [[0, 1], [−k_i, −c_i]] with k_i = ω_i² − Q_r K_a[i, i],
c_i = 2ζ_iω_i − (Q_r/V_r) D_a[i, i] — the structure and the mode's own aerodynamic stiffness
and damping at the reference flow of the export speed (``--speed``, default 15 m/s) — is
integrated exactly; everything else (the change of the diagonal terms from the reference,
the couplings between modes, the flow inputs) is an acceleration a_i applied as a kick:

    x_{k+1} = Φ_h K_k Φ_h x_k,   Φ_h = e^{A Δt/2} (block diagonal),   K_k: η̇ += Δt a(Φ_h x_k).

The system stores y = Φ_h x (the half-step state): y_{k+1} = Φ_s K_k y_k with Φ_s = e^{A Δt},
so a step is, per mode, one rate row (kick and structural step, reading the rates already
updated: :func:`leapfrog_step`, the Python mirror) and one displacement row (from the new
rate) — 6 ``fcs_function`` rows for three modes, constant coefficients, no tables, each
a <difference> of <quotient>s x/(1/c) (:func:`_combination`: JSBSim's <sum> and <product>
copy a reference-counted pointer per argument at every evaluation, these do not). The
structure is exact at any step; the splitting is second order. At the default step (1/960 s:
ω Δt = 0.7 for the third mode, 107 Hz) the step's eigenvalues are within 1 % of the exact
e^{A(Q, V) Δt} over 0–40 m/s for every named wing (:func:`leapfrog_eigen_error`, tested);
:class:`ExportSpec` refuses a step where they are not (at 2/960 s the optimised wing is 3.9 %
off at 40 m/s).

The modal state at the current time, x = Φ_h⁻¹ y, is published as named functions
(``bioflex/modal/eta<i>``, ``eta<i>-dot``), evaluated only when read.

Loads: aerodynamics of the airframe (``<aerodynamics>`` functions in the LIFT, DRAG and PITCH
axes, about the aerodynamic reference point, which is the CG), with JSBSim's air data of the
step, from the stored state y_{k+1}: JSBSim holds the forces it computes in a step over the
next step, and y_{k+1} = Φ_h x_{k+1} is the structural state half a step into that interval.
Against the co-simulation at a quarter of the step (the converged solution) this sampling is
as close as the co-simulation's own at the full step (Fig. 21 case: q 0.7 %, α 0.6 %, η₁
0.8 % NRMSE against 0.5 %, 0.6 %, 0.8 %) and needs no Φ_h⁻¹ (half the products). The
co-simulation's hooks (``external_reactions``) are left out of the native aircraft.

Φ_s and Φ_h hold for ONE step, the exported ``dt_s`` (default 1/960 s, the co-simulation's
step; ``--dt`` for others). ``bioflex/modal/active`` is 1 only when ``simulation/dt``
equals it. While it is 0 (JSBSim's initial-condition run and trim suspend integration with
dt = 0, or a host running another step) only the channel ``execute="bioflex/modal/idle"``
runs: it latches the trim reference α_0, Q_0 (and the kick's trim terms) from JSBSim's air
data and holds the stored state at zero: every trim re-references the wing.

Flow seen by the kick: JSBSim's air data of the previous step (``aero/*``) — the state the
co-simulation reads — except in a step where the down wind changed: then recomputed from
``velocities/{u,v,w}-aero-fps`` with this step's change of the wind (the co-simulation writes
the wind before it reads the flow), so a gust reaches the wing in the step it reaches the
rigid aerodynamics. System ``<function>``s (evaluated once per step before the channels);
the previous step's wind is a ``type="post"`` function, whose cached value the next step
reads; ``ifthen`` evaluates one branch, so a steady wind costs a comparison.

``qsd``: Δη = K(Q)⁻¹ [Q Δα b_α + (Q/V) q b_q + (Q − Q_0) b_0], K(Q) = diag(ω²) − Q K_a, with
K(Q)⁻¹ tabulated against Q (rows every 0.5 m/s of V up to :data:`GRID_SPEED_MAX_M_S`);
Δη̇ = 0; its loads go through the airframe's external reactions (body axes).

Properties (all under ``bioflex/modal/``), ``coupled``: ``eta<i>``, ``eta<i>-dot`` [rad,
rad/s] (functions of the stored ``y-eta<i>-scaled`` = y_η/c_i, c_i = Φ_s[0,1]/Φ_s[1,1] ≈ Δt,
and ``y-eta<i>-dot``), ``alpha0-rad``, ``qbar0-pa``
(latched trim reference), ``active``, ``idle``, ``enabled`` (set 0 to fly the rigid airframe
with the same file); the loads are ``aero/bioflex/modal-lift-lbs``, ``aero/force/modal-lift``,
``aero/force/modal-drag`` [lbs] and ``aero/moment/modal-pitch`` [lbs ft].
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.modal_matrices import ModalMatrices, modal_matrices
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.simulation.leapfrog import (  # noqa: F401  (re-exported for the checks)
    GRID_SPEED_MAX_M_S,
    GRID_SPEED_STEP_M_S,
    LeapfrogCoefficients,
    leapfrog_coefficients,
    leapfrog_eigen_error,
    leapfrog_matrix,
    leapfrog_step,
)
from bioflex_jsb.simulation.jsbsim_settings import INTEGRATORS
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S

EXPORT_MODELS = ("coupled", "qsd")
PREFIX = "bioflex/modal"
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
# Largest relative error of the coupled step's eigenvalues against the exact ones over
# 0..GRID_SPEED_MAX_M_S that an export accepts: the 1 % the native run is held to against
# the co-simulation (docs/native.md).
EIGEN_REL_TOL = 0.01


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


def q_grid_pa(rho_ref: float = P.SEA_LEVEL_DENSITY_KG_M3) -> np.ndarray:
    """Dynamic pressures of the table rows [Pa] (uniform in V_ref)."""
    v = np.arange(0.0, GRID_SPEED_MAX_M_S + 0.5 * GRID_SPEED_STEP_M_S, GRID_SPEED_STEP_M_S)
    return 0.5 * rho_ref * v**2


def qsd_schedule(nums: ModalMatrices, rho_ref: float = P.SEA_LEVEL_DENSITY_KG_M3):
    """(Q grid, K(Q)⁻¹ stack) of the QSD model's tables."""
    qs = q_grid_pa(rho_ref)
    inv = [np.linalg.inv(np.diag(nums.omega**2) - q * nums.k_aero) for q in qs]
    return qs, np.array(inv)


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


def _combination(parent: ET.Element, terms: list[tuple[float, str]], lead=None,
                 minus: tuple[str, ...] = (), **attrib) -> ET.Element:
    """Σ c·x over ``terms`` [(c, property)] (zero c skipped), plus the element ``lead``
    builds, minus the properties ``minus``, in the form JSBSim evaluates fastest: a
    <difference> of <quotient>s, x/(1/c). JSBSim's <sum> and <product> copy a reference-counted
    pointer per argument each time they are evaluated (two atomic operations); <difference>
    and <quotient> index their arguments (a weighted term costs about a third less, measured)."""
    d = _el(parent, "difference", **attrib)
    first = lead is None
    if lead is not None:
        lead(d)
    for coef, prop in terms:
        if coef == 0.0:
            continue
        q = _el(d, "quotient")
        _prop(q, prop)
        _value(q, (1.0 if first else -1.0) / float(coef))
        first = False
    if minus and first:  # nothing added yet: subtract from 0
        _value(d, 0.0)
    for prop in minus:
        _prop(d, prop)
    if len(d) == 0:  # nothing to add: the value 0
        d.tag = "value"
        d.text = "0"
    return d


def _over(x, inverse):
    """Builder of x / ``inverse`` (a property name, or a builder), the product of x and the
    quantity whose inverse that is (:func:`_flow_functions`)."""
    def build(parent: ET.Element) -> None:
        q = _el(parent, "quotient")
        x(q)
        if callable(inverse):
            inverse(q)
        else:
            _prop(q, inverse)
    return build


def _times(x, factor: str):
    """Builder of x·factor as x / (1/factor) (no pointer copies: :func:`_combination`);
    a factor of 0 gives 1/0 = HUGE_VAL in JSBSim and so 0, as the product would."""
    return _over(x, _over(lambda p: _value(p, 1.0), factor))


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

        if self.model == "coupled":
            self._check_step()

    def _check_step(self) -> None:
        """Refuse a step at which the coupled step is not within :data:`EIGEN_REL_TOL` of the
        exact dynamics over 0..GRID_SPEED_MAX_M_S (module docstring)."""
        nums = modal_matrices(self.wing, self.cl_trim)
        err, at = leapfrog_eigen_error(nums, self.leapfrog(nums))
        if err <= EIGEN_REL_TOL:
            return
        ok = self.dt_s
        for _ in range(12):
            ok /= 2.0
            if leapfrog_eigen_error(nums, self.leapfrog(nums, ok))[0] <= EIGEN_REL_TOL:
                break
        raise ExportError(
            f"time step {self.dt_s:.6g} s is too coarse for wing {self.variant!r}: the "
            f"integration's eigenvalues are {err:.1%} off the exact ones at {at:g} m/s "
            f"(accepted: {EIGEN_REL_TOL:.0%}); {ok:.6g} s is within it")

    @property
    def cl_trim(self) -> float:
        return level_flight_condition(self.speed_m_s, self.rho_ref).cl_trim

    def leapfrog(self, nums: ModalMatrices, dt_s: float | None = None) -> LeapfrogCoefficients:
        """The coupled model's step of ``dt_s`` [s] (default the exported step), its exact
        part at the export speed's flow."""
        q = 0.5 * self.rho_ref * self.speed_m_s**2
        return leapfrog_coefficients(nums, self.dt_s if dt_s is None else dt_s, q,
                                     q / self.speed_m_s)


def render_system(spec: ExportSpec) -> str:
    """Text of ``systems/bioflex_modal_<variant>.xml``."""
    nums = modal_matrices(spec.wing, spec.cl_trim)
    n = nums.n
    root = ET.Element("system", name=system_name(spec.variant, spec.model))
    _el(root, "description",
        f"Modal wing '{spec.variant}' ({spec.model}, {n} modes) of the bioflex UAV, generated by "
        "bioflex_jsb.generators.native_wing (see its docstring and docs/native.md). "
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


def _flow_functions(root: ET.Element) -> tuple[str, str, str]:
    """System functions of the flow the modal step sees: (α [rad], 1/Q [1/psf], 2V/c̄ [-]),
    the inverses because the step multiplies by them as x/(1/Q) (:func:`_combination`).

    JSBSim's air data of the previous step (``aero/*``), the state the co-simulation reads,
    except in a step where the down wind changed: then recomputed from the air-relative body
    velocities with this step's change of the wind added (as the co-simulation, which writes
    the wind before it reads the flow), so a gust reaches the wing in the step it reaches the
    rigid aerodynamics. ``ifthen`` evaluates one branch, so a steady wind costs a comparison.
    The previous step's wind is a ``post`` function: evaluated after the channels, its cached
    value is what the next step's functions read."""
    prev = _p("wind-down-prev-fps")
    fn = _el(root, "function", name=prev, type="post")
    _el(fn, "description", "down wind of this step, read by the next step [ft/s]")
    _prop(fn, "atmosphere/wind-down-fps")

    def dwd(p):
        d = _el(p, "difference")
        _prop(d, "atmosphere/wind-down-fps")
        _prop(d, prev)

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

    def speed_squared(parent):
        s = _el(parent, "sum")
        for axis in "uvw":
            p = _el(s, "pow")
            air(p, axis)
            _value(p, 2.0)

    def alpha(parent):
        at = _el(parent, "atan2")
        air(at, "w")
        air(at, "u")

    def inverse(parent, of):
        q = _el(parent, "quotient")
        _value(q, 1.0)
        of(q)

    def qbar(parent):
        speed_squared(_product(parent, 0.5, "atmosphere/rho-slugs_ft3"))

    def ci2vel(parent):
        q = _el(parent, "quotient")
        _prop(q, "metrics/cbarw-ft")
        _product(q, 2.0, lambda p: speed_squared(_el(p, "sqrt")))

    flows = (("alpha-rad", "angle of attack against the air, gust included [rad]", alpha,
              lambda p: _prop(p, "aero/alpha-rad")),
             ("qbar-inv", "1/Q [1/psf] (1/0 gives JSBSim's HUGE_VAL, so x/(1/Q) = 0)",
              lambda p: inverse(p, qbar),
              lambda p: inverse(p, lambda q: _prop(q, "aero/qbar-psf"))),
             ("ci2vel-inv", "2V/cbar [-], the inverse of aero/ci2vel",
              lambda p: inverse(p, ci2vel),
              lambda p: inverse(p, lambda q: _prop(q, "aero/ci2vel"))))  # fmt: skip
    names = []
    for name, text, corrected, steady in flows:
        fn = _el(root, "function", name=_p(name))
        _el(fn, "description", text)
        ift = _el(fn, "ifthen")
        ne = _el(ift, "nq")  # the down wind changed since the previous step
        _prop(ne, "atmosphere/wind-down-fps")
        _prop(ne, prev)
        corrected(ift)
        steady(ift)
        names.append(_p(name))
    return names


def _value_el(x: float) -> ET.Element:
    e = ET.Element("value")
    e.text = _num(x)
    return e


def _forcing_terms(fn_sum: ET.Element, nums: ModalMatrices, i: int) -> None:
    """Q Δα b_α + (Q/V) q b_q + ΔQ b_0 for mode i (SI generalised acceleration)."""
    _product(fn_sum, float(nums.b_alpha[i]), _p("qbar-pa"), _p("dalpha-rad"))
    _product(fn_sum, float(nums.b_q[i]), _p("q-over-v"), "velocities/q-rad_sec")
    _product(fn_sum, float(nums.b_0[i]), _p("dqbar-pa"))


def _qsd_state(ch, spec: ExportSpec, nums: ModalMatrices, eta: list[str]) -> None:
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


def _loads(ch, spec: ExportSpec, nums: ModalMatrices, eta: list[str], etad: list[str]) -> None:
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


def _coupled_system(root: ET.Element, spec: ExportSpec, nums: ModalMatrices, eta, etad) -> None:
    """The coupled model (module docstring): ``active``/``idle`` as system functions, the trim
    reference channel (idle only), the leapfrog step channel (active only). The loads are
    functions of the airframe's aerodynamics (:func:`modal_wing_aerodynamics`)."""
    n = nums.n
    co = spec.leapfrog(nums)
    y_eta, y_rate = _stored_state(n)
    neg_bias_q = [_p(f"kick-trim-q{i + 1}-neg") for i in range(n)]
    neg_bias = [_p(f"kick-trim{i + 1}-neg") for i in range(n)]
    for name in y_eta + y_rate + neg_bias_q + neg_bias:
        _el(root, "property", name, value="0")
    for name in ("alpha0-rad", "qbar0-pa", "never"):
        _el(root, "property", _p(name), value="0")
    _el(root, "property", _p("enabled"), value="1")

    _comment(root, "system functions, evaluated once per step before the channels")
    fn = _el(root, "function", name=_p("active"))
    _el(fn, "description", "1 when simulation/dt is the exported step, else 0 (IC, trim)")
    lt = _el(fn, "lt")
    diff = _el(_el(lt, "abs"), "difference")
    _prop(diff, "simulation/dt")
    _value(diff, spec.dt_s)
    _value(lt, DT_MATCH_REL * spec.dt_s)
    fn = _el(root, "function", name=_p("idle"))
    _el(fn, "description", "1 while not active")
    d = _el(fn, "difference")
    _value(d, 1.0)
    _prop(d, _p("active"))
    alpha, qbar_inv, ci2vel_inv = _flow_functions(root)

    ch = _el(root, "channel", name="Modal wing trim reference", execute=_p("idle"))
    _comment(ch, "while not active (IC, trim, another step): the trim reference latched from "
                 "the flow, the modal state (and so the loads) held at zero")
    _assign(ch, _p("alpha0-latch"), "trim angle of attack [rad]", "aero/alpha-rad",
            [_p("alpha0-rad")])
    fn = _fcs(ch, _p("qbar0-latch"), "trim dynamic pressure [Pa]", output=_p("qbar0-pa"))
    _product(fn, U.PA_PER_PSF, "aero/qbar-psf")
    _assign(ch, _p("reset"), "stored modal state to zero", 0.0, y_eta + y_rate)
    _comment(ch, "the trim terms of each mode's kick, latched with the trim reference and "
                 "stored negated (the step subtracts them): -Q (b_0 - b_alpha alpha_0) per "
                 "unit aero/qbar-psf and b_0 Q_0, times the kick gain")
    for i in range(n):
        g = co.kick[i] * U.PA_PER_PSF
        s = _el(_fcs(ch, f"{neg_bias_q[i]}-latch", f"minus the trim kick of mode {i + 1} per "
                     "unit aero/qbar-psf [rad/s/psf]", output=neg_bias_q[i]), "sum")
        _value(s, -g * nums.b_0[i])
        _product(s, g * nums.b_alpha[i], "aero/alpha-rad")
        fn = _fcs(ch, f"{neg_bias[i]}-latch", f"minus the constant trim kick of mode {i + 1} "
                  "[rad/s]", output=neg_bias[i])
        _product(fn, co.kick[i] * nums.b_0[i] * U.PA_PER_PSF, "aero/qbar-psf")

    ch = _el(root, "channel", name="Modal wing state", execute=_p("never"))
    _comment(ch, "never executed: declares the modal state at the current time, x = Phi_h^-1 "
                 "y, as named functions, evaluated when read (no cost per step)")
    fn = _fcs(ch, _p("state"), "eta<i> [rad] and eta<i>-dot [rad/s] of the current step")
    s = _el(fn, "sum")
    for i in range(n):
        h = co.half_inv[i]
        for row, name in ((0, eta[i]), (1, etad[i])):
            _combination(s, [(h[row, 0] * co.eta_rate[i], y_eta[i]), (h[row, 1], y_rate[i])],
                         name=name)

    pa, c_bar = U.PA_PER_PSF, P.MEAN_AERODYNAMIC_CHORD_M
    ch = _el(root, "channel", name="Modal wing", execute=_p("active"))
    _comment(ch, "leapfrog step (Strang splitting) of the stored half-step state y: the rate "
                 "kicked by the aerodynamic acceleration of y and advanced by the exact "
                 "structural step, then the displacement from the new rate. Flow: JSBSim's air "
                 "data of the previous step; Q = PA_PER_PSF aero/qbar-psf [Pa], "
                 "Q/V = Q (2/cbar) aero/ci2vel [Pa s/m] (aero/ci2vel = cbar/(2V)). Weighted "
                 "sums are differences of quotients x/(1/c): JSBSim evaluates them faster than "
                 "sums of products")
    for i in range(n):
        g = co.kick[i] * pa
        fn = _fcs(ch, f"{y_rate[i]}-step", f"stored rate of mode {i + 1} after the step [rad/s]",
                  output=y_rate[i])
        damp = [(g * 2.0 / c_bar * d, r) for d, r in zip(nums.d_aero[i], y_rate, strict=True)]
        damp.append((g * 2.0 / c_bar * nums.b_q[i], "velocities/q-rad_sec"))
        stiff = [(g * k * c, e)
                 for k, c, e in zip(nums.k_aero[i], co.eta_rate, y_eta, strict=True)]
        stiff.append((g * nums.b_alpha[i], alpha))

        def aero(parent, damp=damp, stiff=stiff, i=i):
            # Q (K_a eta + b_alpha alpha + ... + (Q/V)/Q (D_a etadot + b_q q)), in psf
            _combination(parent, stiff, minus=(neg_bias_q[i],),
                         lead=_over(lambda p: _combination(p, damp), ci2vel_inv))

        own = co.rate_eta[i] - co.kick[i] * co.q_ref_pa * nums.k_aero[i, i]
        _combination(fn, [(own * co.eta_rate[i], y_eta[i]),
                          (co.rate_rate[i] - co.kick[i] * co.q_over_v_ref * nums.d_aero[i, i],
                           y_rate[i])],
                     lead=_over(aero, qbar_inv), minus=(neg_bias[i],))
    for i in range(n):
        fn = _fcs(ch, f"{y_eta[i]}-step", f"stored eta{i + 1} after the step, scaled [rad/s]",
                  output=y_eta[i])
        _combination(fn, [(co.eta_eta[i], y_eta[i])],
                     lead=lambda p, i=i: _prop(p, y_rate[i]))


def _stored_state(n: int) -> tuple[list[str], list[str]]:
    """Stored state: the half-step displacement scaled by 1/c_i (c_i = Φ_s[0, 1]/Φ_s[1, 1]
    ≈ Δt, :attr:`LeapfrogCoefficients.eta_rate`, so its row is one product and a sum) and the
    half-step rate."""
    return ([_p(f"y-eta{i + 1}-scaled") for i in range(n)],
            [_p(f"y-eta{i + 1}-dot") for i in range(n)])


def modal_wing_aerodynamics(nums: ModalMatrices, co: LeapfrogCoefficients) -> dict[str, str]:
    """The native modal wing's loads as JSBSim aerodynamics of the airframe: XML fragments
    keyed by where they go (``functions``: before the first axis; ``LIFT``, ``DRAG``,
    ``PITCH``: into those axes).

    Loads of the stored state y = Φ_h x after this step's update, the structural state half
    a step into the interval over which JSBSim applies the forces it computes (module
    docstring), η and η̇ read as its two parts: ΔL = Q S (C_L_η·η + C_L_η̇·η̇ c̄/(2V)) in the
    LIFT axis, the drag k₂ ΔL (k₂ = 2kC_L0, C_D_η = k₂ C_L_η) in the DRAG axis, ΔM = Q S c̄
    (C_m_η·η + C_m_η̇·η̇ c̄/(2V)) in the PITCH axis (about the aerodynamic reference point,
    which is the CG); Q and V JSBSim's air data of this step; × ``enabled``. The lift
    is an aerodynamics function evaluated once per step (``aero/bioflex/modal-lift-lbs``),
    read by the LIFT and DRAG axes."""
    n = nums.n
    y_eta, y_rate = _stored_state(n)
    k2 = float(nums.load_eta[1, 0] / nums.load_eta[0, 0]) if nums.load_eta[0, 0] else 0.0
    if not (np.allclose(nums.load_eta[1], k2 * nums.load_eta[0])
            and np.allclose(nums.load_etadot[1], k2 * nums.load_etadot[0])):
        raise ExportError("the modal drag is not proportional to the modal lift")
    s_ref, qbar = P.REFERENCE_AREA_M2, "aero/qbar-psf"
    # c̄/(2V) from this step's airspeed: JSBSim updates aero/ci2vel only after the
    # aerodynamics' own functions have run, so it would be the previous step's
    half_chord_ft = 0.5 * P.MEAN_AERODYNAMIC_CHORD_M * U.FT_PER_M

    def loads(fn: ET.Element, r: int, gain: float) -> None:
        c = gain * U.PA_PER_PSF * s_ref
        disp = [(c * nums.load_eta[r, i] * co.eta_rate[i], y_eta[i]) for i in range(n)]
        rate = [(c * half_chord_ft * nums.load_etadot[r, i], y_rate[i]) for i in range(n)]
        lead = (_over(lambda q: _combination(q, rate), "velocities/vt-fps")
                if any(a for a, _ in rate) else None)
        total = lambda p: _combination(p, disp, lead=lead)  # noqa: E731
        _times(_times(total, qbar), _p("enabled"))(fn)

    lift_fn = "aero/bioflex/modal-lift-lbs"
    lift = ET.Element("function", name=lift_fn)
    _el(lift, "description", "modal wing: lift of the modal state [lbs]")
    loads(lift, 0, U.LBF_PER_N)
    in_lift = ET.Element("function", name="aero/force/modal-lift")
    _el(in_lift, "description", "modal wing lift [lbs]")
    _prop(in_lift, lift_fn)
    in_drag = ET.Element("function", name="aero/force/modal-drag")
    _el(in_drag, "description", f"modal wing drag: {_num(k2)} x its lift [lbs]")
    _product(in_drag, k2, lift_fn)
    pitch = ET.Element("function", name="aero/moment/modal-pitch")
    _el(pitch, "description", "modal wing pitching moment about the CG, nose up [lbs ft]")
    loads(pitch, 2, U.LBF_FT_PER_N_M)
    out = {}
    for key, e in (("functions", lift), ("LIFT", in_lift), ("DRAG", in_drag), ("PITCH", pitch)):
        _collapse(e)
        out[key] = ET.tostring(e, encoding="unicode", short_empty_elements=True)
    return out


def _collapse(parent: ET.Element) -> None:
    """Replace every <sum>/<product>/<difference> with one argument (and no name) by that
    argument (JSBSim warns)."""
    for i, child in enumerate(list(parent)):
        _collapse(child)
        if (child.tag in ("sum", "product", "difference") and len(child) == 1
                and "name" not in child.attrib):
            parent.remove(child)
            parent.insert(i, child[0])


def _serialise(root: ET.Element) -> str:
    _collapse(root)
    ET.indent(root, space="  ")
    body = ET.tostring(root, encoding="unicode", short_empty_elements=True)
    header = (
        '<?xml version="1.0" encoding="utf-8"?>\n'
        "<!-- GENERATED by bioflex_jsb.generators.native_wing (bioflex-jsb export-jsbsim):\n"
        "     do not edit; run `python -m bioflex_jsb.generators.native_wing` to regenerate. -->\n"
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
            " by bioflex_jsb.generators.native_wing -->\n")
    head, sep, rest = text.partition("\n")
    return head + sep + note + rest


_EXTERNAL_REACTIONS = re.compile(
    r"^[ \t]*<external_reactions>.*?</external_reactions>[ \t]*\n", re.DOTALL | re.MULTILINE)
_FIRST_AXIS = re.compile(r'^(?P<indent>[ \t]*)<axis name="LIFT">', re.MULTILINE)


def _axis(name: str) -> re.Pattern:
    return re.compile(rf'^(?P<indent>[ \t]*)<axis name="{name}">[ \t]*\n', re.MULTILINE)


def _indented(xml: str, indent: str) -> str:
    e = ET.fromstring(xml)
    ET.indent(e, space="  ", level=0)
    text = ET.tostring(e, encoding="unicode", short_empty_elements=True)
    return "".join(f"{indent}{line}\n" for line in text.splitlines())


def _modal_aircraft(text: str, sysname: str, spec: ExportSpec) -> str:
    if len(_SYSTEM_INCLUDE.findall(text)) != 1:
        raise ExportError("the generated airframe has no single flight-control system include")
    text = _SYSTEM_INCLUDE.sub(
        lambda m: f"{m.group(0)}\n{m['indent']}<!-- modal wing '{spec.variant}' ({spec.model}), "
        f"step {_num(spec.dt_s)} s: bioflex_jsb.generators.native_wing -->\n"
        f'{m["indent"]}<system file="{sysname}" />',
        text,
    )
    if spec.model != "coupled":
        return text
    # the loads are the airframe's own aerodynamics: no co-simulation hooks
    text, count = _EXTERNAL_REACTIONS.subn("", text)
    if count != 1:
        raise ExportError("the generated airframe has no single <external_reactions>")
    nums = modal_matrices(spec.wing, spec.cl_trim)
    parts = modal_wing_aerodynamics(nums, spec.leapfrog(nums))
    m = _FIRST_AXIS.search(text)
    if m is None:
        raise ExportError("the generated airframe has no LIFT axis")
    note = (f"{m['indent']}<!-- modal wing '{spec.variant}': its loads "
            "(bioflex_jsb.generators.native_wing) -->\n")
    text = text[: m.start()] + note + _indented(parts["functions"], m["indent"]) + text[m.start():]
    for axis in ("LIFT", "DRAG", "PITCH"):
        m = _axis(axis).search(text)
        if m is None:
            raise ExportError(f"the generated airframe has no {axis} axis")
        text = text[: m.end()] + _indented(parts[axis], m["indent"] + "  ") + text[m.end():]
    return text


@dataclass(frozen=True)
class TrimState:
    """The flying aircraft's trimmed state and controls, JSBSim units, for an IC file."""

    ic: dict[str, tuple[str, float]]  # IC element → (unit, value)
    controls: dict[str, float]  # control command property → value


def _trim_num(x: float) -> str:
    """Trim values to 10 significant digits (regeneration stays byte-stable)."""
    x = float(x)
    return "0" if abs(x) < 1e-13 else f"{x:.10g}"


def render_fig21_initial_condition(state: TrimState) -> str:
    """Text of ``aircraft/bioflex_optimised/fig21_trim.xml``: the trimmed state."""
    root = ET.Element("initialize", name=FIG21_IC)
    root.append(ET.Comment(f" trim at {P.SECTION5_AIRSPEED_M_S:g} m/s, ISA sea level, by "
                           "Airframe.trim (bioflex_jsb.runtime.fdm); JSBSim reads "
                           "<elevation> before <altitudeMSL> "))
    for name, (unit, value) in state.ic.items():
        _el(root, name, _trim_num(value), unit=unit)
    _el(root, "running", "-1")
    ET.indent(root, space="  ")
    return ('<?xml version="1.0" encoding="utf-8"?>\n'
            "<!-- GENERATED by bioflex_jsb.generators.native_wing: do not edit. -->\n"
            + ET.tostring(root, encoding="unicode", short_empty_elements=True) + "\n")


def render_fig21_script(state: TrimState, dt_s: float = DEFAULT_DT_S) -> str:
    """Text of ``scripts/fig21_native.xml``: the Fig. 21 case in the plain JSBSim program.

    JSBSim's own trim cannot trim the flying aircraft (physical rotor inertia: module
    docstring of jsbsim_fdm), so the script starts from the Python trim written as an initial
    condition (:func:`render_fig21_initial_condition`), sets the trim controls, holds the
    airframe (integrators off) for ``FIG21_SETTLE_S`` while the propellers spin up to their
    trim RPM, then flies with the co-simulation's integrators; the gust comes
    ``FIG21_GUST_START_S`` later."""
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
            "<!-- GENERATED by bioflex_jsb.generators.native_wing: do not edit. -->\n"
            + body + "\n")


# ======================================================================================
# Writing
# ======================================================================================


def export(spec: ExportSpec, out_dir: Path, include_shared: bool = True) -> list[Path]:
    """Write the system and aircraft files under the JSBSim root ``out_dir``; paths written.
    Raises OSError when the directory cannot be written."""
    return airframe_xml.write_files(render_aircraft_files(spec, include_shared), out_dir)


def repository_files(state: TrimState) -> dict[str, str]:
    """Every file this module owns in the repository: path → text. ``state``: the Fig. 21
    trim the initial condition and the script start from (a JSBSim trim, computed by the
    driver :func:`bioflex_jsb.drivers.native.fig21_trim_state`)."""
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

    files: dict[str, str] = {}
    for name in REPOSITORY_VARIANTS:
        spec = ExportSpec(build_wing(VARIANTS[name]).model, name)
        files.update(render_aircraft_files(spec, include_shared=False))
    files[f"aircraft/{aircraft_name(FIG21_VARIANT)}/{FIG21_IC}.xml"] = (
        render_fig21_initial_condition(state))
    files[FIG21_SCRIPT] = render_fig21_script(state)
    return files
