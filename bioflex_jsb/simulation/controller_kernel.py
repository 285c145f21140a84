"""A linear controller's per-step update as one compiled call (numba).

:class:`bioflex_jsb.simulation.controller.ControlLoop` binds a
:class:`~bioflex_jsb.simulation.controller.LinearController` to a run's table
(:class:`LinearBinding`): every step the run calls the update with the table and the row k,
which at the controller's samples (every ``every`` steps) reads the signals of row k less
their trim values u, sets y = C x + D u and x ← A x + B u, and between them holds y; it
writes y into row k's command columns and returns the first command through its **output
map** (the others' into the parameter array), so that the runtime hands it to JSBSim
without a Python step of its own:

    value_i = offset_i + (angle_i + y_i) / (down_i if angle_i + y_i ≥ 0 else up_i)

(the identity by default: offset 0, angle 0, down = up = 1). The runtime sets the elevator's
map once at the JSBSim boundary: its angle-per-command slopes measured on the aircraft,
the trim's angle and command (:mod:`bioflex_jsb.runtime.control_surfaces`).

Why compiled: the update of a 10-state controller with 3 signals is 130 multiply-adds. In
Python each is an object allocation (33 µs a step measured for the reference
:meth:`~bioflex_jsb.simulation.controller.LinearController.step`, numpy's small products
~1 µs each); compiled they take ~0.1 µs and the call the rest, the overload's machine code
called directly (as the step kernel's, ``step_kernel.direct_entry``) with one parameter array
(each array argument costs its type check). ``bioflex-jsb bench`` prints the cost.

Parameter layout (floats; the column indices as floats, exact below 2**53):
``[n, m, l, every, count, A (n·n), B (n·m), C (l·n), D (l·m), offsets (m), in_cols (m),
out_cols (l), map (4·l: offset, angle, down, up), u (m), x (n), x_next (n), y (l),
value (l)]``.
"""

from __future__ import annotations

import numba
import numpy as np

from bioflex_jsb.state_space import StateSpace

HEADER = 5  # n, m, l, every, count
MAP = 4  # offset, angle, down, up per output


def _offsets(n: int, m: int, nl: int) -> dict[str, int]:
    """Where each block starts in the parameter array (module docstring)."""
    out, at = {}, HEADER
    for name, size in (("a", n * n), ("b", n * m), ("c", nl * n), ("d", nl * m),
                       ("offsets", m), ("in_cols", m), ("out_cols", nl), ("map", MAP * nl),
                       ("u", m), ("x", n), ("x_next", n), ("y", nl), ("value", nl)):
        out[name] = at
        at += size
    out["end"] = at
    return out


def pack(system: StateSpace, every: int, offsets, in_cols, out_cols) -> np.ndarray:
    """The parameter array of :func:`linear_step` for the discrete ``system`` sampled every
    ``every`` steps, the inputs' trim ``offsets``, their table columns ``in_cols`` and the
    commands' ``out_cols`` (module docstring); state and output start at 0, the output maps
    at the identity."""
    n, m, nl = system.n_states, len(system.inputs), len(system.outputs)
    if len(offsets) != m or len(in_cols) != m or len(out_cols) != nl:
        raise ValueError("offsets and in_cols need one entry per input, out_cols per output")
    at = _offsets(n, m, nl)
    p = np.zeros(at["end"])
    p[:HEADER] = (n, m, nl, int(every), 0)
    for key in "abcd":
        p[at[key]:at[key] + np.size(getattr(system, key))] = np.ravel(getattr(system, key))
    p[at["offsets"]:at["offsets"] + m] = offsets
    p[at["in_cols"]:at["in_cols"] + m] = in_cols
    p[at["out_cols"]:at["out_cols"] + nl] = out_cols
    p[at["map"]:at["map"] + MAP * nl] = np.tile([0.0, 0.0, 1.0, 1.0], nl)
    return p


@numba.njit(cache=True, nogil=True)
def linear_step(table, k, p):  # pragma: no cover - compiled; tested through LinearBinding
    """One step of the run (module docstring): the first command's mapped value."""
    n, m, nl = int(p[0]), int(p[1]), int(p[2])
    oa = HEADER
    ob = oa + n * n
    oc = ob + n * m
    od = oc + nl * n
    oo = od + nl * m
    oic = oo + m
    ooc = oic + m
    om = ooc + nl
    ou = om + 4 * nl
    ox = ou + m
    oxn = ox + n
    oy = oxn + n
    ov = oy + nl
    if p[4] == 0.0:  # a sample of the controller
        for j in range(m):
            p[ou + j] = table[k, int(p[oic + j])] - p[oo + j]
        for i in range(nl):
            s = 0.0
            for j in range(n):
                s += p[oc + i * n + j] * p[ox + j]
            for j in range(m):
                s += p[od + i * m + j] * p[ou + j]
            p[oy + i] = s
            angle = p[om + 4 * i + 1] + s
            slope = p[om + 4 * i + 2] if angle >= 0.0 else p[om + 4 * i + 3]
            p[ov + i] = p[om + 4 * i] + angle / slope
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += p[oa + i * n + j] * p[ox + j]
            for j in range(m):
                s += p[ob + i * m + j] * p[ou + j]
            p[oxn + i] = s
        for i in range(n):
            p[ox + i] = p[oxn + i]
    count = p[4] + 1.0
    p[4] = 0.0 if count >= p[3] else count
    for i in range(nl):
        table[k, int(p[ooc + i])] = p[oy + i]
    return p[ov]


TABLE_TYPE = numba.typeof(np.zeros((1, 1)))


class LinearBinding:
    """The compiled update of one controller in one run: ``params`` (:func:`pack`),
    ``entry`` the machine code of :func:`linear_step` for a C-ordered float64 table (call
    ``entry(table, k, params)``; :meth:`accepts` says whether a table is one, else call
    ``linear_step``), :meth:`step` ``(table, k)`` the commands y as a tuple (checked
    tables; the generic path), :meth:`set_map` an output's map."""

    def __init__(self, system: StateSpace, every: int, offsets, in_cols, out_cols) -> None:
        self.params = pack(system, every, offsets, in_cols, out_cols)
        n, m, nl = system.n_states, len(system.inputs), len(system.outputs)
        self._at = _offsets(n, m, nl)
        self.n_outputs = nl
        self.entry = linear_step.compile((TABLE_TYPE, numba.int64,
                                          numba.typeof(self.params)))
        self._last, self._call = None, linear_step

    @staticmethod
    def accepts(table) -> bool:
        return isinstance(table, np.ndarray) and numba.typeof(table) == TABLE_TYPE

    def set_map(self, i: int, offset: float, angle: float, down: float, up: float) -> None:
        """Output ``i``'s map (module docstring): value = offset + (angle + y)/(down or
        up by the sign of angle + y)."""
        if not (down > 0.0 and up > 0.0):
            raise ValueError("an output map's slopes are positive")
        at = self._at["map"] + MAP * i
        self.params[at:at + MAP] = (offset, angle, down, up)

    @property
    def state(self) -> np.ndarray:
        """The controller's state x (a view)."""
        n = int(self.params[0])
        return self.params[self._at["x"]:self._at["x"] + n]

    def outputs(self) -> tuple[float, ...]:
        """The commands y held now."""
        return tuple(self.params[self._at["y"]:self._at["y"] + self.n_outputs].tolist())

    def values(self) -> tuple[float, ...]:
        """The commands' mapped values held now."""
        return tuple(self.params[self._at["value"]:self._at["value"] + self.n_outputs]
                     .tolist())

    def step(self, table: np.ndarray, k: int) -> tuple[float, ...]:
        """One step (the generic path): the commands y."""
        if table is not self._last:
            self._last = table
            self._call = self.entry if self.accepts(table) else linear_step
        self._call(table, k, self.params)
        return self.outputs()


def compile_now() -> None:
    """Compile (or load from numba's cache) the update for the types a run passes."""
    system = StateSpace(model="c", speed_m_s=0.0, a=np.zeros((1, 1)), b=np.zeros((1, 1)),
                        c=np.zeros((1, 1)), d=np.zeros((1, 1)), states=("x",),
                        state_units=("-",), inputs=("q",), input_units=("rad/s",),
                        outputs=("elevator",), output_units=("rad",), dt_s=1.0)
    LinearBinding(system, 1, [0.0], [0], [1]).step(np.zeros((1, 2)), 0)
