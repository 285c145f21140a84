"""The modal wing as JSBSim systems: the elastic wing flying in plain JSBSim, no Python in the loop.

:func:`render_system` writes the modal wing of one variant (``coupled`` or ``qsd``) as a JSBSim
``<system>``, :func:`modal_wing_aerodynamics` its loads as aerodynamics of the airframe;
:mod:`bioflex_jsb.generators.native_aircraft` builds the aircraft, ``aircraft/bioflex_<variant>/``,
from the generated rigid airframe's tree with both added. ``docs/native.md`` has the user's view;
this docstring has the numerics.

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
a <difference> of <quotient>s x/(1/c) (``XmlWriter.combination``: JSBSim's <sum> and
<product> copy a reference-counted pointer per argument at every evaluation, these do not). The
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
and ``y-eta<i>-dot``), ``alpha0-rad``, ``qbar0-pa`` (latched trim reference), ``active``,
``idle``, ``enabled`` (0: the rigid airframe with the same file), for an aircraft file's wing
``omega<i>-sq-rad2_s2`` (ω_i² [rad²/s²], 17 digits: its modes, stated); the loads are
``aero/bioflex/modal-lift-lbs``, ``aero/force/modal-lift``, ``aero/force/modal-drag`` [lbs]
and ``aero/moment/modal-pitch`` [lbs ft]. The values (S, c̄, mass, derivatives, modes) are
the wing's airframe's (``ExportSpec.wing.airframe``: the prototype's or a definition's).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.definition.aircraft import default_aircraft
from bioflex_jsb.definition.flying import flight_speeds
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.modal_matrices import ModalMatrices, modal_matrices
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.generators.xml_writer import XmlWriter, collapse, num_12g, serialise
from bioflex_jsb.parameters.airframe import ReferenceGeometry
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3
from bioflex_jsb.simulation.leapfrog import (  # noqa: F401  (re-exported for the checks)
    GRID_SPEED_MAX_M_S,
    GRID_SPEED_STEP_M_S,
    LeapfrogCoefficients,
    leapfrog_coefficients,
    leapfrog_eigen_error,
    leapfrog_matrix,
    leapfrog_step,
)
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S

EXPORT_MODELS = ("coupled", "qsd")
# The trim speed and flight speeds [m/s] of an export given neither: the default aircraft's
# (the prototype's Table 1 cruise, 15 m/s; 5-40 m/s)
DEFAULT_SPEED_M_S, DEFAULT_SPEED_RANGE_M_S = flight_speeds(default_aircraft())
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


# The airspeed [ft/s] the rate terms' c̄/(2V) divide by at least: at rest (an aircraft
# loaded before its initial condition, or standing on the ground) V = 0 made them 0/0, NaN
# forces that an α̇ term (c172p's CLadot) fed back for ever; no flight is near 1e-3 ft/s.
MIN_AIRSPEED_FPS = 1e-3


class ExportError(ValueError):
    """A request the exporter cannot honour (one line)."""


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


def q_grid_pa(rho_ref: float = SEA_LEVEL_DENSITY_KG_M3) -> np.ndarray:
    """Dynamic pressures of the table rows [Pa] (uniform in V_ref)."""
    v = np.arange(0.0, GRID_SPEED_MAX_M_S + 0.5 * GRID_SPEED_STEP_M_S, GRID_SPEED_STEP_M_S)
    return 0.5 * rho_ref * v**2


def qsd_schedule(nums: ModalMatrices, rho_ref: float = SEA_LEVEL_DENSITY_KG_M3):
    """(Q grid, K(Q)⁻¹ stack) of the QSD model's tables."""
    qs = q_grid_pa(rho_ref)
    inv = [np.linalg.inv(np.diag(nums.omega**2) - q * nums.k_aero) for q in qs]
    return qs, np.array(inv)


# ======================================================================================
# XML
# ======================================================================================


W = XmlWriter(num_12g)
el, num, product = W.el, W.number, W.product

# Header of the modal wing's systems (after the XML declaration).
HEADER = (
    "<!-- GENERATED by bioflex_jsb.generators.native_wing (bioflex-jsb export-jsbsim; the\n"
    "     repository's copies: python -m bioflex_jsb.drivers.native): do not edit. -->\n"
)


def _p(name: str) -> str:
    return f"{PREFIX}/{name}"


@dataclass(frozen=True)
class ExportSpec:
    """What to export: the wing (``wing.airframe``: S, c̄, mass, derivatives), its name, the
    model, the step [s], the trim speed [m/s] of the trim C_L (C_0^Q, induced-drag slope), the
    reference density [kg/m³]; ``jsbsim_path``: the aircraft file it is attached to (empty:
    the generated prototype), ``aircraft``: the exported aircraft's name (empty:
    :func:`aircraft_name`), ``jsbsim_chord_m``: c̄ [m] of the file's ``aero/ci2vel`` (0: c̄);
    ``speed_range_m_s``: the speeds [m/s] the aircraft flies (the default aircraft's, the
    prototype's 5-40 m/s; an aircraft definition's flight speeds), where the trim speed must
    lie and over which, from 0, the step's eigenvalues are checked
    (:attr:`check_speed_max_m_s`)."""

    wing: ElasticWingModel
    variant: str
    model: str = "coupled"
    dt_s: float = DEFAULT_DT_S
    speed_m_s: float = DEFAULT_SPEED_M_S
    rho_ref: float = SEA_LEVEL_DENSITY_KG_M3
    jsbsim_path: str = ""
    aircraft: str = ""
    jsbsim_chord_m: float = 0.0
    speed_range_m_s: tuple[float, float] = DEFAULT_SPEED_RANGE_M_S

    def __post_init__(self) -> None:
        if self.model not in EXPORT_MODELS:
            raise ExportError(f"unknown model {self.model!r}; accepted: {', '.join(EXPORT_MODELS)}")
        if not (math.isfinite(self.dt_s) and 0.0 < self.dt_s <= 0.1):
            raise ExportError(f"time step must be in (0, 0.1] s, got {self.dt_s!r}")
        lo, hi = self.speed_range_m_s
        if not (math.isfinite(self.speed_m_s) and lo <= self.speed_m_s <= hi):
            whose = ("the range every command accepts for the prototype"
                     if self.speed_range_m_s == DEFAULT_SPEED_RANGE_M_S else
                     f"the flight speeds of {self.airframe_label}")
            raise ExportError(f"speed {self.speed_m_s:g} m/s is outside {lo:g}..{hi:g} m/s, "
                              f"{whose}")
        if self.jsbsim_path and self.model != "coupled":
            raise ExportError(f"model {self.model!r} puts the wing's loads into the generated "
                              "airframe's external reactions; an aircraft file's wing exports "
                              "the coupled model (its loads in the file's aerodynamics)")
        if self.model == "coupled":
            self._check_step()

    def _check_step(self) -> None:
        """Refuse a step at which the coupled step is not within :data:`EIGEN_REL_TOL` of the
        exact dynamics over 0..check_speed_max_m_s (module docstring)."""
        nums = modal_matrices(self.wing, self.cl_trim)
        err, at = self.eigen_error(nums)
        if err <= EIGEN_REL_TOL:
            return
        ok = self.dt_s
        for _ in range(12):
            ok /= 2.0
            if self.eigen_error(nums, ok)[0] <= EIGEN_REL_TOL:
                break
        raise ExportError(
            f"time step {self.dt_s:.6g} s is too coarse for wing {self.variant!r}: the "
            f"integration's eigenvalues are {err:.1%} off the exact ones at {at:g} m/s of the "
            f"0..{self.check_speed_max_m_s:g} m/s the exported wing flies (trimmed at "
            f"{self.speed_m_s:g} m/s; accepted: {EIGEN_REL_TOL:.0%}); --dt {ok:.6g} s is "
            "within it")

    @property
    def check_speed_max_m_s(self) -> float:
        """The top of the speeds [m/s] the step's eigenvalues are checked over from 0: the
        tables' GRID_SPEED_MAX_M_S, or the aircraft's fastest flight speed if higher."""
        return max(GRID_SPEED_MAX_M_S, float(self.speed_range_m_s[1]))

    def eigen_error(self, nums: ModalMatrices, dt_s: float | None = None
                    ) -> tuple[float, float]:
        """(largest relative error of the step's eigenvalues, its speed [m/s]) over
        0..check_speed_max_m_s at the step ``dt_s`` (default the exported one)."""
        return leapfrog_eigen_error(nums, self.leapfrog(nums, dt_s),
                                    self.check_speed_max_m_s, self.rho_ref)

    @property
    def cl_trim(self) -> float:
        return level_flight_condition(self.speed_m_s, self.rho_ref,
                                      airframe=self.wing.airframe).cl_trim

    @property
    def reference(self) -> ReferenceGeometry:
        """S [m²], b [m], c̄ [m] of the wing's airframe (the modal coefficients')."""
        return self.wing.airframe.reference

    @property
    def ci2vel_chord_m(self) -> float:
        """c̄ [m] of JSBSim's ``aero/ci2vel`` = c̄/(2V) in the aircraft file."""
        return self.jsbsim_chord_m or self.reference.mean_chord_m

    @property
    def aircraft_name(self) -> str:
        """Name (directory and file) of the exported aircraft."""
        return self.aircraft or aircraft_name(self.variant, self.model)

    @property
    def airframe_label(self) -> str:
        name = self.wing.airframe.name
        return "the bioflex UAV" if name == airframe_xml.AIRCRAFT_NAME else f"aircraft {name!r}"

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
    el(root, "description",
        f"Modal wing '{spec.variant}' ({spec.model}, {n} modes) of {spec.airframe_label}, "
        "generated by "
        "bioflex_jsb.generators.native_wing (see its docstring and docs/native.md). "
        f"Exported for a time step of {num(spec.dt_s)} s (simulation/dt must equal it; else "
        f"{PREFIX}/active = 0 and the wing is rigid), trim C_L {spec.cl_trim:.6g} "
        f"({spec.speed_m_s:g} m/s), reference density {spec.rho_ref:g} kg/m3.")
    eta = [_p(f"eta{i + 1}") for i in range(n)]
    etad = [_p(f"eta{i + 1}-dot") for i in range(n)]
    if spec.model == "coupled":
        _coupled_system(root, spec, nums, eta, etad)
        return serialise(root, HEADER, collapse_single=True)
    for name in eta:
        el(root, "property", name, value="0")
    el(root, "property", _p("alpha0-rad"), value="0")
    el(root, "property", _p("qbar0-pa"), value="0")
    el(root, "property", _p("enabled"), value="1")
    el(root, "property", _p("wind-down-prev-fps"), value="0")

    ch = el(root, "channel", name="Modal wing flow")
    W.comment(ch, "flow at the wing in SI (wind of this step included)")
    fn = W.fcs(ch, _p("active"), "1 when simulation/dt is the exported step, else 0 (IC, trim)")
    ift = el(fn, "ifthen")
    lt = el(ift, "lt")
    ab = el(lt, "abs")
    diff = el(ab, "difference")
    W.prop(diff, "simulation/dt")
    W.value(diff, spec.dt_s)
    W.value(lt, DT_MATCH_REL * spec.dt_s)
    W.value(ift, 1.0)
    W.value(ift, 0.0)
    _flow(ch)
    for prop, src in (("alpha0-rad", _p("alpha-rad")), ("qbar0-pa", _p("qbar-pa"))):
        fn = W.fcs(ch, _p(prop.replace("0-", "0-latch-")),
                  f"trim reference: latched from {src} while not active", output=_p(prop))
        ift = el(fn, "ifthen")
        W.prop(ift, _p("active"))
        W.prop(ift, _p(prop))
        W.prop(ift, src)
    fn = W.fcs(ch, _p("dalpha-rad"), "angle of attack from trim, gust included [rad]")
    d = el(fn, "difference")
    W.prop(d, _p("alpha-rad"))
    W.prop(d, _p("alpha0-rad"))
    fn = W.fcs(ch, _p("dqbar-pa"), "dynamic pressure from trim [Pa]")
    d = el(fn, "difference")
    W.prop(d, _p("qbar-pa"))
    W.prop(d, _p("qbar0-pa"))

    ch = el(root, "channel", name="Modal wing")
    _qsd_state(ch, spec, nums, eta)
    _loads(ch, spec, nums, eta, [])
    W.comment(ch, "this step's down wind, for the next step's change")
    g = el(ch, "pure_gain", name=_p("wind-down-store"))
    el(g, "input", "atmosphere/wind-down-fps")
    el(g, "gain", 1.0)
    el(g, "output", _p("wind-down-prev-fps"))
    return serialise(root, HEADER, collapse_single=True)


def _flow(ch: ET.Element) -> None:
    """α, V, Q, Q/V of this step: JSBSim's air-relative body velocities (computed at the end
    of the previous step) with this step's change of the vertical wind added, so a gust
    reaches the wing in the step it reaches the rigid aerodynamics (as in the co-simulation)."""
    fn = W.fcs(ch, _p("dwind-down-fps"), "change of the down wind since the previous step [ft/s]")
    d = el(fn, "difference")
    W.prop(d, "atmosphere/wind-down-fps")
    W.prop(d, _p("wind-down-prev-fps"))
    cos_t = lambda p: W.prop(el(p, "cos"), "attitude/theta-rad")  # noqa: E731
    sin_t = lambda p: W.prop(el(p, "sin"), "attitude/theta-rad")  # noqa: E731
    cos_f = lambda p: W.prop(el(p, "cos"), "attitude/phi-rad")  # noqa: E731
    sin_f = lambda p: W.prop(el(p, "sin"), "attitude/phi-rad")  # noqa: E731
    dwd = _p("dwind-down-fps")
    for axis, terms in (("u", [(1.0, sin_t)]), ("v", [(-1.0, sin_f, cos_t)]),
                        ("w", [(-1.0, cos_f, cos_t)])):  # fmt: skip
        s = el(W.fcs(ch, _p(f"{axis}-air-fps"), f"air-relative body {axis} [ft/s]"), "sum")
        W.prop(s, f"velocities/{axis}-aero-fps")
        for sign, *factors in terms:
            product(s, sign, dwd, *factors)
    fn = W.fcs(ch, _p("alpha-rad"), "angle of attack against the air, gust included [rad]")
    at = el(fn, "atan2")
    W.prop(at, _p("w-air-fps"))
    W.prop(at, _p("u-air-fps"))
    fn = W.fcs(ch, _p("vt-m_s"), "true airspeed V [m/s] (at least 1 ft/s: no division by 0)")
    m = el(el(fn, "product"), "max")
    s = el(el(m, "sqrt"), "sum")
    for axis in "uvw":
        product(s, _p(f"{axis}-air-fps"), _p(f"{axis}-air-fps"))
    W.value(m, 1.0)
    fn.find("product").append(W.value_element(U.M_PER_FT))
    fn = W.fcs(ch, _p("qbar-pa"), "dynamic pressure Q = rho V^2/2 [Pa]")
    product(fn, 0.5 * U.KG_M3_PER_SLUG_FT3, "atmosphere/rho-slugs_ft3", _p("vt-m_s"), _p("vt-m_s"))
    fn = W.fcs(ch, _p("q-over-v"), "Q/V [Pa s/m]")
    q = el(fn, "quotient")
    W.prop(q, _p("qbar-pa"))
    W.prop(q, _p("vt-m_s"))


def _flow_functions(root: ET.Element) -> tuple[str, str, str]:
    """System functions of the flow the modal step sees: (α [rad], 1/Q [1/psf], 2V/c̄ [-]),
    the inverses because the step multiplies by them as x/(1/Q)
    (:meth:`XmlWriter.combination`).

    JSBSim's air data of the previous step (``aero/*``), the state the co-simulation reads,
    except in a step where the down wind changed: then recomputed from the air-relative body
    velocities with this step's change of the wind added (as the co-simulation, which writes
    the wind before it reads the flow), so a gust reaches the wing in the step it reaches the
    rigid aerodynamics. ``ifthen`` evaluates one branch, so a steady wind costs a comparison.
    The previous step's wind is a ``post`` function: evaluated after the channels, its cached
    value is what the next step's functions read."""
    prev = _p("wind-down-prev-fps")
    fn = el(root, "function", name=prev, type="post")
    el(fn, "description", "down wind of this step, read by the next step [ft/s]")
    W.prop(fn, "atmosphere/wind-down-fps")

    def dwd(p):
        d = el(p, "difference")
        W.prop(d, "atmosphere/wind-down-fps")
        W.prop(d, prev)

    cos_t = lambda p: W.prop(el(p, "cos"), "attitude/theta-rad")  # noqa: E731
    sin_t = lambda p: W.prop(el(p, "sin"), "attitude/theta-rad")  # noqa: E731
    cos_f = lambda p: W.prop(el(p, "cos"), "attitude/phi-rad")  # noqa: E731
    sin_f = lambda p: W.prop(el(p, "sin"), "attitude/phi-rad")  # noqa: E731
    terms = {"u": [(1.0, sin_t)], "v": [(-1.0, sin_f, cos_t)], "w": [(-1.0, cos_f, cos_t)]}

    def air(parent, axis):
        s = el(parent, "sum")
        W.prop(s, f"velocities/{axis}-aero-fps")
        for sign, *factors in terms[axis]:
            product(s, sign, dwd, *factors)

    def speed_squared(parent):
        s = el(parent, "sum")
        for axis in "uvw":
            p = el(s, "pow")
            air(p, axis)
            W.value(p, 2.0)

    def alpha(parent):
        at = el(parent, "atan2")
        air(at, "w")
        air(at, "u")

    def inverse(parent, of):
        q = el(parent, "quotient")
        W.value(q, 1.0)
        of(q)

    def qbar(parent):
        speed_squared(product(parent, 0.5, "atmosphere/rho-slugs_ft3"))

    def ci2vel(parent):
        q = el(parent, "quotient")
        W.prop(q, "metrics/cbarw-ft")
        product(q, 2.0, lambda p: speed_squared(el(p, "sqrt")))

    flows = (("alpha-rad", "angle of attack against the air, gust included [rad]", alpha,
              lambda p: W.prop(p, "aero/alpha-rad")),
             ("qbar-inv", "1/Q [1/psf] (1/0 gives JSBSim's HUGE_VAL, so x/(1/Q) = 0)",
              lambda p: inverse(p, qbar),
              lambda p: inverse(p, lambda q: W.prop(q, "aero/qbar-psf"))),
             ("ci2vel-inv", "2V/cbar [-], the inverse of aero/ci2vel",
              lambda p: inverse(p, ci2vel),
              lambda p: inverse(p, lambda q: W.prop(q, "aero/ci2vel"))))  # fmt: skip
    names = []
    for name, text, corrected, steady in flows:
        fn = el(root, "function", name=_p(name))
        el(fn, "description", text)
        ift = el(fn, "ifthen")
        ne = el(ift, "nq")  # the down wind changed since the previous step
        W.prop(ne, "atmosphere/wind-down-fps")
        W.prop(ne, prev)
        corrected(ift)
        steady(ift)
        names.append(_p(name))
    return names


def _forcing_terms(fn_sum: ET.Element, nums: ModalMatrices, i: int) -> None:
    """Q Δα b_α + (Q/V) q b_q + ΔQ b_0 for mode i (SI generalised acceleration)."""
    product(fn_sum, float(nums.b_alpha[i]), _p("qbar-pa"), _p("dalpha-rad"))
    product(fn_sum, float(nums.b_q[i]), _p("q-over-v"), "velocities/q-rad_sec")
    product(fn_sum, float(nums.b_0[i]), _p("dqbar-pa"))


def _qsd_state(ch, spec: ExportSpec, nums: ModalMatrices, eta: list[str]) -> None:
    n = nums.n
    W.comment(ch, "quasi-static deformation: eta = K(Q)^-1 r, K(Q) = diag(w^2) - Q K_a (tables)")
    for i in range(n):
        s = el(W.fcs(ch, _p(f"r{i + 1}"), f"static generalised force on mode {i + 1} [1/s2]"),
                "sum")
        _forcing_terms(s, nums, i)
    qs, inv = qsd_schedule(nums, spec.rho_ref)
    for i in range(n):
        fn = W.fcs(ch, _p(f"eta{i + 1}-qsd"), f"quasi-static eta{i + 1} [rad]", output=eta[i])
        prod = el(fn, "product")
        W.prop(prod, _p("active"))
        s = el(prod, "sum")
        for j in range(n):
            rows = list(zip(qs, inv[:, i, j], strict=True))
            product(s, lambda p, rows=rows: W.table(p, _p("qbar-pa"), rows, width=20),
                    _p(f"r{j + 1}"))


def _loads(ch, spec: ExportSpec, nums: ModalMatrices, eta: list[str], etad: list[str]) -> None:
    s_ref, cb = spec.reference.area_m2, spec.reference.mean_chord_m
    W.comment(ch, "incremental loads: Q S (C_eta eta + C_etadot etadot cbar/(2V)), wind axes, SI")
    names = (("lift-n", "lift, up, normal to the air velocity [N]"),
             ("drag-n", "drag, aft, along the air velocity [N]"),
             ("pitch-n_m", "pitching moment about the CG, nose up [N m]"))  # fmt: skip
    for r, (name, text) in enumerate(names):
        prod = el(W.fcs(ch, _p(name), text), "product")
        W.prop(prod, _p("enabled"))
        total = el(prod, "sum")
        if any(nums.load_eta[r]):
            inner = product(total, s_ref, _p("qbar-pa"))
            W.linear(el(inner, "sum"), list(zip(nums.load_eta[r], eta, strict=True)))
        if etad and any(nums.load_etadot[r]):
            inner = product(total, s_ref * cb / 2.0, _p("q-over-v"))
            W.linear(el(inner, "sum"), list(zip(nums.load_etadot[r], etad, strict=True)))
    W.comment(ch, "into the airframe's external reactions, body axes, JSBSim units")
    lift, drag = _p("lift-n"), _p("drag-n")
    cos_a = lambda p: el(el(p, "cos"), "property", _p("alpha-rad"))  # noqa: E731
    sin_a = lambda p: el(el(p, "sin"), "property", _p("alpha-rad"))  # noqa: E731
    for name, first, second, sign in (("modal-lift", lift, drag, 1.0),
                                      ("modal-drag", drag, lift, -1.0)):  # fmt: skip
        fn = W.fcs(ch, _p(f"{name}-lbs"), f"{name} force [lbs]",
                  output=airframe_xml.external_property(name))
        s = el(product(fn, U.LBF_PER_N), "sum")
        product(s, first, cos_a)
        product(s, sign, second, sin_a)
    fn = W.fcs(ch, _p("modal-pitch-lbsft"), "modal-pitch moment [lbs ft]",
              output=airframe_xml.external_property("modal-pitch"))
    product(fn, U.LBF_FT_PER_N_M, _p("pitch-n_m"))


def _assign(ch: ET.Element, name: str, description: str, value, outputs: list[str]) -> None:
    """One fcs_function writing ``value`` (property name or number) to every output."""
    comp = el(ch, "fcs_function", name=name)
    el(comp, "description", description)
    fn = el(comp, "function")
    if isinstance(value, str):
        W.prop(fn, value)
    else:
        W.value(fn, value)
    for out in outputs:
        el(comp, "output", out)


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
        el(root, "property", name, value="0")
    for name in ("alpha0-rad", "qbar0-pa", "never"):
        el(root, "property", _p(name), value="0")
    el(root, "property", _p("enabled"), value="1")
    if spec.jsbsim_path:  # an aircraft file's wing states its modes (not read by the step)
        for i, w in enumerate(nums.omega):
            el(root, "property", _p(f"omega{i + 1}-sq-rad2_s2"), value=repr(float(w * w)))

    W.comment(root, "system functions, evaluated once per step before the channels")
    fn = el(root, "function", name=_p("active"))
    el(fn, "description", "1 when simulation/dt is the exported step, else 0 (IC, trim)")
    lt = el(fn, "lt")
    diff = el(el(lt, "abs"), "difference")
    W.prop(diff, "simulation/dt")
    W.value(diff, spec.dt_s)
    W.value(lt, DT_MATCH_REL * spec.dt_s)
    fn = el(root, "function", name=_p("idle"))
    el(fn, "description", "1 while not active")
    d = el(fn, "difference")
    W.value(d, 1.0)
    W.prop(d, _p("active"))
    alpha, qbar_inv, ci2vel_inv = _flow_functions(root)

    ch = el(root, "channel", name="Modal wing trim reference", execute=_p("idle"))
    W.comment(ch, "while not active (IC, trim, another step): the trim reference latched from "
                 "the flow, the modal state (and so the loads) held at zero")
    _assign(ch, _p("alpha0-latch"), "trim angle of attack [rad]", "aero/alpha-rad",
            [_p("alpha0-rad")])
    fn = W.fcs(ch, _p("qbar0-latch"), "trim dynamic pressure [Pa]", output=_p("qbar0-pa"))
    product(fn, U.PA_PER_PSF, "aero/qbar-psf")
    _assign(ch, _p("reset"), "stored modal state to zero", 0.0, y_eta + y_rate)
    W.comment(ch, "the trim terms of each mode's kick, latched with the trim reference and "
                 "stored negated (the step subtracts them): -Q (b_0 - b_alpha alpha_0) per "
                 "unit aero/qbar-psf and b_0 Q_0, times the kick gain")
    for i in range(n):
        g = co.kick[i] * U.PA_PER_PSF
        s = el(W.fcs(ch, f"{neg_bias_q[i]}-latch", f"minus the trim kick of mode {i + 1} per "
                     "unit aero/qbar-psf [rad/s/psf]", output=neg_bias_q[i]), "sum")
        W.value(s, -g * nums.b_0[i])
        product(s, g * nums.b_alpha[i], "aero/alpha-rad")
        fn = W.fcs(ch, f"{neg_bias[i]}-latch", f"minus the constant trim kick of mode {i + 1} "
                  "[rad/s]", output=neg_bias[i])
        product(fn, co.kick[i] * nums.b_0[i] * U.PA_PER_PSF, "aero/qbar-psf")

    ch = el(root, "channel", name="Modal wing state", execute=_p("never"))
    W.comment(ch, "never executed: declares the modal state at the current time, x = Phi_h^-1 "
                 "y, as named functions, evaluated when read (no cost per step)")
    fn = W.fcs(ch, _p("state"), "eta<i> [rad] and eta<i>-dot [rad/s] of the current step")
    s = el(fn, "sum")
    for i in range(n):
        h = co.half_inv[i]
        for row, name in ((0, eta[i]), (1, etad[i])):
            W.combination(s, [(h[row, 0] * co.eta_rate[i], y_eta[i]), (h[row, 1], y_rate[i])],
                         name=name)

    # c̄ of JSBSim's aero/ci2vel (the aircraft file's): Q/V = Q (2/c̄) aero/ci2vel exactly
    pa, c_bar = U.PA_PER_PSF, spec.ci2vel_chord_m
    ch = el(root, "channel", name="Modal wing", execute=_p("active"))
    W.comment(ch, "leapfrog step (Strang splitting) of the stored half-step state y: the rate "
                 "kicked by the aerodynamic acceleration of y and advanced by the exact "
                 "structural step, then the displacement from the new rate. Flow: JSBSim's air "
                 "data of the previous step; Q = PA_PER_PSF aero/qbar-psf [Pa], "
                 "Q/V = Q (2/cbar) aero/ci2vel [Pa s/m] (aero/ci2vel = cbar/(2V)). Weighted "
                 "sums are differences of quotients x/(1/c): JSBSim evaluates them faster than "
                 "sums of products")
    for i in range(n):
        g = co.kick[i] * pa
        fn = W.fcs(ch, f"{y_rate[i]}-step", f"stored rate of mode {i + 1} after the step [rad/s]",
                  output=y_rate[i])
        damp = [(g * 2.0 / c_bar * d, r) for d, r in zip(nums.d_aero[i], y_rate, strict=True)]
        damp.append((g * 2.0 / c_bar * nums.b_q[i], "velocities/q-rad_sec"))
        stiff = [(g * k * c, e)
                 for k, c, e in zip(nums.k_aero[i], co.eta_rate, y_eta, strict=True)]
        stiff.append((g * nums.b_alpha[i], alpha))

        def aero(parent, damp=damp, stiff=stiff, i=i):
            # Q (K_a eta + b_alpha alpha + ... + (Q/V)/Q (D_a etadot + b_q q)), in psf
            W.combination(parent, stiff, minus=(neg_bias_q[i],),
                         lead=W.over(lambda p: W.combination(p, damp), ci2vel_inv))

        own = co.rate_eta[i] - co.kick[i] * co.q_ref_pa * nums.k_aero[i, i]
        W.combination(fn, [(own * co.eta_rate[i], y_eta[i]),
                          (co.rate_rate[i] - co.kick[i] * co.q_over_v_ref * nums.d_aero[i, i],
                           y_rate[i])],
                     lead=W.over(aero, qbar_inv), minus=(neg_bias[i],))
    for i in range(n):
        fn = W.fcs(ch, f"{y_eta[i]}-step", f"stored eta{i + 1} after the step, scaled [rad/s]",
                  output=y_eta[i])
        W.combination(fn, [(co.eta_eta[i], y_eta[i])],
                     lead=lambda p, i=i: W.prop(p, y_rate[i]))


def _stored_state(n: int) -> tuple[list[str], list[str]]:
    """Stored state: the half-step displacement scaled by 1/c_i (c_i = Φ_s[0, 1]/Φ_s[1, 1]
    ≈ Δt, :attr:`LeapfrogCoefficients.eta_rate`, so its row is one product and a sum) and the
    half-step rate."""
    return ([_p(f"y-eta{i + 1}-scaled") for i in range(n)],
            [_p(f"y-eta{i + 1}-dot") for i in range(n)])


def modal_wing_aerodynamics(nums: ModalMatrices, co: LeapfrogCoefficients,
                            reference: ReferenceGeometry) -> dict[str, ET.Element]:
    """The native modal wing's loads as JSBSim aerodynamics of the airframe: ``<function>``
    elements keyed by where they go (``speed``, then ``functions``: before the first axis, in
    that order; ``LIFT``, ``DRAG``, ``PITCH``: into those axes).

    Loads of the stored state y = Φ_h x after this step's update, the structural state half
    a step into the interval over which JSBSim applies the forces it computes (module
    docstring), η and η̇ read as its two parts: ΔL = Q S (C_L_η·η + C_L_η̇·η̇ c̄/(2V)) in the
    LIFT axis, the drag k₂ ΔL (k₂ = 2kC_L0, C_D_η = k₂ C_L_η) in the DRAG axis, ΔM = Q S c̄
    (C_m_η·η + C_m_η̇·η̇ c̄/(2V)) in the PITCH axis (about the aerodynamic reference point,
    which is the CG); Q and V JSBSim's air data of this step; × ``enabled``. The lift
    is an aerodynamics function evaluated once per step (``aero/bioflex/modal-lift-lbs``),
    read by the LIFT and DRAG axes. ``reference``: S [m²] and c̄ [m] of the modal coefficients
    (the wing's airframe's; default the prototype's)."""
    n = nums.n
    y_eta, y_rate = _stored_state(n)
    # k₂ from the largest lift term (a pure bending mode's C_L_η is 0: the SGS's first)
    lift_terms = np.concatenate([nums.load_eta[0], nums.load_etadot[0]])
    drag_terms = np.concatenate([nums.load_eta[1], nums.load_etadot[1]])
    big = int(np.argmax(np.abs(lift_terms)))
    k2 = float(drag_terms[big] / lift_terms[big]) if lift_terms[big] else 0.0
    if not (np.allclose(nums.load_eta[1], k2 * nums.load_eta[0])
            and np.allclose(nums.load_etadot[1], k2 * nums.load_etadot[0])):
        raise ExportError("the modal drag is not proportional to the modal lift")
    s_ref, qbar = reference.area_m2, "aero/qbar-psf"
    # c̄/(2V) from this step's airspeed: JSBSim updates aero/ci2vel only after the
    # aerodynamics' own functions have run, so it would be the previous step's
    half_chord_ft = 0.5 * reference.mean_chord_m * U.FT_PER_M

    # V [ft/s], at least MIN_AIRSPEED_FPS: one function a step, read by the lift and pitch
    speed_fn = "aero/bioflex/vt-guarded-fps"
    speed = ET.Element("function", name=speed_fn)
    el(speed, "description", f"airspeed [ft/s], at least {MIN_AIRSPEED_FPS:g} (no 0/0 at rest)")
    m = el(speed, "max")
    W.prop(m, "velocities/vt-fps")
    W.value(m, MIN_AIRSPEED_FPS)

    def airspeed(parent: ET.Element) -> None:
        W.prop(parent, speed_fn)

    def loads(fn: ET.Element, r: int, gain: float) -> None:
        c = gain * U.PA_PER_PSF * s_ref
        disp = [(c * nums.load_eta[r, i] * co.eta_rate[i], y_eta[i]) for i in range(n)]
        rate = [(c * half_chord_ft * nums.load_etadot[r, i], y_rate[i]) for i in range(n)]
        lead = (W.over(lambda q: W.combination(q, rate), airspeed)
                if any(a for a, _ in rate) else None)
        total = lambda p: W.combination(p, disp, lead=lead)  # noqa: E731
        W.times(W.times(total, qbar), _p("enabled"))(fn)

    lift_fn = "aero/bioflex/modal-lift-lbs"
    lift = ET.Element("function", name=lift_fn)
    el(lift, "description", "modal wing: lift of the modal state [lbs]")
    loads(lift, 0, U.LBF_PER_N)
    in_lift = ET.Element("function", name="aero/force/modal-lift")
    el(in_lift, "description", "modal wing lift [lbs]")
    W.prop(in_lift, lift_fn)
    in_drag = ET.Element("function", name="aero/force/modal-drag")
    el(in_drag, "description", f"modal wing drag: {num(k2)} x its lift [lbs]")
    product(in_drag, k2, lift_fn)
    pitch = ET.Element("function", name="aero/moment/modal-pitch")
    el(pitch, "description", "modal wing pitching moment about the CG, nose up [lbs ft]")
    loads(pitch, 2, U.LBF_FT_PER_N_M)
    out = {}
    for key, e in (("speed", speed), ("functions", lift), ("LIFT", in_lift), ("DRAG", in_drag),
                   ("PITCH", pitch)):
        collapse(e)
        out[key] = e
    return out
