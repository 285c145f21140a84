"""What one compiled coupled step costs, piece by piece: JSBSim's step, the property reads,
the kernel, the property writes, the driver around the step.

    PYTHONPATH=. python scripts/step_pieces.py [--span full|half|both] [--steps N]
                                               [--repeat R] [--speed V] [--json]

On the trimmed airframe of ``bioflex-jsb bench`` (the optimised prototype, 1/960 s, the
coupled wing, quasi-steady strips) each piece is timed alone in loops of ``--steps`` calls,
the pieces interleaved, ``--repeat`` times; each figure is the least time per call over the
repeats (noise on a shared machine only adds time; ``docs/performance.md``, "The
estimator"), on the process's CPU clock, with the median beside it:

* ``bare``: JSBSim's own step, nothing else (the bench's denominator);
* ``step``: the whole compiled step as a run calls it (``CoupledStep.stepper()``, calm
  air; ``bench``'s runs add the driver's loop around it, the gust and the history);
* ``reads``: the snapshot's property reads as the step calls them (20, or 22 for both
  halves) into one tuple;
* ``agl``: the one height read after JSBSim's step (the range check's);
* ``kernel``: the kernel's machine code on a fixed snapshot (the step's own arrays);
* ``writes``: the wind and the reactions (3, or 6 for both halves) written, from one
  ``tolist()``;
* ``jsbsim_in_step``: what is left of ``step`` after the pieces, the Python around them
  and JSBSim's own step run between them (its caches shared with ours).

Ratios are to ``bare``. Pieces run alone are cheaper than inside a step (their code and
data stay in the caches between calls); the remainder says how much.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time

import numpy as np

from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.runtime.coupled_step import CoupledStep, configure_airframe
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation import step_kernel as K
from bioflex_jsb.simulation.full_span import prototype_aileron
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S

PIECES = ("bare", "step", "reads", "agl", "kernel", "writes")


def _timed(fn, n: int) -> float:
    """CPU seconds per call of ``fn(n)`` (which makes ``n`` calls)."""
    c0 = time.process_time()
    fn(n)
    return (time.process_time() - c0) / n


def pieces(build, span: str, speed_m_s: float, max_steps: int):
    """name → ``run(n)`` of the pieces (module docstring) on one trimmed airframe."""
    airframe = Airframe()
    configure_airframe(airframe, DEFAULT_DT_S)
    trim = airframe.trim(speed_m_s)
    full = {} if span == "half" else {"span": "full",
                                      "aileron": prototype_aileron(build.variant.name)}
    wing = build if span == "full" else build.model
    step = CoupledStep(airframe, wing, "coupled", speed_m_s, trim=trim, **full)
    names = step.names
    table = np.zeros((8, len(names)))
    fly = step.stepper()
    with airframe.capturing():
        for k in range(8):  # the first reference step and the kernel's load, untimed
            fly(0.0, table, k)
    getters = list(step._getters)
    if span == "full":
        getters += [step._get_left_aileron, step._get_right_aileron]
    getters = tuple(getters)
    agl = step._agl_m
    params, cols, x = step._params, step._cols, (step._x_full if span == "full"
                                                 else step.wing._x)
    n_reads = len(getters) + (1 if span == "full" else 0)
    entry, _ = K.direct_entry(step._kernel, params, x, cols, n_reads=n_reads)
    snapshot = tuple(g() for g in getters) + ((0.0,) if span == "full" else ())
    setters = tuple(step._set_reactions) + ((step._set_roll, step._set_side, step._set_yaw)
                                            if span == "full" else ())
    set_wind, reactions = step._set_wind, step._reactions
    jsbsim_step = airframe.step_function()

    def bare(n: int) -> float:
        airframe.trim(speed_m_s)

        def loop(m: int) -> None:
            for _ in range(m):
                jsbsim_step()

        with airframe.capturing():
            return _timed(loop, n)

    big = np.zeros((2 * max_steps + 8, len(names)))

    def stepped(n: int) -> float:
        """The step as a run calls it, on rows 8.. of a reused table (the flight goes on
        from timing to timing, trimmed and calm: the same step)."""
        def loop(m: int) -> None:
            for k in range(8, 8 + m):
                fly(0.0, big, k)

        with airframe.capturing():
            return _timed(loop, n)

    # the step calls the readers from locals into one tuple literal: time that form
    names_ = [f"g{i}" for i in range(len(getters))]
    src = (f"def r({', '.join(names_)}, m):\n    for _ in range(m):\n"
           f"        ({', '.join(f'{g}()' for g in names_)},)\n")
    ns: dict = {}
    exec(src, ns)  # noqa: S102
    read_loop = ns["r"]

    def reads(n: int) -> float:
        return _timed(lambda m: read_loop(*getters, m), n)

    def agl_read(n: int) -> float:
        def loop(m: int) -> None:
            for _ in range(m):
                agl()

        return _timed(loop, n)

    def kernel(n: int) -> float:
        def loop(m: int) -> None:
            for _ in range(m):
                entry(snapshot, params, x, cols, table, 0, 0.0, 0.0)

        x_saved = x.copy()
        t = _timed(loop, n)
        x[:] = x_saved
        return t

    def writes(n: int) -> float:
        # the step writes them one by one from locals: time that form
        body = "\n".join(f"        s{i}(r{i})" for i in range(len(setters)))
        unpack = ", ".join(f"r{i}" for i in range(len(setters)))
        args = ", ".join(f"s{i}" for i in range(len(setters)))
        src = (f"def w(set_wind, reactions, m, {args}):\n    for _ in range(m):\n"
               f"        set_wind(-0.0)\n        {unpack}, *_ = reactions.tolist()\n{body}\n")
        ns: dict = {}
        exec(src, ns)  # noqa: S102
        w = ns["w"]
        t = _timed(lambda m: w(set_wind, reactions, m, *setters), n)
        step.release()  # no reactions left for the next piece's JSBSim
        return t

    # the set-up's multi-threaded BLAS calls (the antisymmetric modes' beam solve) leave
    # OpenBLAS's worker threads spinning for ~0.1 s, on this process's CPU clock: wait
    time.sleep(0.3)
    return {"bare": bare, "step": stepped, "reads": reads, "agl": agl_read,
            "kernel": kernel, "writes": writes}


def measure(span: str, steps: int, repeat: int, speed_m_s: float) -> dict:
    build = build_wing(VARIANTS["optimised"])
    runs = pieces(build, span, speed_m_s, steps)
    times: dict[str, list[float]] = {k: [] for k in PIECES}
    load0 = list(os.getloadavg())
    for _ in range(repeat):
        for name in PIECES:
            times[name].append(runs[name](steps) * 1e6)
    least = {k: min(v) for k, v in times.items()}
    bare = least["bare"]
    rest = least["step"] - least["reads"] - least["agl"] - least["kernel"] - least["writes"]
    out = {k: {"least_us": least[k], "median_us": statistics.median(times[k]),
               "ratio": least[k] / bare} for k in PIECES}
    out["jsbsim_in_step"] = {"least_us": rest, "ratio": rest / bare}
    return {"span": span, "steps": steps, "repeat": repeat, "pieces": out,
            "load_average_before": load0, "load_average": list(os.getloadavg())}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--span", choices=("half", "full", "both"), default="both")
    p.add_argument("--steps", type=int, default=2000, help="calls a timing (default 2000)")
    p.add_argument("--repeat", type=int, default=15, help="interleaved repeats (default 15)")
    p.add_argument("--speed", type=float, default=15.0, help="trim airspeed [m/s], default 15")
    p.add_argument("--json", action="store_true")
    a = p.parse_args()
    spans = ("half", "full") if a.span == "both" else (a.span,)
    results = [measure(s, a.steps, a.repeat, a.speed) for s in spans]
    if a.json:
        print(json.dumps(results, indent=1))
        return
    for r in results:
        print(f"{r['span']} span: least of {r['repeat']} timings of {r['steps']} calls, CPU "
              f"clock; load {r['load_average_before'][0]:.2f} -> {r['load_average'][0]:.2f}")
        for name, d in r["pieces"].items():
            med = f"  (median {d['median_us']:.3f})" if "median_us" in d else ""
            print(f"  {name:15s} {d['least_us']:7.3f} µs  x{d['ratio']:.3f} bare{med}")


if __name__ == "__main__":
    main()
