"""Both wing halves in the coupled step: what :class:`~bioflex_jsb.runtime.coupled_step
.CoupledStep` does with ``span="full"`` (the physics: :mod:`bioflex_jsb.simulation.full_span`).

A mixin of CoupledStep, kept apart so that the half wing's step reads as before: it builds
the antisymmetric modal wing of the run's build on the JSBSim airframe's roll inertia
(:func:`~bioflex_jsb.flight_dynamics.lateral_elastic.antisymmetric_wing`), adds its channels
to the row, steps it (the Python reference, or the compiled
:func:`~bioflex_jsb.simulation.full_span_kernel.full_span_kernel` in one call with the half
wing's), reads JSBSim's two aileron positions and writes its rolling moment, side force and
yawing moment to ``external_reactions/modal-roll``, ``modal-side`` and ``modal-yaw`` each
step. Per step it costs two property reads, three writes and the antisymmetric modes'
arithmetic (``bioflex-jsb bench``). The wing's lift L_w = n_z W of the yaw rate's terms
takes the aircraft's weight W from JSBSim's mass once, at set-up (a run's fuel burn is not
followed).
"""

from __future__ import annotations

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.errors import InputError
from bioflex_jsb.generators.airframe import external_property
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
from bioflex_jsb.simulation import jsbsim_properties as JP
from bioflex_jsb.simulation import step_kernel as K
from bioflex_jsb.simulation.limits import ETA_LIMIT_RAD, mode_labels, out_of_range

SPANS = ("half", "full")
AILERON_PROPERTIES = (JP.FCS_LEFT_AILERON_POS_RAD, JP.FCS_RIGHT_AILERON_POS_RAD)
IXX_PROPERTY = JP.INERTIA_IXX_SLUGS_FT2


def check_span(span: str, build, model: str, aero: str) -> None:
    """A full-span step needs the wing's build (its beam: the antisymmetric modes) and a
    wing of ours (not the native one); one line otherwise. Its strips are the run's
    ``aero`` (unsteady: the coupled wing's, :mod:`bioflex_jsb.simulation
    .unsteady_full_span`)."""
    if span not in SPANS:
        raise InputError(f"unknown span {span!r}; accepted: {', '.join(SPANS)}")
    if span == "half":
        return
    if model == "native":
        raise InputError("span='full' flies the Python modal wing, not the native one")
    if build is None:
        raise InputError("span='full' needs the wing's build (its beam, for the "
                         "antisymmetric modes), not only its ElasticWingModel")


class FullSpanSteps:
    """The full-span part of CoupledStep (module docstring); ``self.lateral`` is the
    :class:`~bioflex_jsb.simulation.full_span.AntisymmetricModalWing` (None: half wing)."""

    def _make_lateral(self, span: str, aileron, build, model: str):
        """The antisymmetric wing of a full-span run (None for ``half``), its channels in
        :attr:`units`, the aileron readers and the roll writer bound."""
        if span == "half":
            return None
        from bioflex_jsb.aeroelasticity.antisymmetric_strips import (
            antisymmetric_strips,
            yaw_sideslip_terms,
        )
        from bioflex_jsb.flight_dynamics.lateral_elastic import antisymmetric_wing
        from bioflex_jsb.simulation.full_span import (
            AntisymmetricModalWing,
            lateral_channel_units,
        )
        from bioflex_jsb.simulation.modal_wing import one_blas_thread

        airframe = self.airframe
        for name in AILERON_PROPERTIES:
            if not airframe.has_property(name):
                raise InputError(f"span='full' reads the ailerons' positions; the JSBSim "
                                 f"aircraft {airframe.aircraft!r} has no {name!r}")
        ixx = airframe[IXX_PROPERTY] * U.KG_PER_SLUG * U.M_PER_FT**2
        # on one BLAS thread, as the reference steps are: a multi-threaded call leaves
        # OpenBLAS's other thread spinning for ~0.1 s after it, on this process's CPU clock
        # and on the second core, while the run steps (the results are the same, bit for bit)
        refresh = getattr(self.wing, "refresh_rel", 0.05)
        with one_blas_thread():
            wing_a = antisymmetric_wing(build, ixx)
            strips = antisymmetric_strips(wing_a, aileron, np.asarray(build.aero.chord_m))
            sym_tip = np.asarray(build.modes.twist_rad, dtype=float)[:self.n_modes, -1]
            terms = yaw_sideslip_terms(wing_a, build.modes, self.n_modes, build.planform,
                                       2.0 * float(build.aero.semispan_m))
            if self.aero == "unsteady":  # the coupled wing's unsteady strips, both halves
                from bioflex_jsb.aeroelasticity.antisymmetric import aircraft_strips
                from bioflex_jsb.simulation.unsteady_full_span import UnsteadyAntisymmetricWing

                lateral = UnsteadyAntisymmetricWing(
                    strips, aircraft_strips(build, wing_a, ixx), model, self.dt_s, sym_tip,
                    refresh_rel=refresh, terms=terms)
            else:
                lateral = AntisymmetricModalWing(strips, model, self.dt_s, sym_tip,
                                                 refresh_rel=refresh, terms=terms)
        # the aircraft's weight [N] (L_w = n_z W) and the symmetric trim deflection [rad]
        self._weight_n = (airframe[JP.INERTIA_MASS_SLUGS] * U.KG_PER_SLUG
                          * STANDARD_GRAVITY_M_S2)
        self._static_eta_s = np.asarray(getattr(self.wing, "static_eta",
                                                np.zeros(self.n_modes)), dtype=float).copy()
        self.units.update(lateral_channel_units(lateral.n_modes))
        node = airframe.property_node
        self._get_left_aileron = node(AILERON_PROPERTIES[0]).get_double_value
        self._get_right_aileron = node(AILERON_PROPERTIES[1]).get_double_value
        self._set_roll = node(external_property("modal-roll")).set_double_value
        self._set_side = node(external_property("modal-side")).set_double_value
        self._set_yaw = node(external_property("modal-yaw")).set_double_value
        zeros = np.zeros(lateral.n_modes)
        self._lateral_row = lateral.row(0.0, 0.0, zeros, zeros, np.zeros(self.n_modes))
        self.antisymmetric_wing = wing_a
        return lateral

    # -- the Python step ---------------------------------------------------------------------
    def _lateral_python_step(self, state, eta_s, p_g_rad_s: float) -> None:
        """Step the antisymmetric wing with the snapshot ``state`` of t_k (its flow, p),
        JSBSim's ailerons now and the gust roll rate; write its rolling moment for JSBSim's
        step and keep the row's channels (η_a, η̇_a of t_k; ``eta_s`` the half wing's η_k)."""
        from bioflex_jsb.simulation.full_span import LateralInputs

        lat, f = self.lateral, state.flow
        aileron = 0.5 * (self._get_left_aileron() - self._get_right_aileron())
        eta_a, eta_a_dot = lat.eta.copy(), lat.eta_dot.copy()
        q_pa, v = f.dynamic_pressure_pa, f.airspeed_m_s
        lift = state.n_z * self._weight_n
        static = self._static_eta_s
        inputs = LateralInputs(state.p_rad_s, aileron, float(p_g_rad_s), state.r_rad_s,
                               state.beta_rad, lift, static + np.asarray(eta_s))
        lat.step(q_pa, v, inputs)
        # the loads of η_{k+1} with the symmetric wing's η_{k+1} (stepped before this one)
        after = LateralInputs(state.p_rad_s, aileron, float(p_g_rad_s), state.r_rad_s,
                              state.beta_rad, lift, static + self.wing.eta)
        moment, side, yaw = lat.reactions(q_pa, v, after)
        self._set_roll(moment * U.LBF_FT_PER_N_M)
        self._set_side(side * U.LBF_PER_N)
        self._set_yaw(yaw * U.LBF_FT_PER_N_M)
        self._lateral_row = lat.row(aileron, moment, eta_a, eta_a_dot, eta_s, side, yaw)

    def _renew_lateral(self, q_pa: float, v_m_s: float) -> None:
        """Renew the antisymmetric wing's reference step at (Q, V) (with the half wing's)."""
        lat = self.lateral
        if lat.model != "coupled":
            return
        lat.reference(float(q_pa), float(v_m_s))
        if self.compiled and self.aero == "unsteady":  # runtime/unsteady_full_span_step.py
            from bioflex_jsb.runtime.unsteady_full_span_step import load_reference

            load_reference(self)
        elif self.compiled:
            lv = self._lat_views
            lv["stack"][:] = np.ravel(lat._stack)
            lv["input_cols"][:] = np.ravel(lat._input_cols)
            lv["force_map"][:] = np.ravel(lat._force_map)
            lv["key"][:] = lat._key

    def _switch_lateral(self, model: str) -> None:
        """The antisymmetric wing switched to ``model`` with the half wing (set_model),
        undeformed; the compiled step's state rebound to both wings' (one array)."""
        lat = self.lateral
        lat.model = model
        lat._x = np.zeros(2 * lat.n_modes)
        if self.compiled:
            x, n2 = self._x_full, 2 * self.n_modes
            x[:] = 0.0
            self.wing._x, lat._x = x[:n2], x[n2:]
            self._lat_views["model"][0] = K.MODEL_CODES[model]
            if model == "coupled" and lat._key is not None:
                self._renew_lateral(*lat._key)

    def _prepare_lateral(self, w_g_m_s: float) -> None:
        """The antisymmetric wing's reference for the flow now (:meth:`prepare`)."""
        flow = self._read(-w_g_m_s * U.FT_PER_M).flow
        self._renew_lateral(flow.dynamic_pressure_pa, flow.airspeed_m_s)

    # -- the compiled step -------------------------------------------------------------------
    def _setup_full_span_kernel(self) -> None:
        """One parameter array, state and column index for both wings (the layout of
        :mod:`bioflex_jsb.simulation.full_span_kernel`): the half wing's as _setup_kernel
        made them, the antisymmetric block after them; the half wing's views, state and
        reactions rebound onto them. On unsteady strips:
        :func:`~bioflex_jsb.runtime.unsteady_full_span_step.setup_kernel`."""
        if self.aero == "unsteady":
            from bioflex_jsb.runtime.unsteady_full_span_step import setup_kernel

            setup_kernel(self)
            return
        from bioflex_jsb.simulation import full_span_kernel as FK
        from bioflex_jsb.simulation.full_span import full_span_columns, joined_state

        lat, n_s = self.lateral, self.n_modes
        n_a = lat.n_modes
        s = lat.strips
        sym_size = self._params.size
        lay = FK.lateral_layout(n_a, n_s)
        block = FK.lateral_block_size(n_a, n_s)
        params = np.zeros(sym_size + block + FK.N_DIMS)
        params[:sym_size] = self._params
        self._params = params
        self._views = {name: params[o:o + size] for name, (o, size) in K.layout(n_s).items()}
        lv = {name: params[sym_size + o:sym_size + o + size] for name, (o, size) in lay.items()}
        lv["force_eta"][:] = np.ravel(s.force_eta)
        lv["force_p"][:] = s.force_p
        lv["force_delta"][:] = s.force_delta
        lv["stiffness"][:] = s.mass_kg_m2 * s.omega_rad_s**2
        lv["roll_eta"][:] = s.roll_eta
        lv["roll_etadot"][:] = s.roll_etadot
        lv["tip_anti"][:] = s.tip_twist_rad
        lv["tip_sym"][:] = lat.symmetric_tip_twist_rad
        lv["model"][0] = K.MODEL_CODES[lat.model]
        t = lat.terms
        lv["consts"][:] = (lat.refresh_rel, U.M_PER_FT, U.KG_M3_PER_SLUG_FT3,
                           U.LBF_FT_PER_N_M, ETA_LIMIT_RAD, U.LBF_PER_N, self._weight_n,
                           t.induced_per_lift)
        for name in ("force_r", "force_beta", "force_beta_s", "roll_r_s", "roll_beta_s",
                     "side_eta", "side_dihedral_eta", "side_dihedral_etadot", "yaw_etadot",
                     "yaw_p_s"):
            lv[name][:] = np.ravel(getattr(t, name))
        lv["static_s"][:] = self._static_eta_s
        lv["key"][:] = np.nan  # no reference yet: the first step asks for one
        self._lat_views = lv
        lay_s = K.layout(n_s)
        params[-FK.N_DIMS:] = (sym_size, self._cols.size, n_s, n_a, lay_s["out_flow"][0])
        self._reactions = lv["reactions"]  # lift, drag, pitch, roll, side, yaw (lbf, lbf·ft)
        self._out_flow = self._views["out_flow"]
        # views: the kernel updates x
        self._x_full, self.wing._x, lat._x = joined_state(self.wing._x, lat._x)
        self._cols = np.concatenate([self._cols, full_span_columns(self.names, n_a)])
        self._kernel = FK.full_span_kernel
        K.say_if_compiling(self._kernel, "full-span coupled step")
        if lat._key is not None:
            self._renew_lateral(*lat._key)

    def _bind_full_span_step(self, before_control=None):
        """The compiled full-span step as a closure (CoupledStep._bind_fast_step's, with the
        two aileron reads, the gust roll rate and the roll, side and yaw writes):
        ``fast(w_g_m_s, table, k, p_g_rad_s=0.0) -> stopped``; ``before_control`` as there
        (the sensor channels, written before the controller reads them)."""
        from bioflex_jsb.simulation.controller_kernel import linear_step
        from bioflex_jsb.simulation.full_span_kernel import EXTRA_READS

        params, cols, x = self._params, self._cols, self._x_full
        (g_u, g_v, g_w, g_q, g_p, g_r, g_theta, g_phi, g_psi, g_rho, g_nz, g_h, g_agl, g_lat,
         g_lon, g_vn, g_ve, g_vd, g_elevator, g_throttle) = self._getters
        g_left, g_right = self._get_left_aileron, self._get_right_aileron
        kernel, needs_refresh, ok = self._kernel, K.NEEDS_REFRESH, K.OK
        entry, accepts = K.direct_entry(kernel, params, x, cols,
                                        n_reads=len(K.READ_KEYS) + len(EXTRA_READS))
        checked, call = None, kernel
        set_wind, jsbsim_step, agl = self._set_wind, self.airframe.step_function(), self._agl_m
        set_lift, set_drag, set_pitch = self._set_reactions
        set_roll, set_side, set_yaw = self._set_roll, self._set_side, self._set_yaw
        reactions, out_flow = self._reactions, self._out_flow
        ft_per_m, alpha_range = U.FT_PER_M, self.alpha_range_rad
        labels = mode_labels(len(self.wing.eta), len(self.lateral.eta))
        control = self._control_step
        fast_control = self._control_fast
        if fast_control is not None:
            binding, set_command = fast_control
            c_params, c_entry = binding.params, binding.entry
        c_call = None
        # the snapshot's height above ground is the one read after the last JSBSim step (the
        # same state: the wind written before the snapshot does not move the aircraft), not
        # read again: no kernel uses it (one property read a step, 0.03-0.1 µs)
        agl_ft = agl()

        def fast(w_g_m_s: float, table: np.ndarray, k: int, p_g_rad_s: float = 0.0
                 ) -> str | None:
            nonlocal checked, call, c_call, agl_ft
            if table is not checked:
                checked, call = table, (entry if accepts(table) else kernel)
                if fast_control is not None:
                    c_call = c_entry if call is entry else linear_step
            wind_down_fps = -w_g_m_s * ft_per_m
            set_wind(wind_down_fps)
            reads = (g_u(), g_v(), g_w(), g_q(), g_p(), g_r(), g_theta(), g_phi(), g_psi(),
                     g_rho(), g_nz(), g_h(), agl_ft, g_lat(), g_lon(), g_vn(), g_ve(), g_vd(),
                     g_elevator(), g_throttle(), g_left(), g_right(), p_g_rad_s)
            status = call(reads, params, x, cols, table, k, wind_down_fps, w_g_m_s)
            if status == needs_refresh:
                self._renew_reference()
                status = call(reads, params, x, cols, table, k, wind_down_fps, w_g_m_s)
            lift_lbf, drag_lbf, pitch_lbf_ft, roll_lbf_ft, side_lbf, yaw_lbf_ft = (
                reactions.tolist())
            set_lift(lift_lbf)
            set_drag(drag_lbf)
            set_pitch(pitch_lbf_ft)
            set_roll(roll_lbf_ft)
            set_side(side_lbf)
            set_yaw(yaw_lbf_ft)
            if before_control is not None:
                before_control(table, k)
            if c_call is not None:
                set_command(c_call(table, k, c_params))
            elif control is not None:
                control(table, k)
            jsbsim_step()
            step_k = self.k
            self.k = step_k + 1
            agl_ft = agl()
            if status != ok or agl_ft <= 0.0:
                eta = np.concatenate([self.wing.eta, self.lateral.eta])
                self.stopped = out_of_range(self.names, table[k].tolist(), step_k * self.dt_s,
                                            out_flow[0], eta, agl_ft * U.M_PER_FT,
                                            alpha_range, labels)
                return self.stopped
            return None

        return fast

