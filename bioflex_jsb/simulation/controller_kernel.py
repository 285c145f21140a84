"""A linear controller's per-step update as one compiled call (numba).

:class:`bioflex_jsb.simulation.controller.ControlLoop` binds a
:class:`~bioflex_jsb.simulation.controller.LinearController` to a run's table with
:func:`bind_linear`: every step the run calls ``step(table, k)``, which at the controller's
samples (every ``every`` steps) reads the signals of row k less their trim values u, sets
y = C x + D u and x ← A x + B u, and between them holds y; it writes y into row k's command
columns and returns the first two outputs (0.0 for an absent second), so that the runtime
sets them in JSBSim without indexing an array.

Why compiled: the update of a 10-state controller with 3 signals is 130 multiply-adds. In
Python each is an object allocation (~6 µs a step); numpy's small products cost ~1 µs each,
two or three a step. Compiled they take ~0.1 µs and the call itself the rest: the
overload's machine code is called directly (as the step kernel's, ``step_kernel.
direct_entry``), with one parameter array holding everything (each array argument costs
its type check), 0.6 µs a step measured under load 5 on the 2-core machine
(``bioflex-jsb bench``: ``controller``).

Parameter layout (floats; the column indices as floats, exact below 2**53):
``[n, m, l, every, count, A (n·n), B (n·m), C (l·n), D (l·m), offsets (m), in_cols (m),
out_cols (l), u (m), x (n), x_next (n), y (l)]``.
"""

from __future__ import annotations

import numba
import numpy as np

from bioflex_jsb.state_space import StateSpace

HEADER = 5  # n, m, l, every, count


def pack(system: StateSpace, every: int, offsets, in_cols, out_cols) -> np.ndarray:
    """The parameter array of :func:`linear_step` for the discrete ``system`` sampled every
    ``every`` steps, the inputs' trim ``offsets``, their table columns ``in_cols`` and the
    commands' ``out_cols`` (module docstring); state and output start at 0."""
    n, m, nl = system.n_states, len(system.inputs), len(system.outputs)
    if len(offsets) != m or len(in_cols) != m or len(out_cols) != nl:
        raise ValueError("offsets and in_cols need one entry per input, out_cols per output")
    return np.concatenate([
        [n, m, nl, int(every), 0],
        np.ravel(system.a), np.ravel(system.b), np.ravel(system.c), np.ravel(system.d),
        np.asarray(offsets, dtype=float), np.asarray(in_cols, dtype=float),
        np.asarray(out_cols, dtype=float), np.zeros(m + 2 * n + nl)]).astype(float)


@numba.njit(cache=True, nogil=True)
def linear_step(table, k, p):  # pragma: no cover - compiled; tested through bind_linear
    """One step of the run (module docstring): returns (y[0], y[1] or 0.0)."""
    n, m, nl = int(p[0]), int(p[1]), int(p[2])
    oa = HEADER
    ob = oa + n * n
    oc = ob + n * m
    od = oc + nl * n
    oo = od + nl * m
    oic = oo + m
    ooc = oic + m
    ou = ooc + nl
    ox = ou + m
    oxn = ox + n
    oy = oxn + n
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
    return p[oy], (p[oy + 1] if nl > 1 else 0.0)


def state_of(p: np.ndarray) -> np.ndarray:
    """The controller's state x (a view into ``p``)."""
    n, m, nl = int(p[0]), int(p[1]), int(p[2])
    ox = HEADER + n * n + n * m + nl * n + nl * m + 3 * m + nl
    return p[ox:ox + n]


def bind_linear(system: StateSpace, every: int, offsets, in_cols, out_cols):
    """``step(table, k) -> (y0, y1)`` of the discrete ``system`` (:func:`pack`'s arguments):
    the compiled overload's machine code for a C-ordered float64 table, the dispatcher for
    any other (checked once per table, as the step kernel's entry)."""
    p = pack(system, every, offsets, in_cols, out_cols)
    table_type = numba.typeof(np.zeros((1, 1)))
    entry = linear_step.compile((table_type, numba.int64, numba.typeof(p)))
    last, call = None, linear_step

    def step(table: np.ndarray, k: int) -> tuple[float, float]:
        nonlocal last, call
        if table is not last:
            last, call = table, (entry if numba.typeof(table) == table_type else linear_step)
        return call(table, k, p)

    step.params = p  # the state and the held outputs, for tests and the benchmark
    return step


def compile_now() -> None:
    """Compile (or load from numba's cache) the update for the types a run passes."""
    system = StateSpace(model="c", speed_m_s=0.0, a=np.zeros((1, 1)), b=np.zeros((1, 1)),
                        c=np.zeros((1, 1)), d=np.zeros((1, 1)), states=("x",),
                        state_units=("-",), inputs=("q",), input_units=("rad/s",),
                        outputs=("elevator",), output_units=("rad",), dt_s=1.0)
    bind_linear(system, 1, [0.0], [0], [1])(np.zeros((1, 2)), 0)
