"""The one state-space type of the package.

Every linear model is a :class:`StateSpace` or converts to one through its
``to_state_space()``: the paper's LTI model of the free aircraft
(:func:`bioflex_jsb.flight_dynamics.lti.build_state_space` and the unsteady and trimmed
variants return it), one strip's finite-state aerodynamics
(:class:`bioflex_jsb.aerodynamics.indicial.StripStateSpace`), the wing's finite-state
generalised forces (:class:`bioflex_jsb.aeroelasticity.strip_aero.ModalAeroStateSpace`) and
the clamped wing's aeroelastic system
(:class:`bioflex_jsb.aeroelasticity.state_space.AeroelasticSystem`).

    continuous (``dt_s is None``):   ẋ = A x + B u,             y = C x + D u
    discrete (``dt_s`` > 0 [s]):     x[k+1] = A x[k] + B u[k],  y[k] = C x[k] + D u[k]

Every state, input and output has a name and a unit (SI; the unit strings beside the names);
frames and signs are those of the model that built it (its docstring says them).
:meth:`StateSpace.to_control` gives python-control's ``StateSpace`` with the names carried
over (the optional ``control`` extra, imported only there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from bioflex_jsb.errors import InputError

CONTROL_MISSING = ("python-control is not installed (StateSpace.to_control needs it): "
                   "pip install 'bioflex-jsb[control]'")


@dataclass(frozen=True)
class StateSpace:
    """A linear time-invariant model with named signals and units (module docstring).

    ``model`` names what it is (``rigid``, ``coupled``, ``qsd``, ``coupled-unsteady``,
    ``strip``, ``modal-aero``, ``clamped-aeroelastic``); ``speed_m_s`` [m/s] the airspeed it
    was built at; ``a`` (n, n), ``b`` (n, m), ``c`` (p, n), ``d`` (p, m) in the units of the
    signals (A [1/s] for a continuous model); ``states``/``state_units`` (n),
    ``inputs``/``input_units`` (m), ``outputs``/``output_units`` (p); ``notes`` what it was
    built from; ``dt_s`` [s] the sample time of a discrete model, ``None`` for continuous.
    Inconsistent shapes or names are the builder's bug (ValueError).
    """

    model: str
    speed_m_s: float
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    states: tuple[str, ...]
    state_units: tuple[str, ...]
    inputs: tuple[str, ...]
    input_units: tuple[str, ...]
    outputs: tuple[str, ...]
    output_units: tuple[str, ...]
    notes: dict[str, object] = field(default_factory=dict)
    dt_s: float | None = None

    def __post_init__(self) -> None:
        n, m, p = len(self.states), len(self.inputs), len(self.outputs)
        shapes = {"a": (n, n), "b": (n, m), "c": (p, n), "d": (p, m)}
        for key, shape in shapes.items():
            got = np.shape(getattr(self, key))
            if got != shape:
                raise ValueError(f"StateSpace {self.model!r}: {key} is {got}, expected {shape} "
                                 f"for {n} states, {m} inputs, {p} outputs")
        for names, units in ((self.states, self.state_units), (self.inputs, self.input_units),
                             (self.outputs, self.output_units)):
            if len(units) != len(names) or len(set(names)) != len(names):
                raise ValueError(f"StateSpace {self.model!r}: names {names} need distinct "
                                 f"names and one unit each (units {units})")
        if self.dt_s is not None and not (math.isfinite(self.dt_s) and self.dt_s > 0.0):
            raise ValueError(f"StateSpace {self.model!r}: dt_s must be None (continuous) or "
                             f"a sample time > 0 s, got {self.dt_s!r}")

    @property
    def n_states(self) -> int:
        return int(self.a.shape[0])

    @property
    def continuous(self) -> bool:
        return self.dt_s is None

    def eigenvalues(self) -> np.ndarray:
        """The poles: eigenvalues of A ([rad/s] continuous; z-plane, [-], discrete)."""
        return np.linalg.eigvals(self.a)

    def frequency_response(self, frequency_rad_s) -> np.ndarray:
        """Complex G(iω) = C (sI − A)⁻¹ B + D, (len(ω), outputs, inputs), at ω [rad/s]
        (s = iω; discrete: z = exp(iω dt_s))."""
        w = np.atleast_1d(np.asarray(frequency_rad_s, dtype=float))
        s = 1j * w if self.continuous else np.exp(1j * w * self.dt_s)
        out = np.empty((w.size, len(self.outputs), len(self.inputs)), dtype=complex)
        eye = np.eye(self.n_states)
        for k, sk in enumerate(s):
            g = np.asarray(self.d, dtype=complex)
            if self.n_states:
                g = g + self.c @ np.linalg.solve(sk * eye - self.a, self.b)
            out[k] = g
        return out

    def to_discrete(self, dt_s: float) -> StateSpace:
        """The zero-order-hold discrete model at sample time ``dt_s`` [s] (input held over
        each step): [A_d B_d; 0 I] = expm([A B; 0 0] dt_s); C and D unchanged."""
        from scipy.linalg import expm

        if not self.continuous:
            raise ValueError(f"StateSpace {self.model!r} is already discrete (dt_s "
                             f"{self.dt_s} s)")
        n, m = self.n_states, len(self.inputs)
        block = np.zeros((n + m, n + m))
        block[:n, :n], block[:n, n:] = self.a, self.b
        e = expm(block * float(dt_s))
        return StateSpace(model=self.model, speed_m_s=self.speed_m_s, a=e[:n, :n],
                          b=e[:n, n:], c=self.c, d=self.d, states=self.states,
                          state_units=self.state_units, inputs=self.inputs,
                          input_units=self.input_units, outputs=self.outputs,
                          output_units=self.output_units,
                          notes={**self.notes, "discretised": "zero-order hold"},
                          dt_s=float(dt_s))

    def to_control(self):
        """This model as a python-control ``StateSpace`` (``control.ss``): the same matrices,
        the state, input and output names carried over, ``dt`` 0 (continuous) or ``dt_s``;
        the system is named ``bioflex_<model>``. Needs the ``control`` extra (one-line
        :class:`~bioflex_jsb.errors.InputError` without it)."""
        try:
            import control
        except ImportError:
            raise InputError(CONTROL_MISSING) from None
        return control.ss(self.a, self.b, self.c, self.d,
                          0 if self.dt_s is None else self.dt_s,
                          states=list(self.states), inputs=list(self.inputs),
                          outputs=list(self.outputs), name=f"bioflex_{self.model}")


def with_motion_inputs(model: str, speed_m_s: float, lag, coordinates: tuple[str, ...],
                       coordinate_units: tuple[str, ...], outputs: tuple[str, ...],
                       output_units: tuple[str, ...]) -> StateSpace:
    """A finite-state aerodynamic model written on the motion it is driven by,

        ẋ = A x + B_q q + B_qd q̇ + B_g w_g,   f = C x + D_q q + D_qd q̇ − M_a q̈ + D_g w_g,

    (``lag``: its attributes ``a, b_q, b_qd, b_g, c, d_q, d_qd, d_g, apparent_mass,
    state_names, state_units``) as a :class:`StateSpace` whose inputs are
    u = (q, q̇, q̈, w_g): B = [B_q B_qd 0 B_g], D = [D_q D_qd −M_a D_g]. ``coordinates``
    name q (their rates are ``<name>_dot`` and ``<name>_ddot`` in ``<unit>/s`` and
    ``<unit>/s^2``); w_g [m/s] is the gust velocity, positive up. Its G(iω) on
    (q̄, iω q̄, −ω² q̄) is the model's own force matrix."""
    n_q, n_x = len(coordinates), int(lag.a.shape[0])
    b = np.concatenate([np.reshape(lag.b_q, (n_x, n_q)), np.reshape(lag.b_qd, (n_x, n_q)),
                        np.zeros((n_x, n_q)), np.reshape(lag.b_g, (n_x, 1))], axis=1)
    d = np.concatenate([lag.d_q, lag.d_qd, -lag.apparent_mass,
                        np.reshape(lag.d_g, (len(outputs), 1))], axis=1)
    inputs = (coordinates + tuple(f"{q}_dot" for q in coordinates)
              + tuple(f"{q}_ddot" for q in coordinates) + ("w_g",))
    units = (coordinate_units + tuple(f"{u}/s" for u in coordinate_units)
             + tuple(f"{u}/s^2" for u in coordinate_units) + ("m/s",))
    return StateSpace(model=model, speed_m_s=float(speed_m_s), a=lag.a, b=b,
                      c=np.reshape(lag.c, (len(outputs), n_x)), d=d,
                      states=tuple(lag.state_names), state_units=tuple(lag.state_units),
                      inputs=inputs, input_units=units, outputs=outputs,
                      output_units=output_units)
