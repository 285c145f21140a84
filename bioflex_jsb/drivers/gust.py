"""A nonlinear gust run: trim, then fly the one coupled step through a gust.

:func:`run_gust` is a thin loop over :class:`~bioflex_jsb.runtime.coupled_step.CoupledStep`
(whose docstring has the order of a step): the gust is sampled by step number, the rows are
written block by block (a block = the log's chunk, 0.9 s of simulated time) and each full
block is handed to a recorder (an MCAP log), and the run stops when the step leaves its valid
range. Short runs keep every row; long ones keep one block plus a bounded envelope for their
summary (``keep``), so memory stays flat however long the run. The Fig. 21 run is within
1 % NRMSE of the same run at a quarter of the step (``tests/test_cosim.py``).

Given the wing's build (``loads=``), a run also reports the wing's **section loads** at the
monitoring stations (``docs/loads.md``): computed block by block as the run is flown
(:class:`bioflex_jsb.loads.stream.LoadStream`, a row's loads once the next row's q is
known), kept as channels ``loads_<fs|md>_<quantity>_s<j>`` (every step, or their extremes
in the envelope) and handed to a recorder that takes them (the log's ``/bioflex/<model>/
loads`` topic).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.wing_model import WingBuild
from bioflex_jsb.interrupts import STOP, raise_if_stopped
from bioflex_jsb.loads.model import LoadsModel, build_loads_model
from bioflex_jsb.loads.stream import LoadStream
from bioflex_jsb.parameters.sensors import Sensors
from bioflex_jsb.runtime.coupled_step import CoupledStep
from bioflex_jsb.runtime.fdm import Airframe, TrimResult
from bioflex_jsb.runtime.gust_loads import GUST_CHANNELS, GustLoads, field_for, with_gust_loads
from bioflex_jsb.simulation import jsbsim_properties as JP
from bioflex_jsb.simulation.channels import mode_tips
from bioflex_jsb.simulation.controller import controller_meta
from bioflex_jsb.simulation.results import KEEP_ALL_MAX_S, TimeHistory
from bioflex_jsb.simulation.run_config import RunConfig
from bioflex_jsb.simulation.sensors import SensorSet

# The envelope: per this span of simulated time [s], the first and last step and the steps
# where each summary channel reaches its minimum and maximum.
ENVELOPE_S = 0.25
# At most this many envelope windows are kept: beyond, neighbours are merged in pairs (the
# span doubles), so the envelope of a run of any length stays under ~6 MB; its peaks stay
# those of every step.
ENVELOPE_MAX_WINDOWS = 2048
# … and at most this many rows: a run with section loads keeps the extremes of 36 more
# selectors per window (24 loads, 12 FS − MD differences, up to 84 rows a window), so its
# windows are merged by the rows they hold too; the bound stays that of the run without
# loads, 2048 windows × 12 rows (24576 rows of 55 doubles with loads: 10.8 MB).
ENVELOPE_MAX_ROWS = 12 * ENVELOPE_MAX_WINDOWS
SUMMARY_CHANNELS = ("u", "alpha", "q", "theta", "n_z")  # what gust_metrics reads
WINDOW_S = 0.9  # rows per block without a recorder [s of simulated time]
KEEP_CHOICES = ("auto", "all", "envelope")


class StepRecorder(Protocol):
    """Something that keeps a run's steps as they complete (an MCAP log), handed a block of
    rows at a time.

    ``start(names, dt_s)`` is called once before the first step with the channel names and
    the step [s] and returns how many steps a block should hold (the log's chunk);
    ``rows(time_s, rows)`` with each block's complete rows as soon as it is flown (times [s],
    a (steps × channels) array in the names' order, units:
    :func:`bioflex_jsb.simulation.channels.channel_units`; both may be reused once it
    returns), and with the rows left when the run stops; ``stop(n)`` once at the end,
    however the run ends (finished, stopped, interrupted, failed), with the number of
    complete rows.

    A recorder that also logs a controller in the loop has ``controller(names, meta)``
    (optional): called once before the first step of a run with a controller (``meta``: the
    run's ``meta["controller"]``), it returns an object whose ``rows(time_s, rows)`` is
    handed the same rows as the recorder's, right after them, and whose ``stop()`` is called
    once at the end, before the recorder's own.

    A recorder that also logs section loads has ``loads(layout)`` (optional): called once
    before the first step of a run with loads (``layout``: the run's ``meta["loads"]``,
    channel names, units, stations, 1 g values), it returns an object whose ``rows(time_s,
    values)`` is handed the loads (rows × ``layout["names"]``) a block at a time, one step
    behind the steps (:class:`~bioflex_jsb.loads.stream.LoadStream`), and whose ``stop()``
    is called once at the end, before the recorder's own.
    """

    def start(self, names: tuple[str, ...], dt_s: float) -> int: ...

    def rows(self, time_s: np.ndarray, rows: np.ndarray) -> None: ...

    def stop(self, n: int) -> None: ...


class _Envelope:
    """A bounded history of a long run: per window of steps (ENVELOPE_S, doubled each time
    more than ENVELOPE_MAX_WINDOWS windows or ENVELOPE_MAX_ROWS rows are kept), the first
    and last step and the steps where each of :data:`SUMMARY_CHANNELS` (and each of
    ``extra``, the load channels) is smallest and largest, and where the difference of each
    column pair of ``pairs`` (force summation − mode displacement) is, so the peaks (and
    the overshoot) that ``gust_metrics`` reports are those of every step; its settling time
    is resolved to the window (``span_s``)."""

    def __init__(self, names: tuple[str, ...], dt_s: float, extra: tuple[str, ...] = (),
                 pairs: tuple[tuple[int, int], ...] = ()) -> None:
        self.cols = [names.index(c) for c in SUMMARY_CHANNELS if c in names]
        self.cols += [names.index(c) for c in extra]
        self.pair_a = np.array([a for a, _ in pairs], dtype=np.intp)
        self.pair_b = np.array([b for _, b in pairs], dtype=np.intp)
        self.every = max(1, int(round(ENVELOPE_S / dt_s)))
        self.span_s = self.every * dt_s
        self._t: list[np.ndarray] = []
        self._rows: list[np.ndarray] = []

    def _keep(self, t: np.ndarray, seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = seg[:, self.cols]
        if self.pair_a.size:
            x = np.hstack([x, seg[:, self.pair_a] - seg[:, self.pair_b]])
        nan = np.isnan(x)
        hi = np.argmax(np.where(nan, -np.inf, x), axis=0)
        lo = np.argmin(np.where(nan, np.inf, x), axis=0)
        keep = np.unique(np.concatenate([[0, len(seg) - 1], hi, lo]))
        return t[keep], seg[keep]

    def add(self, time_s: np.ndarray, rows: np.ndarray) -> None:
        for a in range(0, len(rows), self.every):
            t, seg = self._keep(time_s[a:a + self.every], rows[a:a + self.every])
            self._t.append(t)
            self._rows.append(seg.copy())
        while (len(self._rows) > ENVELOPE_MAX_WINDOWS
               or (sum(len(r) for r in self._rows) > ENVELOPE_MAX_ROWS and len(self._rows) > 1)):
            self._coarsen()

    def _coarsen(self) -> None:
        """Merge neighbouring windows in pairs: the span doubles, the extremes stay."""
        ts, rs = [], []
        for i in range(0, len(self._rows) - 1, 2):
            t, seg = self._keep(np.concatenate(self._t[i:i + 2]),
                                np.concatenate(self._rows[i:i + 2]))
            ts.append(t)
            rs.append(seg)
        if len(self._rows) % 2:
            ts.append(self._t[-1])
            rs.append(self._rows[-1])
        self._t, self._rows = ts, rs
        self.every *= 2
        self.span_s *= 2.0

    def history(self, n_channels: int) -> tuple[np.ndarray, np.ndarray]:
        if not self._rows:
            return np.empty(0), np.empty((0, n_channels))
        return np.concatenate(self._t), np.concatenate(self._rows)


def run_gust(
    airframe: Airframe,
    wing: ElasticWingModel | WingBuild | None,
    model: str,
    setup: RunConfig,
    on_sample: Callable[[int, float, np.ndarray], None] | None = None,
    trim: TrimResult | None = None,
    recorder: StepRecorder | None = None,
    compiled: bool = True,
    keep: str = "auto",
    loads: WingBuild | LoadsModel | None = None,
    progress: Callable[[int], None] | None = None,
    sensors: Sensors | SensorSet | None = None,
    controller=None,
    span: str = "half",
    aileron=None,
    aileron_input=None,
) -> TimeHistory:
    """Trim, then fly ``setup`` (a :class:`~bioflex_jsb.simulation.run_config.RunConfig`)
    with the wing ``model`` (rigid/coupled/qsd, or native for an aircraft with the wing in
    its XML, ``wing`` then None), with the aerodynamics and the trim the configuration gives
    that model (``setup.settings_for``: the unsteady strips and the elastic trim are the
    elastic wings'; they need the wing's build, ``setup.needs_build``).

    ``on_sample(k, t_s, row)`` is called after every step, ``row`` the step's row (channel
    order; read it, do not keep it): it costs 0.28 µs a step of ~6.7 (measured with a
    progress bar's callback), so a progress bar takes ``progress(steps)`` instead,
    called after every block with the steps flown so far; ``recorder`` (a log) is handed
    the rows a block at a time (:class:`StepRecorder`). A run that leaves the valid range
    stops: the returned history holds the steps up to then and its ``stopped`` field says
    why.
    ``trim``: the airframe was just trimmed to this (skip it). ``compiled``: the compiled
    step kernel, or (False) the readable Python step it is tested against.

    ``keep``: what the returned history holds. ``"all"``: every step (memory grows with the
    run, ≈ 0.5 MB per simulated second); ``"envelope"``: a bounded-rate envelope (per
    ENVELOPE_S, the first and last step and each summary channel's extremes: exact peaks,
    settling time to ENVELOPE_S; ``meta["history"]`` says which) while the run itself keeps
    only one block of rows; ``"auto"`` (default): ``"all"`` up to KEEP_ALL_MAX_S of
    duration, else ``"envelope"``.

    ``loads``: also report the wing's section loads (module docstring): the wing's
    :class:`WingBuild` (the default stations, root, 25, 50, 75 % semispan; the 1 g part the
    elastic trim's for the coupled and qsd wings, the undeformed wing's for the rigid model;
    the run's own air density) or a :class:`~bioflex_jsb.loads.model.LoadsModel` of the
    run's speed. The history then has the channels ``loads_<fs|md>_<quantity>_s<j>`` [N,
    N·m] and ``meta["loads"]`` (stations, methods, 1 g values); a wing without section loads
    (a modes file, no static equilibrium at this speed) or the native model has
    ``meta["loads_unavailable"]`` (why) instead. Methods: both for the coupled and qsd
    wings (the unsteady wing's force summation with its strips' lag, apparent-mass and
    Küssner increments recovered after the steps: :mod:`bioflex_jsb.loads.unsteady`), force
    summation for the rigid model; a modes-file wing without EI, GJ has force summation only
    (:mod:`bioflex_jsb.loads.stream`).

    ``sensors``: the aircraft's IMUs and airspeed probes
    (:class:`~bioflex_jsb.parameters.sensors.Sensors`, in body axes from the CG, their mode
    shapes from the build, ``wing`` or ``loads``; or a ready
    :class:`~bioflex_jsb.simulation.sensors.SensorSet`); None: the wing build's (an
    aircraft definition's ``[sensors]``). Each is
    channels of the history (``imu_<name>_ax_m_s2`` … ``gz_rad_s``, ``airspeed_<name>_m_s``;
    :mod:`bioflex_jsb.simulation.sensors`), ``meta["sensors"]`` says where they sit.
    ``controller``: a controller in the loop (:mod:`bioflex_jsb.simulation.controller`: a
    Python object with ``step(t_s, signals)`` or a
    :class:`~bioflex_jsb.simulation.controller.LinearController`; a fresh one per run, its
    state starts at the trim): every step it reads the row's signals and commands the
    elevator and throttle over the trim; the history has its commands as channels
    ``ctrl_<command>`` and ``meta["controller"]`` says what it was.

    ``span``: ``half`` (the half wing, default) or ``full`` (both halves: the antisymmetric
    modes too, ``wing`` a WingBuild; :mod:`bioflex_jsb.simulation.full_span`, its channels
    ``asym_eta<i>``, ``tip_twist_port_rad`` …), ``aileron`` its
    :class:`~bioflex_jsb.aeroelasticity.control_surface.ControlSurface` (the definition's
    ``[aileron]``; None: none on the strips); ``aileron_input`` an
    :class:`~bioflex_jsb.simulation.full_span.AileronInput` (a step or doublet of JSBSim's
    aileron over the trim, ``meta["aileron_input"]``) or None.
    """
    if keep not in KEEP_CHOICES:
        raise ValueError(f"keep must be one of {', '.join(KEEP_CHOICES)}, not {keep!r}")
    aero, trim_mode = (v.value for v in setup.settings_for(model))  # the run's rules
    model = str(model)  # its name, as the history, the logs and the tables carry it
    # what each η_i does at the tip (twist or deflection), for figures: from the build
    build = wing if isinstance(wing, WingBuild) else loads if isinstance(loads, WingBuild) \
        else None
    sensor_set = _sensor_set(sensors, build, wing)
    if aileron_input is not None and "aileron" in getattr(controller, "outputs", ()):
        raise InputError("an aileron step or doublet and a controller's aileron command both "
                         "write JSBSim's aileron command: give one of them")
    step = CoupledStep(airframe, wing, model, setup.speed_m_s, setup.altitude_m,
                       setup.dt_s, trim=trim, compiled=compiled, aero=aero,
                       trim_mode=trim_mode, sensors=sensor_set, controller=controller,
                       span=span, aileron=aileron)
    refused = True
    try:
        stream, loads_meta = _load_stream(loads, step, model, setup.speed_m_s, aero)
        refused = False
    finally:
        if refused:  # a loads model refused (InputError): the step's hold goes with it
            step.release()
    keep_all = keep == "all" or (keep == "auto" and setup.duration_s <= KEEP_ALL_MAX_S)
    run = _GustRun(step, setup, stream, loads_meta, recorder, keep_all, build)
    run.inputs = _aileron_changes(step, aileron_input)
    run.fly(airframe, on_sample, progress)
    history = run.history(model, trim_mode, build)
    if aileron_input is not None:
        history.meta["aileron_input"] = aileron_input.as_dict()
    history.meta["span"] = span
    if span == "full":  # the antisymmetric wing's strips and which step flew them
        history.meta["lateral_strips"] = (f"{aero}, "
                                          f"{'compiled kernel' if step.compiled else 'python'}")
    if step.flaperon is not None:  # its surface and derivatives (compare's LTI flies them)
        history.meta["flaperon"] = step.flaperon.deriv.as_dict()
    if sensor_set is not None:  # as flown (both halves: the antisymmetric columns too)
        history.meta["sensors"] = step.sensor_set.describe()
    return history


def _sensor_set(sensors, build: WingBuild | None, wing) -> SensorSet | None:
    """The run's :class:`SensorSet` (None: no sensors): ``sensors`` or the build's, with the
    build's modes (the wing model's first ``n_modes``); a sensor on the wing without the
    build (its mode shapes) is refused in one line."""
    if isinstance(sensors, SensorSet):
        return sensors if len(sensors) else None
    if sensors is None:
        sensors = build.sensors if build is not None else None
    if not sensors:
        return None
    n_modes = getattr(wing, "n_modes", None)
    if isinstance(wing, WingBuild):
        n_modes = wing.model.n_modes
    if build is None and any(s.wing is not None for s in (*sensors.imus, *sensors.airspeeds)):
        raise InputError("a sensor on the wing needs the wing's mode shapes: give the "
                         "WingBuild as wing or loads, or a SensorSet")
    return SensorSet(sensors, None if build is None else build.modes, n_modes)


class _GustRun:
    """One run's rows on their way: the table (every step, or one block refilled), the
    envelope of a long run, the section loads one step behind, the recorder and its loads
    topic; :meth:`fly` flies the blocks, :meth:`history` gives the TimeHistory."""

    def __init__(self, step: CoupledStep, setup: RunConfig, stream, loads_meta: dict,
                 recorder, keep_all: bool, build=None) -> None:
        self.step, self.setup, self.stream, self.loads_meta = step, setup, stream, loads_meta
        self.recorder, self.keep_all = recorder, keep_all
        dt = self.dt = step.dt_s
        # the uniform gust, or one that varies over the aircraft (runtime/gust_loads.py)
        self.gust = field_for(setup.gust, step.airframe_data, build, setup.speed_m_s,
                              setup.gust_start_s, setup.duration_s, dt)
        # its loads, written before each step (an aircraft without the hooks refused here,
        # before the recorder starts)
        self.gust_loads = None if not getattr(self.gust, "varies", False) else GustLoads(
            step.airframe, self.gust, step.airframe_data.aero,
            step.airframe[JP.ATTITUDE_PSI_RAD])
        self.n_steps = int(round(setup.duration_s / dt))
        names = self.names = step.names
        block = max(1, int(round(WINDOW_S / dt)))
        self.loads_out = None  # the recorder's loads topic
        self.control_out = None  # the recorder's controller topic
        self.lateral_out = None  # the recorder's antisymmetric wing's topic (span full)
        if recorder is not None:
            block = max(1, int(recorder.start(names, dt)))
            if stream is not None and hasattr(recorder, "loads"):
                self.loads_out = recorder.loads(loads_meta["loads"])
            if step.control is not None and hasattr(recorder, "controller"):
                meta = controller_meta(step.control)
                if step.flaperon is not None:  # its surface: a log's loads need it
                    meta["flaperon"] = step.flaperon.deriv.as_dict()
                self.control_out = recorder.controller(names, meta)
            if step.lateral is not None and hasattr(recorder, "lateral"):
                self.lateral_out = recorder.lateral(names)  # both wing halves
        self.block = min(block, max(self.n_steps, 1))
        load_names = self.load_names = stream.names if stream is not None else ()
        self.loads_table = None
        if keep_all:  # row k: step k, columns in names' order
            self.table = np.full((self.n_steps, len(names)), np.nan)
            if stream is not None:
                self.loads_table = np.full((self.n_steps, len(load_names)), np.nan)
            self.envelope = None
        else:  # one block of rows, refilled block after block
            self.table = np.full((self.block, len(names)), np.nan)
            both = names + load_names
            pairs = tuple((both.index(c), both.index(c.replace("loads_fs_", "loads_md_")))
                          for c in load_names if c.startswith("loads_fs_")
                          and c.replace("loads_fs_", "loads_md_") in load_names)
            self.envelope = _Envelope(both, dt, load_names, pairs)
        self.k_loads = 0  # rows whose loads are out
        self.k = 0  # steps handed over
        self.stopped: str | None = None
        self.interrupted = False
        self.inputs = None  # (set(value), {step: value}) of an aileron input

    def hand_loads(self, time_s: np.ndarray, rows: np.ndarray, values: np.ndarray) -> None:
        """Rows whose loads are known (one behind the steps): to the loads topic, the
        loads table or the envelope."""
        if not len(time_s):
            return
        if self.loads_out is not None:
            self.loads_out.rows(time_s, values)
        if self.loads_table is not None:
            self.loads_table[self.k_loads:self.k_loads + len(time_s)] = values
        if self.envelope is not None:
            self.envelope.add(time_s, np.hstack([rows, values]))
        self.k_loads += len(time_s)

    def hand(self, k0: int, m: int, j0: int, last: bool = False) -> None:
        """Rows [k0, k0 + m) of the run, complete in the table from row j0: to the
        recorder and the envelope (and their loads, those known, to theirs; with the
        ``last`` block, every one: the loads topic gets no chunk of a single step)."""
        if m <= 0:
            return
        rows = self.table[j0:j0 + m]
        time_s = (k0 + np.arange(m)) * self.dt
        if self.recorder is not None:
            self.recorder.rows(time_s, rows)
            if self.control_out is not None:
                self.control_out.rows(time_s, rows)
            if self.lateral_out is not None:
                self.lateral_out.rows(time_s, rows)
        if self.stream is not None:
            known = self.stream.add(time_s, rows)
            if last:
                end = self.stream.finish()
                known = tuple(np.concatenate([a, b]) for a, b in zip(known, end, strict=True))
            self.hand_loads(*known)
        elif self.envelope is not None:
            self.envelope.add(time_s, rows)

    def _block(self, advance_into, j0: int, on_sample) -> tuple[int, str | None]:
        """Fly one block from row ``j0``: (the steps flown, why the run stopped or None).
        Between steps a stop signal deferred inside JSBSim's calls (STOP.pending,
        bioflex_jsb.interrupts) ends the block, raised once it is handed on."""
        k, table, dt = self.k, self.table, self.dt
        # the gust by step number [m/s, up], one block at a time
        ws = self.gust.samples(min(self.block, self.n_steps - k), k).tolist()
        stop, i, ended = None, 0, False
        # the steps flown are counted once, when the block ends (returned) or fails (kept in
        # _in_block for _finish), not after every step
        try:
            for w in ws:
                stop = advance_into(w, table, j0 + i)
                i += 1
                if on_sample is not None:
                    on_sample(k + i - 1, (k + i - 1) * dt, table[j0 + i - 1])
                if stop or STOP.pending:
                    break
            ended = True
        finally:
            if not ended:  # an error or Ctrl-C inside the block: _finish hands its i rows
                self._in_block = (j0, i)
        return i, stop

    def fly(self, airframe: Airframe, on_sample, progress) -> None:
        """Fly every block, handing each on; a stop (out of range) ends the run, Ctrl-C or
        SIGTERM keeps what was flown; every complete step reaches the recorder however the
        run ends."""
        advance_into = self.step.stepper()  # the step, bound once (compiled or Python)
        if self.inputs is not None:  # an aileron input: its commands at their steps
            advance_into = _with_inputs(advance_into, self.step, *self.inputs)
        gust_loads = self.gust_loads
        if gust_loads is not None:
            advance_into = with_gust_loads(advance_into, self.step, gust_loads)
        self._in_block = (0, 0)
        try:
            with airframe.capturing():  # JSBSim's output captured once for the loop
                while self.k < self.n_steps:
                    j0 = self.k if self.keep_all else 0
                    m, stop = self._block(advance_into, j0, on_sample)
                    self.k += m
                    self.hand(self.k - m, m, j0, last=bool(stop) or self.k >= self.n_steps)
                    if progress is not None:
                        progress(self.k)
                    if stop:
                        self.stopped = stop
                        break
                    raise_if_stopped()
        except KeyboardInterrupt:  # Ctrl-C or SIGTERM (the CLI maps it): keep what was flown
            self.interrupted = True
        finally:
            if gust_loads is not None:
                gust_loads.clear()
            self._finish()

    def _finish(self) -> None:
        self.step.release()
        try:
            j0, i = self._in_block
            if i:  # the block in progress when the loop failed or was interrupted
                self._in_block = (j0, 0)
                self.k += i
                self.hand(self.k - i, i, j0, last=True)
            if self.stream is not None and self.stream.holding:  # interrupted between blocks
                self.hand_loads(*self.stream.finish())
        finally:
            try:
                if self.loads_out is not None:
                    self.loads_out.stop()
                if self.control_out is not None:
                    self.control_out.stop()
                if self.lateral_out is not None:
                    self.lateral_out.stop()
            finally:
                if self.recorder is not None:
                    self.recorder.stop(self.k)  # also when the loop failed: every step kept

    def history(self, model: str, trim_mode: str, build) -> TimeHistory:
        """The run as a TimeHistory: every step, or the envelope (``meta["history"]``)."""
        n, dt, step, setup = self.k, self.dt, self.step, self.setup
        stopped = f"interrupted at t = {n * dt:.3f} s" if self.interrupted else self.stopped
        trim = step.trim
        units = dict(step.units)
        names, load_names = self.names, self.load_names
        if self.envelope is None:
            time_s = np.arange(n) * dt
            channels = table_columns(self.table[:n], names)
            if self.loads_table is not None:
                channels.update(table_columns(self.loads_table[:n], load_names))
            history = "all"
        else:
            time_s, rows = self.envelope.history(len(names) + len(load_names))
            channels = table_columns(rows, names + load_names)
            history = "envelope"
        if self.stream is not None:
            units.update(self.stream.units)
        if getattr(self.gust, "varies", False) and self.envelope is None:
            # the parts its loads were written from, step by step (a block at a time: an
            # oblique front's field is steps × strips)
            blocks = [self.gust.parts(min(4096, n - k0), k0) for k0 in range(0, n, 4096)]
            for i, name in enumerate(GUST_CHANNELS):
                channels[name] = np.concatenate([b[1 + i] for b in blocks]) if blocks \
                    else np.zeros(0)
            units.update(GUST_CHANNELS)
        return TimeHistory(
            model=model,
            time_s=time_s,
            channels=channels,
            units=units,
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
                "interrupted": self.interrupted,
                "history": history,
                "trim_mode": trim_mode,
                "static_eta_rad": (None if step.elastic_trim is None
                                   else [float(e) for e in step.elastic_trim.eta_rad]),
                "steps": n,
                "envelope_s": self.envelope.span_s if self.envelope is not None else None,
                "mode_tips": None if build is None else mode_tips(build.modes),
                **self.loads_meta,
                **({} if step.control is None else {"controller": controller_meta(step.control)}),
            },
            stopped=stopped,
        )


# Rows of the table turned into the history's columns this many at a time: a block of rows
# (≤ 512 × 8 bytes × the channels) stays in the core's cache while it is written out column
# after column. A 76 800-step full-span table of 50 channels (30 MB): 5.3-5.4 ms in blocks
# of 256 or 512 rows, 7.1-10 ms in blocks of 1024-8192, 13.6-14.5 ms copying one column at
# a time (the Intel guest, least of 3, load 4.7; 25-30 ms column by column inside a run,
# whose JSBSim steps have left the table out of the caches).
COLUMN_BLOCK_ROWS = 512


def table_columns(table: np.ndarray, names) -> dict[str, np.ndarray]:
    """``table``'s columns (rows × names) by name, each contiguous (rows of one transposed
    copy, made :data:`COLUMN_BLOCK_ROWS` rows at a time): the values of ``table[:, c]``."""
    out = np.empty((table.shape[1], table.shape[0]))
    for r0 in range(0, table.shape[0], COLUMN_BLOCK_ROWS):
        out[:, r0:r0 + COLUMN_BLOCK_ROWS] = table[r0:r0 + COLUMN_BLOCK_ROWS].T
    return {name: out[c] for c, name in enumerate(names)}


def _aileron_changes(step: CoupledStep, aileron_input):
    """(the aileron's writer, {step: δa over the trim [rad]}) of ``aileron_input``, or None."""
    if aileron_input is None:
        return None
    from bioflex_jsb.runtime.aileron_input import aileron_setter

    set_angle, _ = aileron_setter(step.airframe)
    return set_angle, aileron_input.changes(step.dt_s)


def _with_inputs(advance_into, step: CoupledStep, set_value, changes: dict[int, float]):
    """``advance_into`` writing each scheduled command before its step (steps flown:
    ``step.k``)."""
    get = changes.get

    def stepped(w_g_m_s: float, table: np.ndarray, k: int, *p_g):
        value = get(step.k)
        if value is not None:
            set_value(value)
        return advance_into(w_g_m_s, table, k, *p_g)  # p_g: a full-span step's gust roll

    return stepped


def _load_stream(loads, step: CoupledStep, model: str, speed_m_s: float, aero: str
                 ) -> tuple[LoadStream | None, dict[str, object]]:
    """The run's :class:`LoadStream` and its meta entries (``run_gust``'s ``loads``): None
    and ``{}`` without ``loads``; None and ``loads_unavailable`` (why) for a wing or model
    that has no section loads."""
    if loads is None:
        return None, {}
    if model == "native":
        return None, {"loads_unavailable": "the native wing (in the aircraft's XML) has no "
                                           "section loads model; fly the coupled model"}
    if isinstance(loads, LoadsModel):
        lm = loads
        if abs(lm.speed_m_s - speed_m_s) > 1e-9:
            raise InputError(f"the loads model is for {lm.speed_m_s:g} m/s, the run is "
                             f"trimmed at {speed_m_s:g} m/s")
        if model == "rigid" and np.any(lm.static_eta_rad != 0.0):
            raise InputError("a rigid-wing run has no static deflection: give a loads model "
                             "with static='rigid'")
    elif isinstance(loads, WingBuild):
        # the run's own density: JSBSim's at the trim (its dynamic pressure is the run's)
        rho = 2.0 * step.reference.dynamic_pressure_pa / speed_m_s**2
        try:
            lm = build_loads_model(loads, speed_m_s, density_kg_m3=rho,
                                   static="rigid" if model == "rigid" else "elastic")
        except InputError as exc:  # a modes-file wing, no static equilibrium: said why
            return None, {"loads_unavailable": str(exc)}
    else:
        raise TypeError(f"loads must be a WingBuild or a LoadsModel, not "
                        f"{type(loads).__name__}")
    if getattr(step, "flaperon", None) is not None and lm.flaperon is None:
        from bioflex_jsb.loads.flaperon import with_flaperon  # its strips' loads

        lm = with_flaperon(lm, step.flaperon.deriv)
    static_eta = None if step.elastic_trim is None else step.elastic_trim.eta_rad
    stream = LoadStream(lm, step.names, step.dt_s, model, static_eta, aero)
    layout = {"names": list(stream.names), "units": dict(stream.units),
              "methods": list(stream.methods), "stations_m": lm.stations_m.tolist(),
              "station_fractions": list(lm.station_fractions),
              "static_1g": dict(stream.static_1g), "note": lm.static_note,
              "density_kg_m3": lm.density_kg_m3, "wing": lm.wing}
    return stream, {"loads": layout}
