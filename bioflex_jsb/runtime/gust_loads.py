"""The loads of a gust that varies over the aircraft, written to JSBSim every step.

The coupled step (:mod:`bioflex_jsb.runtime.coupled_step`) writes the symmetric vertical gust
w̄ to JSBSim's wind, ``atmosphere/wind-down-fps`` = −w̄: JSBSim's rigid aerodynamics and the
modal wing take it at the CG, uniform over the aircraft. :class:`GustLoads` adds, before each
step, what the parts of a :class:`~bioflex_jsb.simulation.spanwise_gusts.SpanwiseGustField`
change:

* **lateral gust v_g** through JSBSim's own wind, horizontal and perpendicular to the trim
  heading ψ_0 (a gust of the air, fixed to the earth, not to the aircraft):
  ``wind-north-fps`` = −v_g sin ψ_0, ``wind-east-fps`` = v_g cos ψ_0 (NED; at wings level
  and ψ = ψ_0 the body axes see v_wind = v_g, so β_air = β − v_g/V, the lateral model's
  input). JSBSim's C_Yβ, C_lβ, C_nβ (its sideslip against the air) then carry it; nothing is
  added by hand.
* **rolling gust p_g** as external moments, JSBSim's own rate derivatives with p − p_g:
  its rolling-moment table is C_lp · qbar S b · b/(2V) · p_aero (``aero/bi2vel``,
  ``velocities/p-aero-rad_sec``), so the gust's share is

      ΔL = −C_lp qbar S b (b/2V) p_g  (``gust-roll``),  ΔN = −C_np qbar S b (b/2V) p_g
      (``gust-yaw``),

  with the same qbar, S, b, b/(2V) JSBSim multiplies (read from it each step). Why C_lp
  and not the strip integral ΔL = −∫ l y dy: the airframe's roll damping *is* C_lp, and a
  field of air rolling with the aircraft (p_g = p) must leave it no moment; the strip
  integral with its own weights would leave (C_lp,strip − C_lp) Q S b² p/(2V). The strips
  fix the *shape* (p_g of a non-linear field by first-moment equivalence); for a wing whose
  C_lp is its strips' the two are one (tests/test_spanwise_gusts.py). No double count:
  JSBSim's p_aero is p minus its own turbulence rates, which are off (its turbulence model
  is never enabled here), so its table carries p alone; an elastic wing's antisymmetric
  strips that take p_g carry only their elastic increments (their rigid part is this).
* **tail penetration delay**: JSBSim's C_Lα, C_mα give the tail the gust of the wing's
  instant; the tail meets it τ = l_t/V later, so the difference
  ΔL_t = qbar S a_t,S (1 − dε/dα) (w_t − w̄)/V (up, body −z at the CG, ``gust-lift``) and
  ΔM = −l_t ΔL_t (nose up, ``gust-pitch``) are added
  (:class:`~bioflex_jsb.simulation.spanwise_gusts.TailGust`: the tail of the aircraft's
  rigid derivatives). The tail's lift is taken normal to the body x axis (at the trim's
  α of 1.8°: cos α = 0.9995).

A step's loads belong to t_k, written before JSBSim's step k, as the coupled step writes the
wing's. The hooks are the airframe's ``gust-*`` external reactions
(:mod:`bioflex_jsb.generators.airframe`); an aircraft without them (a native export) is
refused in one line.
"""

from __future__ import annotations

import math

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.errors import InputError
from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation import jsbsim_properties as JP
from bioflex_jsb.simulation.spanwise_gusts import (
    GustParts,
    SpanStations,
    SpanwiseGustField,
    TailGust,
    gust_field,
)

GUST_HOOKS = ("gust-lift", "gust-pitch", "gust-roll", "gust-yaw")
BLOCK_STEPS = 256  # the field's parts are computed this many steps at a time
# The run's extra channels (units): the parts the loads were written from.
GUST_CHANNELS = {"p_g": "rad/s", "v_g": "m/s", "w_g_tail": "m/s"}
_BI2VEL, _QBAR, _VT = JP.AERO_BI2VEL, JP.AERO_QBAR_PSF, JP.VELOCITIES_VT_FPS
_SW, _BW = JP.METRICS_SW_SQFT, JP.METRICS_BW_FT


def span_stations(build, airframe_data) -> SpanStations:
    """The strips of the wing's build (its vortex lattice's C_lα c, mirrored), or without a
    build a rectangular wing of the aircraft's S, b and uniform C_Lα."""
    ref = airframe_data.reference
    if build is not None:
        a = build.aero
        return SpanStations.from_half_wing(a.stations_m, a.weights_m, a.cl_alpha_c_m_per_rad,
                                           ref.area_m2, ref.span_m)
    return SpanStations.rectangular(ref.span_m, ref.area_m2 / ref.span_m,
                                    airframe_data.aero.cl_alpha_per_rad)


def field_for(spec, airframe_data, build=None, speed_m_s: float = 15.0, start_s: float = 0.5,
              duration_s: float = 10.0, dt_s: float = 1.0 / 120.0):
    """The gust field of ``spec`` on this aircraft (:func:`~bioflex_jsb.simulation.
    spanwise_gusts.gust_field`): the uniform field, or the spanwise one over the build's
    strips with the tail of the aircraft's derivatives (only when the gust has a tail
    delay: an aircraft without an elevator flies every other part)."""
    if spec.spanwise is None:
        return gust_field(spec, speed_m_s, start_s=start_s, duration_s=duration_s, dt_s=dt_s)
    tail = None
    if spec.spanwise.tail_delay:
        tail = TailGust.from_derivatives(airframe_data.aero, airframe_data.reference.mean_chord_m)
    return gust_field(spec, speed_m_s, span_stations(build, airframe_data), tail, start_s,
                      duration_s, dt_s)


class GustLoads:
    """Writes the loads of ``field``'s parts (module docstring) into ``airframe`` before each
    step; ``aero`` the aircraft's rigid derivatives (its C_lp, C_np of JSBSim's tables),
    ``heading_rad`` ψ_0 the trim heading the lateral gust is perpendicular to; ``rigid_roll``
    False leaves the rolling moment to a wing model that carries its rigid part itself."""

    def __init__(self, airframe: Airframe, field: SpanwiseGustField, aero,
                 heading_rad: float, rigid_roll: bool = True) -> None:
        node = airframe.property_node
        try:
            self._set = tuple(node(airframe_xml.external_property(h)).set_double_value
                              for h in GUST_HOOKS)
        except KeyError:
            raise InputError(f"the aircraft {airframe.aircraft!r} has no gust hooks "
                             f"({', '.join(GUST_HOOKS)}): a gust with spanwise parts flies the "
                             "Python wing's aircraft (not --model native)") from None
        self._north = node(JP.ATMOSPHERE_WIND_NORTH_FPS).set_double_value
        self._east = node(JP.ATMOSPHERE_WIND_EAST_FPS).set_double_value
        self._get = tuple(node(p).get_double_value for p in (_QBAR, _SW, _BW, _BI2VEL, _VT))
        self.field = field
        self._clp = aero.cl_p_per_rad if rigid_roll else 0.0
        self._cnp = aero.cn_p_per_rad if rigid_roll else 0.0
        tail = field.tail
        self._tail_arm_ft = tail.arm_m * U.FT_PER_M if tail is not None else 0.0
        self._tail_slope = tail.lift_slope_per_rad if tail is not None else 0.0
        self._sin, self._cos = math.sin(heading_rad), math.cos(heading_rad)
        self._parts: GustParts | None = None
        self._k0 = 0
        self.last = (0.0, 0.0, 0.0)  # p_g [rad/s], v_g [m/s], w_t [m/s] of the last step

    def apply(self, k: int) -> None:
        """Write the loads of step ``k`` (t_k = k Δt)."""
        parts = self._parts
        if parts is None or not self._k0 <= k < self._k0 + len(parts.p_g):
            self._k0, parts = k, self.field.parts(BLOCK_STEPS, k)
            self._parts = parts
        i = k - self._k0
        p_g, v_g = float(parts.p_g[i]), float(parts.v_g[i])
        w_t, w_sym = float(parts.w_tail[i]), float(parts.w_sym[i])
        qbar, sw, bw, bi2vel, vt = (g() for g in self._get)
        v_fps = v_g * U.FT_PER_M
        self._north(-v_fps * self._sin)
        self._east(v_fps * self._cos)
        rate = qbar * sw * bw * bi2vel * p_g  # [lbf·ft] per unit C_lp
        lift = qbar * sw * self._tail_slope * (w_t - w_sym) * U.FT_PER_M / vt if vt > 0 else 0.0
        set_lift, set_pitch, set_roll, set_yaw = self._set
        set_lift(lift)
        set_pitch(-self._tail_arm_ft * lift)
        set_roll(-self._clp * rate)
        set_yaw(-self._cnp * rate)
        self.last = (p_g, v_g, w_t)

    @property
    def roll_rate_rad_s(self) -> float:
        """p_g [rad/s] of the step last written: the gust roll rate an elastic wing's
        antisymmetric strips take in the same step (their upwash (p − p_g)·y)."""
        return self.last[0]

    def clear(self) -> None:
        """No gust loads and no horizontal wind left in the airframe."""
        for s in self._set:
            s(0.0)
        self._north(0.0)
        self._east(0.0)


def with_gust_loads(stepper, step, loads: GustLoads):
    """``stepper`` (a coupled step's ``step(w_g, table, k) -> stopped``) with ``loads``
    written before each step, at the coupled step's own step count (``step.k``). A step of
    both wing halves (``step.lateral`` set: runtime/full_span_step.py) also takes the step's
    gust roll rate p_g on its antisymmetric strips (their elastic increments; the rigid
    rolling moment stays ``gust-roll``'s, so nothing is counted twice)."""
    apply = loads.apply
    if getattr(step, "lateral", None) is not None:

        def advance_full_span(w_g_m_s: float, table: np.ndarray, k: int):
            apply(step.k)
            return stepper(w_g_m_s, table, k, loads.last[0])

        return advance_full_span

    def advance(w_g_m_s: float, table: np.ndarray, k: int):
        apply(step.k)
        return stepper(w_g_m_s, table, k)

    return advance
