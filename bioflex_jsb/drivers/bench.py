"""Benchmarks of the coupled step: figures measured in one run, as ratios of interleaved pairs.

Machines are shared and noisy (load averages of 4-10 on 2 cores were seen), so every ratio
is the median of pairs timed back to back (the load changes less within a pair than across
a run), with its min and max; and per-step costs are separated from fixed per-run costs by
timing each run at two lengths (per step = ΔT/ΔN, fixed = T − N·per step).
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from bioflex_jsb.drivers.gust import RunSetup, run_gust
from bioflex_jsb.drivers.native import native_airframe
from bioflex_jsb.flight_dynamics.wing_model import WingBuild
from bioflex_jsb.runtime.coupled_step import configure_airframe
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks.mcap import RunLog


@dataclass(frozen=True)
class Spread:
    """Median, min and max of a set of measurements (units of the measurement)."""

    median: float
    min: float
    max: float

    @classmethod
    def of(cls, values: list[float]) -> Spread:
        return cls(statistics.median(values), min(values), max(values))

    def as_dict(self) -> dict[str, float]:
        return {"median": self.median, "min": self.min, "max": self.max}


class BenchmarkStopped(RuntimeError):
    """A benchmark run left the valid range (the benchmark case must fly)."""


def _per_step(timed: Callable[[int], float], n_short: int, n_long: int) -> tuple[float, float]:
    """(per-step [s], fixed per-run [s]) of ``timed(n) -> seconds`` from two run lengths."""
    t_short, t_long = timed(n_short), timed(n_long)
    per_step = (t_long - t_short) / (n_long - n_short)
    return per_step, t_short - n_short * per_step


class StepBench:
    """Bare JSBSim, the co-simulation (compiled and Python steps), logged, and the native XML
    wing, on one airframe at the co-simulation's step."""

    def __init__(self, build: WingBuild, speed_m_s: float = 15.0, steps: int = 1200) -> None:
        self.build = build
        self.speed_m_s = speed_m_s
        self.steps = steps
        self.airframe = Airframe()
        self.native = native_airframe(build.variant.name)
        configure_airframe(self.airframe, DEFAULT_DT_S)
        configure_airframe(self.native, DEFAULT_DT_S, modal_hooks=False)
        self._tmp = tempfile.TemporaryDirectory()
        self._logs = 0

    def close(self) -> None:
        self._tmp.cleanup()

    def bare(self, n: int) -> float:
        """Seconds for ``n`` steps of JSBSim alone (trimmed first, outside the timing)."""
        self.airframe.trim(self.speed_m_s)
        return self._timed_run(self.airframe, n)

    def native_run(self, n: int) -> float:
        self.native.trim(self.speed_m_s)
        return self._timed_run(self.native, n)

    @staticmethod
    def _timed_run(af: Airframe, n: int) -> float:
        step = af.step_function()
        with af.capturing():
            t0 = time.perf_counter()
            for _ in range(n):
                step()
            return time.perf_counter() - t0

    def cosim(self, n: int, gust: str = "sharp:0.3", logged: bool = False,
              compiled: bool = True) -> float:
        """Seconds for a co-simulated run of ``n`` steps (the coupled wing) through ``gust``,
        starting at half the run; with an MCAP log when ``logged``."""
        dt = DEFAULT_DT_S
        setup = RunSetup(self.speed_m_s, parse_gust(gust), duration_s=n * dt,
                         gust_start_s=0.5 * self.steps * dt, dt_s=dt)
        trim = self.airframe.trim(self.speed_m_s)  # outside the timing, as for bare()
        log = None
        if logged:
            self._logs += 1
            desc = RunDescription("bench", self.build.variant.name, self.speed_m_s, gust=gust,
                                  models=("coupled",), duration_s=n * dt)
            log = RunLog.open(Path(self._tmp.name) / f"bench{self._logs}.mcap", desc)
        try:
            t0 = time.perf_counter()
            run = run_gust(self.airframe, self.build.model, "coupled", setup, trim=trim,
                           recorder=log.recorder("coupled") if log else None,
                           compiled=compiled)
            elapsed = time.perf_counter() - t0
        finally:
            if log is not None:
                log.close()
        if run.stopped:
            raise BenchmarkStopped(f"benchmark run stopped: {run.stopped}")
        return elapsed

    def measure(self, repeat: int = 5, gusts: tuple[str, ...] = ("sharp:0.3", "sharp:3",
                                                                    "dryden:1.5:100:7"),
                progress=None) -> dict[str, object]:
        """Every figure of ``bioflex-jsb bench`` (module docstring; times in µs per step)."""
        n1, n2 = self.steps, 2 * self.steps
        pairs: dict[str, list[float]] = {k: [] for k in (
            "ratio", "logged_ratio", "log_ratio", "native_ratio", "python_ratio")}
        us: dict[str, list[float]] = {k: [] for k in (
            "bare", "cosim", "logged", "native", "python")}
        fixed: dict[str, list[float]] = {k: [] for k in ("cosim", "logged")}
        by_gust: dict[str, list[float]] = {g: [] for g in gusts}
        # warm-up, not timed: the first run pays one-time costs (lazy imports, the first
        # reference step, the log writer's first chunk) that would land in one run length
        self.cosim(n1)
        self.cosim(n1, logged=True)
        self.cosim(n1, compiled=False)
        self.native_run(n1)
        for _ in range(repeat):
            b, _f = _per_step(self.bare, n1, n2)
            c, fc = _per_step(lambda n: self.cosim(n), n1, n2)
            lg, fl = _per_step(lambda n: self.cosim(n, logged=True), n1, n2)
            b2, _f = _per_step(self.bare, n1, n2)
            nat, _f = _per_step(self.native_run, n1, n2)
            py, _f = _per_step(lambda n: self.cosim(n, compiled=False), n1, n2)
            bb = 0.5 * (b + b2)  # the bare step on both sides of the co-simulated ones
            pairs["ratio"].append(c / bb)
            pairs["logged_ratio"].append(lg / bb)
            pairs["log_ratio"].append(lg / c)
            pairs["native_ratio"].append(nat / b2)
            pairs["python_ratio"].append(py / bb)
            for key, value in (("bare", bb), ("cosim", c), ("logged", lg), ("native", nat),
                               ("python", py)):
                us[key].append(value * 1e6)
            fixed["cosim"].append(fc * 1e3)
            fixed["logged"].append(fl * 1e3)
            for g in gusts:
                gc, _f = _per_step(lambda n, g=g: self.cosim(n, gust=g), n1, n2)
                by_gust[g].append(gc * 1e6)
            if progress is not None:
                progress.update(1)
        if progress is not None:
            progress.close()
        return {
            **{k: Spread.of(v).as_dict() for k, v in pairs.items()},
            "us_per_step": {k: Spread.of(v).as_dict() for k, v in us.items()},
            "fixed_ms_per_run": {k: Spread.of(v).as_dict() for k, v in fixed.items()},
            "cosim_us_per_step_by_gust": {g: Spread.of(v).as_dict()
                                          for g, v in by_gust.items()},
        }


def refresh_cost_ms(build: WingBuild, n: int = 50) -> dict[str, float]:
    """Cost of renewing the wing's reference step (expm and Fréchet derivatives, BLAS on one
    thread) [ms]: median and max over ``n`` refreshes at flows 1 % apart."""
    from bioflex_jsb.simulation.modal_wing import ModalWing, TrimReference

    mw = ModalWing(build.model, TrimReference(0.05, 137.8, 0.5), dt_s=DEFAULT_DT_S)
    mw._reference(137.8, 15.0)  # the first call loads what it needs: not a refresh
    times = []
    for i in range(n):
        t0 = time.perf_counter()
        mw._reference(137.8 * (1.0 + 0.01 * (i + 1)), 15.0)
        times.append((time.perf_counter() - t0) * 1e3)
    return {"median": statistics.median(times), "max": max(times)}


def compile_cost_s() -> dict[str, float]:
    """Seconds to import and compile the step kernel with an empty numba cache (``cold``: a
    fresh machine pays this once) and to import it again with that cache filled
    (``cached``: every later run), each measured in a child process."""
    code = ("import time; t0 = time.perf_counter(); "
            "from bioflex_jsb.simulation import step_kernel as K; K.compile_now(); "
            "print(time.perf_counter() - t0)")
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        out = {}
        for name in ("cold", "cached"):
            run = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                                 text=True, check=True, timeout=600)
            out[name] = float(run.stdout.strip().splitlines()[-1])
    return out
