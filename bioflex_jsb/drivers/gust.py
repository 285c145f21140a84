"""A nonlinear gust run: trim, then fly the one coupled step through a gust.

:func:`run_gust` is a thin loop over :class:`~bioflex_jsb.runtime.coupled_step.CoupledStep`
(whose docstring has the order of a step): the gust is sampled by step number, every row is
stored in the run's table and handed to a recorder (an MCAP log), and the run stops when the
step leaves its valid range. The Fig. 21 run is within 1 % NRMSE of the same run at a quarter
of the step (``tests/test_cosim.py``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.runtime.coupled_step import CoupledStep
from bioflex_jsb.runtime.fdm import Airframe, TrimResult
from bioflex_jsb.simulation.gusts import GustField, GustSpec
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.simulation.results import TimeHistory


@dataclass(frozen=True)
class RunSetup:
    """What a gust run needs: trim speed [m/s], gust, duration [s], gust start [s], altitude
    [m], co-simulation step [s]."""

    speed_m_s: float
    gust: GustSpec
    duration_s: float = 6.0
    gust_start_s: float = 0.5
    altitude_m: float = 0.0
    dt_s: float = DEFAULT_DT_S


class StepRecorder(Protocol):
    """Something that keeps a run's steps as they complete (an MCAP log), reading them from
    the run's own table rather than being handed each step's numbers.

    ``start`` is called once before the first step with the channel names, the times [s] of
    every step the run may take and the (steps × channels) table the run fills row by row
    (units: :func:`bioflex_jsb.simulation.channels.channel_units`); ``step(k)`` after row k
    is complete; ``stop(n)`` once at the end, however the run ends (finished, stopped,
    interrupted, failed), with the number of complete rows.
    """

    def start(self, names: tuple[str, ...], time_s: np.ndarray, table: np.ndarray) -> None: ...

    def step(self, k: int) -> None: ...

    def stop(self, n: int) -> None: ...


def run_gust(
    airframe: Airframe,
    wing: ElasticWingModel | None,
    model: str,
    setup: RunSetup,
    on_sample: Callable[[int, float, np.ndarray], None] | None = None,
    trim: TrimResult | None = None,
    recorder: StepRecorder | None = None,
    compiled: bool = True,
    aero: str = "quasi-steady",
) -> TimeHistory:
    """Trim, then fly ``setup`` with the wing ``model`` (rigid/coupled/qsd, or native for an
    aircraft with the wing in its XML, ``wing`` then None).

    ``on_sample(k, t_s, row)`` is called after every step (progress), ``row`` the step's
    row of the table (channel order; read it, do not keep it); ``recorder`` (a log) reads
    the steps from the run's table (:class:`StepRecorder`). A run that leaves the valid
    range stops: the returned history holds every step up to then and its ``stopped``
    field says why. ``trim``: the airframe was just trimmed to this (skip it).
    ``compiled``: the compiled step kernel, or (False) the readable Python step it is
    tested against.
    """
    step = CoupledStep(airframe, wing, model, setup.speed_m_s, setup.altitude_m, setup.dt_s,
                       trim=trim, compiled=compiled, aero=aero)
    dt = step.dt_s
    gust = GustField(setup.gust, setup.speed_m_s, setup.gust_start_s, setup.duration_s, dt)
    n_steps = int(round(setup.duration_s / dt))
    names = step.names
    table = np.full((n_steps, len(names)), np.nan)  # row k: step k, columns in names' order
    time_s = np.arange(n_steps) * dt
    stopped = None
    interrupted = False
    done = 0  # complete rows of the table
    if recorder is not None:
        recorder.start(names, time_s, table)
        record = recorder.step
    advance_into = step.stepper()  # the step, bound once (compiled or Python)
    w_g = gust.samples(n_steps).tolist()  # the gust by step number [m/s, up]
    try:
        with airframe.capturing():  # JSBSim's output captured once for the loop
            for k in range(n_steps):
                stop = advance_into(w_g[k], table, k)
                done = k + 1
                if recorder is not None:
                    record(k)
                if on_sample is not None:
                    on_sample(k, k * dt, table[k])
                if stop:
                    stopped = stop
                    break
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM (the CLI maps it): keep what was flown
        interrupted = True
        stopped = f"interrupted at t = {done * dt:.3f} s"
    finally:
        step.release()
        if recorder is not None:
            recorder.stop(done)  # also when the loop failed: keep every complete step
    n = done
    trim = step.trim
    return TimeHistory(
        model=model,
        time_s=time_s[:n],
        channels={name: table[:n, i].copy() for i, name in enumerate(names)},
        units=dict(step.units),
        meta={
            "source": "jsbsim-native" if model == "native" else "jsbsim-cosim",
            "speed_m_s": setup.speed_m_s,
            "dt_s": dt,
            "gust": setup.gust.text(),
            "gust_start_s": setup.gust_start_s,
            "trim_alpha_rad": trim.alpha_rad,
            "trim_theta_rad": trim.theta_rad,
            "trim_elevator_rad": trim.elevator_rad,
            "trim_throttle": trim.throttle,
            "alpha_peak_rad": step.alpha_peak_rad,
            "time_beyond_stall_s": step.stall_steps * dt,
            "interrupted": interrupted,
        },
        stopped=stopped,
    )
