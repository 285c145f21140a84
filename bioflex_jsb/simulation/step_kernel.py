"""The coupled step's per-step numerics as one compiled function (numba).

:class:`bioflex_jsb.runtime.coupled_step.CoupledStep` runs either the readable Python step
(:class:`~bioflex_jsb.simulation.modal_wing.ModalWing`, the reference) or this kernel, which
does the same arithmetic in one call: the flow at the wing from the snapshot and the wind,
the exact modal step with its Fréchet correction (or the quasi-static deflection), the
loads and their rotation to body axes in JSBSim's units, the row of the step and the range
checks that need no JSBSim state after the step. Python keeps the gust, the property reads
and writes, JSBSim's step and the (rare) reference refreshes. ``tests/test_step_kernel.py``
holds both paths to 1e-9 of each channel's range on the golden cases.

A controller's flaperon (:mod:`bioflex_jsb.runtime.flaperon_step`) has a column of its own:
the kernel adds the deflection held over the step to the modes' forcing (Ψ_r b_δf Q δf, or
Q b_δf δf in the quasi-static balance) and logs it, and :func:`flaperon_loads`, called after
the controller, adds the new command's loads to the row and the reactions. Without a
flaperon the block is zero and the kernel's arithmetic is what it was
(``tests/test_flaperon.py`` holds the two steps to 1e-9 with one).

Why numba: the per-step work is ~40 scalar operations and three 6×6 products; in Python
each costs an object allocation (the measured profile: 6.5 µs for the wing step, 3.2 µs for
the loads, 2.9 µs for the row, 2.7 µs for the range check, against 7.7 µs for JSBSim's own
step). Compiled, they cost well under a microsecond; numba compiles from the same Python
source, caches the machine code on disk (``cache=True``: paid once per machine) and needs no
build step or compiler at install time.
"""

from __future__ import annotations

import glob
import math
import os
import pickle
import sys

import numba
import numpy as np

# Layout of the snapshot array the runtime fills (its property keys, in this order).
READ_KEYS = ("u", "v", "w", "q", "p", "r", "theta", "phi", "psi", "rho", "nz", "h", "agl",
             "lat", "lon", "vn", "ve", "vd", "elevator", "throttle")
# The kernel's output slots, by channel name (the runtime maps them to the table's columns
# by name: ``cols[slot]`` is the column of ``KERNEL_SLOTS[slot]``); η, η̇ follow.
KERNEL_SLOTS = ("u", "alpha", "q", "theta", "n_z", "w_g", "airspeed_m_s", "altitude_m",
                "lift_n", "drag_n", "pitch_moment_n_m", "latitude_rad", "longitude_rad",
                "phi_rad", "theta_rad", "psi_rad", "p_rad_s", "r_rad_s", "elevator_rad",
                "throttle", "alpha_rad", "beta_rad", "v_north_m_s", "v_east_m_s",
                "v_down_m_s")
MODEL_CODES = {"rigid": 0, "coupled": 1, "qsd": 2}
# Status codes of :func:`step_kernel`.
OK = 0
NEEDS_REFRESH = 1  # nothing was done: renew the reference at out_flow[2], out_flow[3]
NON_FINITE = 10
ALPHA_OUT = 11
ETA_OUT = 12

N_CONSTS = 10
# The flaperon block, the last of :func:`layout` (so that :func:`flaperon_loads` finds it at
# the end of the array), by entry: the deflection δf held over the step [rad]; the
# flaperon's S [m²], C_Lδf [1/rad], the induced-drag factor 2 k C_L0 of its lift [-], c̄
# [m], C_mδf [1/rad] (runtime/flaperon_step.py FlaperonLoads); the table column of
# ``flaperon_rad`` plus one (0: no flaperon, and the kernel steps as without one); the
# columns of ``lift_n``, ``drag_n``, ``pitch_moment_n_m``; the wing's own lift, drag [N] and
# moment [N·m] of the step and α [rad], Q [Pa] of its flow (written by the kernel); N→lbf,
# N·m→lbf·ft.
N_FLAP = 17
FLAP_HELD, FLAP_AREA, FLAP_CL, FLAP_K2, FLAP_CHORD, FLAP_CM, FLAP_COL = 0, 1, 2, 3, 4, 5, 6
FLAP_LOAD_COLS = 7  # lift_n, drag_n, pitch_moment_n_m: 7, 8, 9
FLAP_WING = 10  # the wing's lift, drag, moment: 10, 11, 12
FLAP_ALPHA, FLAP_Q, FLAP_LBF, FLAP_LBF_FT = 13, 14, 15, 16


def layout(n_modes: int) -> dict[str, tuple[int, int]]:
    """Where each block sits in the flat parameter array of :func:`step_kernel` for
    ``n_modes`` modes: name → (offset, length). One array instead of a dozen arguments,
    because the compiled function's call checks the type of every argument (about 0.1 µs
    each)."""
    n, n2 = n_modes, 2 * n_modes
    sizes = (("stack", 3 * n2 * n2), ("input_cols", n2 * 3), ("key", 2), ("trim", 4),
             ("k_aero", n * n), ("omega2", n), ("forcing", n * 3), ("load_eta", 3 * n),
             ("load_etadot", 3 * n), ("consts", N_CONSTS), ("refresh_rel", 1), ("model", 1),
             ("reactions", 3), ("out_flow", 4), ("stall_steps", 1), ("scratch", n2),
             ("static_load", 3), ("flap_cols", n2), ("flap_force", n), ("flap", N_FLAP))
    out, offset = {}, 0
    for name, size in sizes:
        out[name] = (offset, size)
        offset += size
    return out


# -- what both kernels (this one and the unsteady wing's) do alike -------------------------
@numba.njit(cache=True, nogil=True)
def air_flow(reads, wind_down_fps, m_per_ft, rho_si):
    """The flow at the wing from the snapshot ``reads`` (:data:`READ_KEYS`, JSBSim units)
    and the NED down wind ``wind_down_fps`` [ft/s]: (v_a [ft/s], V [ft/s], V [m/s], α [rad],
    Q [Pa]), the air-relative body velocity being the body velocity less the wind seen in
    body axes (FGAuxiliary's); ``m_per_ft``, ``rho_si`` [kg/m³ per slug/ft³] convert."""
    u, v, w = reads[0], reads[1], reads[2]
    theta, phi = reads[6], reads[7]
    ua = u + wind_down_fps * math.sin(theta)
    va = v - wind_down_fps * math.sin(phi) * math.cos(theta)
    wa = w - wind_down_fps * math.cos(phi) * math.cos(theta)
    vt_fps = math.sqrt(ua * ua + va * va + wa * wa)
    vt = vt_fps * m_per_ft
    alpha = math.atan2(wa, ua)
    qbar = 0.5 * reads[9] * rho_si * vt * vt
    return va, vt_fps, vt, alpha, qbar


@numba.njit(cache=True, nogil=True)
def finish_row(row, cols, reads, trim, consts, x, n, va, vt_fps, vt, alpha, w_g, lift, drag,
               moment):
    """Write the row of t_k by slot (:data:`KERNEL_SLOTS`, ``row[cols[slot]]``) and check
    the step: NON_FINITE (any of the row's channels), ALPHA_OUT (α outside [consts[7],
    consts[8]] rad), ETA_OUT (any of the ``n`` modal coordinates x[:n] beyond consts[6]
    [rad]) or OK. ``trim``: α_0, θ_0, Q_0, V_0; lift, drag [N, against the air], moment
    [N·m, nose up]; the flow from :func:`air_flow`; w_g the gust [m/s, up]."""
    m_per_ft = consts[0]
    theta, phi = reads[6], reads[7]
    vals = (vt - trim[3], alpha - trim[0], reads[3], theta - trim[1], reads[10], w_g, vt,
            reads[11] * m_per_ft, lift, drag, moment, reads[13], reads[14], phi, theta,
            reads[8], reads[4], reads[5], reads[18], reads[19], alpha,
            math.asin(va / vt_fps) if vt_fps > 0.0 else 0.0,
            reads[15] * m_per_ft, reads[16] * m_per_ft, reads[17] * m_per_ft)
    for s in range(len(vals)):
        row[cols[s]] = vals[s]
    for c in range(len(cols)):
        if not math.isfinite(row[cols[c]]):
            return NON_FINITE
    if not consts[7] <= alpha <= consts[8]:
        return ALPHA_OUT
    for i in range(n):
        if abs(x[i]) > consts[6]:
            return ETA_OUT
    return OK



@numba.njit(cache=True, nogil=True)
def step_kernel(reads, params, x, cols, table, k, wind_down_fps, w_g):
    """One step of the wing (module docstring), writing row ``k`` of ``table``.

    reads: the snapshot in :data:`READ_KEYS` order (a tuple; JSBSim units); params: the flat array
    of :func:`layout` — stack, input_cols, key: the reference step
    (:meth:`ModalWing._compute_reference`) and its (Q_r [Pa], V_r [m/s]); trim: α_0 [rad],
    θ_0 [rad], Q_0 [Pa], V_0 [m/s]; k_aero, omega2, forcing: the QSD terms; load_eta,
    load_etadot: (3, n) loads per unit Q S; consts: ft→m, slug/ft³→kg/m³, S [m²], c̄ [m],
    N→lbf, N·m→lbf·ft, η limit [rad], α min, α max, α peak [rad]; refresh_rel; model
    (:data:`MODEL_CODES`); out: reactions (body axes, written to JSBSim [lbf, lbf, lbf·ft])
    and out_flow (α [rad], q [rad/s], Q [Pa], V [m/s]), the count of steps beyond the lift
    peak, a scratch block; static_load; flap_cols, flap_force, flap: the flaperon's step
    column, its forcing and its block (:data:`N_FLAP`; zero: no flaperon); x: [Δη, Δη̇]
    (updated in place to η_{k+1}); cols: the table column of each slot; wind_down_fps: the
    NED down wind written for this step [ft/s]; w_g: the gust [m/s, up]. Returns a status
    code."""
    n2 = x.shape[0]
    n = n2 // 2
    # offsets of the blocks (layout()); blocks are read by flat index, with no array views
    o_stack = 0
    o_in = o_stack + 3 * n2 * n2
    o_key = o_in + n2 * 3
    o_trim = o_key + 2
    o_ka = o_trim + 4
    o_w2 = o_ka + n * n
    o_fc = o_w2 + n
    o_le = o_fc + n * 3
    o_ld = o_le + 3 * n
    o_c = o_ld + 3 * n
    o_rr = o_c + N_CONSTS
    o_out = o_rr + 2
    o_scratch = o_out + 8
    o_sl = o_scratch + n2  # the static deflection's loads per unit Q S (elastic trim; or 0)
    o_fc2 = o_sl + 3  # the flaperon's step column Ψ_r b_δf (coupled)
    o_ff = o_fc2 + n2  # its forcing b_δf, η̈ per unit Q δf (qsd)
    o_fl = o_ff + n  # the flaperon block (N_FLAP)
    flap_col = int(params[o_fl + FLAP_COL]) - 1  # -1: no flaperon
    consts = params[o_c:o_c + N_CONSTS]
    refresh_rel = params[o_rr]
    model = int(params[o_rr + 1])
    key0, key1 = params[o_key], params[o_key + 1]
    trim = params[o_trim:o_trim + 4]
    row = table[k]
    s_ref, cbar = consts[2], consts[3]
    q = reads[3]
    va, vt_fps, vt, alpha, qbar = air_flow(reads, wind_down_fps, consts[0], consts[1])
    params[o_out + 3], params[o_out + 4] = alpha, q
    params[o_out + 5], params[o_out + 6] = qbar, vt
    # (written as "not within" so that the NaN key of a wing with no reference yet refreshes)
    if model == 1 and not (abs(qbar - key0) <= refresh_rel * abs(key0)
                           and abs(vt - key1) <= refresh_rel * abs(key1)):
        return NEEDS_REFRESH
    # the row's modal state: η_k, η̇_k (before the step)
    base = len(cols) - 2 * n
    for i in range(n2):
        row[cols[base + i]] = x[i]
    if flap_col >= 0:  # the deflection whose loads act over this step, δf_{k-1}
        row[flap_col] = params[o_fl + FLAP_HELD]
    f0 = qbar * (alpha - trim[0])
    f1 = qbar / vt * q
    f2 = qbar - trim[2]
    lift = drag = moment = 0.0
    if model == 1:
        dq, dqv = qbar - key0, qbar / vt - key0 / key1
        s1, s2 = n2 * n2, 2 * n2 * n2  # the ∂Φ/∂Q and ∂Φ/∂(Q/V) blocks of the stack
        for i in range(n2):
            acc = 0.0
            r = o_stack + i * n2
            for j in range(n2):
                acc += (params[r + j] + dq * params[r + s1 + j] + dqv * params[r + s2 + j]) * x[j]
            c = o_in + 3 * i
            params[o_scratch + i] = (acc + params[c] * f0 + params[c + 1] * f1
                                     + params[c + 2] * f2)
        if flap_col >= 0:  # the flaperon held over the step: + Ψ_r b_δf Q δf
            qf = qbar * params[o_fl + FLAP_HELD]
            for i in range(n2):
                x[i] = params[o_scratch + i] + params[o_fc2 + i] * qf
        else:
            for i in range(n2):
                x[i] = params[o_scratch + i]
    elif model == 2:
        kq = np.empty((n, n))
        rhs = np.empty(n)
        for i in range(n):
            for j in range(n):
                kq[i, j] = -qbar * params[o_ka + n * i + j]
            kq[i, i] += params[o_w2 + i]
            c = o_fc + 3 * i
            rhs[i] = params[c] * f0 + params[c + 1] * f1 + params[c + 2] * f2
            if flap_col >= 0:
                rhs[i] += qbar * params[o_fl + FLAP_HELD] * params[o_ff + i]
        eta_qs = np.linalg.solve(kq, rhs)
        for i in range(n):
            x[i] = eta_qs[i]
            x[n + i] = 0.0
    if model != 0:
        rate = cbar / (2.0 * vt)
        l0, l1, l2 = params[o_sl], params[o_sl + 1], params[o_sl + 2]
        for i in range(n):
            e, ed = x[i], rate * x[n + i]
            l0 += params[o_le + i] * e + params[o_ld + i] * ed
            l1 += params[o_le + n + i] * e + params[o_ld + n + i] * ed
            l2 += params[o_le + 2 * n + i] * e + params[o_ld + 2 * n + i] * ed
        qs = qbar * s_ref
        lift, drag, moment = qs * l0, qs * l1, qs * l2
    if flap_col >= 0:  # for flaperon_loads, after the controller
        params[o_fl + FLAP_WING] = lift
        params[o_fl + FLAP_WING + 1] = drag
        params[o_fl + FLAP_WING + 2] = moment
        params[o_fl + FLAP_ALPHA] = alpha
        params[o_fl + FLAP_Q] = qbar
    ca, sa = math.cos(alpha), math.sin(alpha)
    params[o_out] = (lift * ca + drag * sa) * consts[4]
    params[o_out + 1] = (drag * ca - lift * sa) * consts[4]
    params[o_out + 2] = moment * consts[5]
    if alpha > consts[9]:
        params[o_out + 7] += 1.0  # steps beyond the lift peak
    return finish_row(row, cols, reads, trim, consts, x, n, va, vt_fps, vt, alpha, w_g,
                      lift, drag, moment)


@numba.njit(cache=True, nogil=True)
def flaperon_loads(params, table, k, delta_rad):
    """After the controller of step k: the flaperon's command ``delta_rad`` δf_k [rad,
    clipped] adds its lift ΔL = Q S C_Lδf δf_k, induced drag 2 k C_L0 ΔL and moment
    Q S c̄ C_mδf δf_k to the wing's loads of the step in row ``k`` (``lift_n``, ``drag_n``,
    ``pitch_moment_n_m``) and is held for the wing's next step; returns the reactions to
    write before JSBSim's step (lbf, lbf, lbf·ft; the kernel's ``reactions``, the flaperon's
    included). ``params``: the kernel's array (the flaperon block at its end, filled by the
    kernel's step k). The arithmetic of runtime/flaperon_step.py ``apply_flaperon``."""
    o = params.shape[0] - N_FLAP
    q = params[o + FLAP_Q]
    d_lift = q * params[o + FLAP_AREA] * params[o + FLAP_CL] * delta_rad
    d_drag = params[o + FLAP_K2] * d_lift
    d_moment = (q * params[o + FLAP_AREA] * params[o + FLAP_CHORD] * params[o + FLAP_CM]
                * delta_rad)
    lift = params[o + FLAP_WING] + d_lift
    drag = params[o + FLAP_WING + 1] + d_drag
    moment = params[o + FLAP_WING + 2] + d_moment
    row = table[k]
    row[int(params[o + FLAP_LOAD_COLS])] = lift
    row[int(params[o + FLAP_LOAD_COLS + 1])] = drag
    row[int(params[o + FLAP_LOAD_COLS + 2])] = moment
    params[o + FLAP_HELD] = delta_rad
    alpha = params[o + FLAP_ALPHA]
    ca, sa = math.cos(alpha), math.sin(alpha)
    lbf = params[o + FLAP_LBF]
    return ((lift * ca + drag * sa) * lbf, (drag * ca - lift * sa) * lbf,
            moment * params[o + FLAP_LBF_FT])


# ---------------------------------------------------------------------------------------
# A damaged cache heals itself. numba keeps a kernel's machine code in two pickles in its
# cache directory (``<module>.<function>-<line>.pyXY.nbi``, the index, and ``….N.nbc``, the
# code); a truncated, empty or overwritten file makes every run fail in numba's loader
# (UnpicklingError, EOFError, MemoryError, ...) until it is deleted by hand. The guard wraps
# the kernel's cache loader: a file that cannot be read is discarded (this kernel's files
# only), one line says so on stderr, and numba compiles the kernel and caches it anew. A
# cache that cannot be written (a full disk: numba's save raised ENOSPC and the run ended
# with status 4 naming no path) is skipped: the compiled code runs, one line on stderr says
# where the cache is and why, once per process.
# ---------------------------------------------------------------------------------------
# What unpickling damaged bytes raises (pickle's own error, a stream cut short, a length or
# an opcode argument out of range, an object built from nonsense): reading a file, nothing
# else, happens inside the guarded call.
DAMAGED_CACHE_ERRORS = (pickle.UnpicklingError, EOFError, ValueError, TypeError,
                        AttributeError, ImportError, LookupError, MemoryError, OverflowError)


def guard_cache(dispatcher) -> None:
    """Make ``dispatcher`` (an ``@numba.njit(cache=True)`` function) discard and rebuild a
    damaged on-disk cache instead of failing, and run uncached when its cache cannot be
    written: see the section's comment."""
    cache = dispatcher._cache
    load, save = cache.load_overload, cache.save_overload

    def load_overload(sig, target_context):
        try:
            return load(sig, target_context)
        except DAMAGED_CACHE_ERRORS as exc:
            _discard_cache(dispatcher, cache, exc)
            return None  # numba compiles, then saves a fresh index and code

    def save_overload(sig, data):
        try:
            save(sig, data)
        except OSError as exc:  # a full disk, a read-only or vanished cache directory
            _unwritable_cache(cache, exc)  # the compiled code is used all the same

    cache.load_overload = load_overload
    cache.save_overload = save_overload


UNWRITABLE_CACHE_SAID: list[str] = []  # the cache said to be unwritable (once a process)


def _unwritable_cache(cache, exc: OSError) -> None:
    """One line on stderr, once per process: the cache cannot be written, the run goes on
    with the code compiled in memory, and where the cache is (NUMBA_CACHE_DIR when set,
    else the kernel's own folder)."""
    if UNWRITABLE_CACHE_SAID:
        return
    where = numba.config.CACHE_DIR or cache._cache_file._cache_path
    UNWRITABLE_CACHE_SAID.append(where)
    why = exc.strerror or type(exc).__name__
    sys.stderr.write(f"bioflex-jsb: numba's cache in {where} cannot be written ({why}); "
                     "running uncached (each run compiles its kernels again, 20-35 s) until "
                     "there is room there, or NUMBA_CACHE_DIR names a writable folder\n")


COMPILING_SAID: list[str] = []  # the kernels said to be compiling (once a process each)


def say_if_compiling(dispatcher, what: str) -> None:
    """One line on a terminal's stderr, once a process, when ``dispatcher``'s machine code is
    neither in memory nor in numba's cache on disk (a new installation, a cleared cache): the
    first run then spends 10-40 s compiling ``what``, and says so and where it will be
    cached. Not on a pipe or a file (a script's or a test's stderr holds its errors only)."""
    if (what in COMPILING_SAID or not sys.stderr.isatty() or dispatcher.overloads
            or cache_files(dispatcher)):
        return
    COMPILING_SAID.append(what)
    where = numba.config.CACHE_DIR or dispatcher._cache._cache_file._cache_path
    sys.stderr.write(f"bioflex-jsb: compiling the {what} for this machine (once per "
                     f"installation, 10-40 s; cached in {where})\n")


def cache_files(dispatcher) -> list[str]:
    """The on-disk cache files of ``dispatcher`` (its index and code files) that exist."""
    files = dispatcher._cache._cache_file
    pattern = files._data_name_pattern.replace("{number:d}", "*")
    found = glob.glob(os.path.join(glob.escape(files._cache_path), pattern))
    return sorted([files._index_path] * os.path.exists(files._index_path) + found)


def _discard_cache(dispatcher, cache, exc: BaseException) -> None:
    names = cache_files(dispatcher)
    for name in names:
        try:
            os.unlink(name)
        except FileNotFoundError:  # another process discarded it first
            pass
    why = " ".join(f"{type(exc).__name__}: {exc}".split())[:160]
    where = os.path.dirname(names[0]) if names else cache._cache_file._cache_path
    sys.stderr.write(f"bioflex-jsb: numba's cache of the compiled {dispatcher.__name__} in "
                     f"{where} was damaged ({why}); discarded it, compiling anew\n")


guard_cache(air_flow)  # the helpers are loaded from their own caches with the kernels
guard_cache(finish_row)
guard_cache(step_kernel)
guard_cache(flaperon_loads)


# -- the kernel called without numba's dispatcher ------------------------------------------
# A call through the dispatcher types every argument first (the 20-tuple element by element,
# the four arrays, the scalars) to pick the compiled overload: 0.67 µs of a 10.1 µs
# co-simulation step (least of 60 interleaved blocks of 200 steps, 2-core KVM machine,
# load 2.2; kernel alone 1.10 µs, 0.77 µs direct). The overload's entry point, found once for the
# run's types, skips that; it converts what it is given to those types without checking
# them (a table of another layout is written in the wrong places, tested), so a caller
# checks each new table once with the ``accepts`` it comes with.
def direct_entry(dispatcher, params: np.ndarray, x: np.ndarray, cols: np.ndarray,
                 n_reads: int = len(READ_KEYS)):
    """``(entry, accepts)`` for ``dispatcher`` (:func:`step_kernel` or the unsteady wing's
    kernel, whose arguments are the same): ``entry(reads, params, x, cols, table, k,
    wind_down_fps, w_g)`` is its machine code for a snapshot of :data:`READ_KEYS` floats,
    these ``params``, ``x``, ``cols`` (checked here), a C-ordered float64 table, an int row
    and float winds (compiled or loaded from numba's cache once; ``n_reads`` floats in the
    snapshot, the full-span kernel's more); ``accepts(table)``: whether
    ``table`` has exactly that table type (numba's own typing), else call ``dispatcher``."""
    types = tuple(numba.typeof(a) for a in (params, x, cols))
    want = (numba.typeof(np.zeros(1)), numba.typeof(np.zeros(1)),
            numba.typeof(np.zeros(1, dtype=np.int64)))
    if types != want:
        raise TypeError(f"the kernel's arrays must be {want}, got {types}")
    table_type = numba.typeof(np.zeros((1, 1)))
    reads_type = numba.typeof((0.0,) * n_reads)
    entry = dispatcher.compile((reads_type, *types, table_type, numba.int64, numba.float64,
                                numba.float64))

    def accepts(table) -> bool:
        return isinstance(table, np.ndarray) and numba.typeof(table) == table_type

    return entry, accepts


def flaperon_entry(params: np.ndarray):
    """``(entry, accepts)`` for :func:`flaperon_loads` as :func:`direct_entry` gives them
    for the step kernel: ``entry(params, table, k, delta_rad)`` its machine code for these
    ``params`` (checked here), a C-ordered float64 table, an int row and a float command;
    ``accepts(table)``: whether ``table`` is of that type, else call :func:`flaperon_loads`."""
    params_type = numba.typeof(params)
    if params_type != numba.typeof(np.zeros(1)):
        raise TypeError(f"the flaperon's parameters must be {numba.typeof(np.zeros(1))}, "
                        f"got {params_type}")
    table_type = numba.typeof(np.zeros((1, 1)))
    entry = flaperon_loads.compile((params_type, table_type, numba.int64, numba.float64))

    def accepts(table) -> bool:
        return isinstance(table, np.ndarray) and numba.typeof(table) == table_type

    return entry, accepts


def compile_now(n_modes: int = 3) -> None:
    """Compile (or load from numba's cache) the kernel for the types a run passes: the
    snapshot as a 20-tuple of floats, float64 arrays, an int64 column index. For timing
    the cold compile (``bioflex-jsb bench``) and warming a real-time loop."""
    n2 = 2 * n_modes
    size = sum(s for _, s in layout(n_modes).values())
    params = np.zeros(size)
    lay = layout(n_modes)
    o, _ = lay["key"]
    params[o:o + 2] = 1.0
    o, _ = lay["trim"]
    params[o + 3] = 1.0
    o, size = lay["consts"]
    params[o:o + size] = 1.0  # any finite flow will do
    cols = np.arange(len(KERNEL_SLOTS) + n2, dtype=np.int64)
    table = np.zeros((1, len(cols)))
    reads = (1.0,) * len(READ_KEYS)
    step_kernel(reads, params, np.zeros(n2), cols, table, 0, 0.0, 0.0)
