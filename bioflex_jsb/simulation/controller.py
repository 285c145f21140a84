"""Controllers in the loop: every step a controller reads named signals of the coupled step
and writes control commands.

**Signals** are the run's channels by name (:mod:`bioflex_jsb.simulation.channels`, SI:
``u``, ``alpha``, ``q``, ``theta``, ``n_z``, ``w_g``, the air data and attitude, ``eta<i>``,
``eta<i>_dot``, ...): a controller may read any channel the step writes before JSBSim's step,
the sensor stations' among them (``imu_<name>_az_m_s2`` of a wing-tip accelerometer,
``airspeed_<name>_m_s``; :mod:`bioflex_jsb.simulation.sensors`), which a linear controller
reads as perturbations from their true (noise- and bias-free) reading at the trim.
The section loads are not among them: a row's loads need the next row's pitch rate (its
pitch acceleration is a central difference, ``docs/loads.md``), so they are known one step
behind the steps. ``w_g`` is the true gust at the centre of gravity: an ideal gust sensor,
for feed-forward studies.

**Commands** (:data:`CONTROL_OUTPUTS`) are increments over the trim, in the LTI model's units
and signs (its inputs ``elevator`` and ``throttle``, :mod:`bioflex_jsb.flight_dynamics.lti`):

* ``elevator`` [rad]: elevator deflection added to the trim's, + trailing edge down
  (nose-down moment);
* ``throttle`` [-]: throttle added to the trim's (fraction of full throttle); the total is
  clipped to 0..1 by the flight controls;
* ``flaperon`` [rad]: the wing's ailerons deflected together, **both trailing edges down
  positive** (more lift, a nose-down moment on the prototype), on the half-wing co-simulation
  only; the definition's ``[aileron]`` on the strips, its travel ±10°
  (:mod:`bioflex_jsb.aeroelasticity.flaperon`: sign, section data, what is left out).
  JSBSim's tables have no symmetric aileron: its loads go to JSBSim's external reactions
  beside the modes' (never through ``fcs/aileron-cmd-norm``), its strip loads onto the
  symmetric modes, on the compiled step as on the Python one
  (:mod:`bioflex_jsb.runtime.control_surfaces`, "The flaperon";
  :mod:`bioflex_jsb.runtime.flaperon_step`);
* ``aileron`` [rad]: JSBSim's differential aileron δa = ½ (δ_left − δ_right) added to the
  trim's, **+ rolls right** (the starboard trailing edge up), on a full-span run only
  (``span="full"``: both wing halves, whose antisymmetric modes read JSBSim's two aileron
  positions every step, :mod:`bioflex_jsb.simulation.full_span`); written to
  ``fcs/aileron-cmd-norm`` through the aileron's measured map
  (:mod:`bioflex_jsb.runtime.aileron_input`), so JSBSim's rigid tables carry its rolling
  moment (C_lδa) and the strips its load on the modes. Refused (one line) on the half wing
  (no antisymmetric modes to load), over an autopilot (the SITL aircraft's roll loop writes
  that command itself), beside an aileron step or doublet (the same command) and in a
  campaign (its runs fly the half wing).

The runtime converts them once at the JSBSim boundary (``fcs/elevator-cmd-norm`` through
the aircraft's own rad-per-command scaling, ``fcs/throttle-cmd-norm[i]``); the surface's
travel limits are the flight controls' (the prototype's ±20°). Each command is logged as
the channel ``ctrl_<command>`` (:data:`COMMAND_CHANNELS`), the surface's actual deflection
as ``elevator_rad``.

**Timing.** The row of step k is the airframe's snapshot at t_k (``runtime/coupled_step.py``);
the commands computed from it are written to JSBSim before its step k, whose flight controls
move the surface and whose forces of x_{k+1} act over step k+1. A command therefore reaches
the state one step after the zero-order hold of the LTI model would apply it (the gust does
likewise in the co-simulation): one step of delay, 1.04 ms at 960 Hz, which the closed-loop
LTI prediction carries (:mod:`bioflex_jsb.simulation.closed_loop`). A sensor-fed controller
is a sampled controller with one step of computation delay: at step k it reads the sensors'
sample of t_k (the airframe's x_k, the wing's η_k; its modal acceleration the central
difference with the η_{k+1} the wing has reached before JSBSim's step), and its command first
shows in the sensors' sample of t_{k+1} (the forces of x_{k+1}), never in that of t_k.

Two kinds of controller:

* **a Python object** (:class:`Controller`): ``inputs`` (the signals it reads),
  ``outputs`` (the commands it writes) and ``step(t_s, signals) -> commands`` (``t_s``
  [s] the time since it was bound: the run's start, a SITL session's last reset; mappings by
  name; ``signals`` holds the channels *as the run logs them*: ``u``, ``alpha``, ``theta``
  perturbations from the trim, the others absolute, ``n_z`` 1 in level flight); an optional
  ``reset(trim, dt_s)`` is called once before the first step with every channel's value at
  the trim and the run's step [s];
* **a linear controller** (:class:`LinearController`): a state space with the signals as
  its inputs and the commands as its outputs, discrete (``dt_s`` its sample time: the
  run's step or a whole multiple of it, the commands held between its samples) or
  continuous (discretised at the run's step with a zero-order hold). It reads each signal's
  *perturbation from its trim value* (so its state is 0 at the trim). Loaded from a file
  (:meth:`LinearController.load`: ``.npz`` or ``.toml``, :data:`FILE_KEYS`) or made from
  python-control's ``StateSpace`` (:meth:`LinearController.from_control`) or the package's
  (:meth:`LinearController.from_state_space`); its per-step update is one compiled call
  (:mod:`bioflex_jsb.simulation.controller_kernel`).

Names are checked when a controller is made (an unknown signal or command is one line,
:class:`~bioflex_jsb.errors.InputError`) and again against the run's channels when it is
bound to a run (:class:`ControlLoop`: ``eta4`` of a three-mode wing).
"""

from __future__ import annotations

import io
import json
import math
import re
import zipfile
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Protocol, runtime_checkable

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.files import read_input_bytes
from bioflex_jsb.inputs import (
    Invalid,
    Matrix,
    Names,
    Real,
    Table,
    Text,
    check_keys,
    problem,
    read_table,
)
from bioflex_jsb.simulation.channels import describe
from bioflex_jsb.state_space import StateSpace
from bioflex_jsb.tomlfile import loads_toml

# The commands a controller may write: name → unit (increments over the trim, module
# docstring).
CONTROL_OUTPUTS: dict[str, str] = {"elevator": "rad", "throttle": "-", "flaperon": "rad",
                                   "aileron": "rad"}
# The channel each command is logged as.
COMMAND_CHANNELS: dict[str, str] = {"elevator": "ctrl_elevator_rad", "throttle": "ctrl_throttle",
                                    "flaperon": "ctrl_flaperon_rad",
                                    "aileron": "ctrl_aileron_rad"}
# A controller file is read whole: at most this many bytes (a 10-state controller of a few
# signals is ~2 kB as .npz; 1000 states of double matrices would be 8 MB).
MAX_CONTROLLER_BYTES = 16 * 1024 * 1024
# Keys of a controller file (.npz arrays, or the [controller] table of a .toml): the
# matrices (a, b, c may be absent for a static gain, d alone), the sample time [s] (0:
# continuous), the signal and command names, an optional name and notes (JSON text / table).
FILE_KEYS = ("a", "b", "c", "d", "dt_s", "inputs", "outputs", "name", "notes")
FILE_SUFFIXES = (".npz", ".toml")
# A discrete controller's sample time must be a whole number of the run's steps to this
# relative tolerance (a sample time written as 1/960 in decimal text).
SAMPLE_TIME_RTOL = 1e-9
_LOADS = re.compile(r"loads_.*")


@runtime_checkable
class Controller(Protocol):
    """What the coupled step calls every step (module docstring): ``inputs`` the signals
    read, ``outputs`` the commands written (:data:`CONTROL_OUTPUTS`), ``step(t_s,
    signals)`` [s, SI signals by name] → commands by name (increments over the trim)."""

    inputs: tuple[str, ...]
    outputs: tuple[str, ...]

    def step(self, t_s: float, signals: Mapping[str, float]) -> Mapping[str, float]: ...


def check_signals(names, what: str = "controller") -> tuple[str, ...]:
    """``names`` as a tuple of signals a controller may read (module docstring); else
    InputError, one line: an unknown name, a section load (one step behind), a command
    channel, a duplicate or none at all."""
    out = _name_tuple(names, f"{what} inputs")
    for name in out:
        if _LOADS.fullmatch(name):
            raise InputError(f"{what} input {name!r}: the section loads are computed one step "
                             "behind the steps (a row's pitch acceleration needs the next "
                             "row), so a controller cannot read them")
        if name in COMMAND_CHANNELS.values():
            raise InputError(f"{what} input {name!r} is a controller's own command")
        if describe(name).kind == "unknown" or name == "alpha_inertial":
            raise InputError(f"{what} input {name!r} is not a signal of the run; a "
                             "controller reads the run's channels: u, alpha, q, theta, n_z, "
                             "w_g, airspeed_m_s, ..., eta<i>, eta<i>_dot (docs/api.md)")
    return out


def check_outputs(names, what: str = "controller") -> tuple[str, ...]:
    """``names`` as a tuple of commands (:data:`CONTROL_OUTPUTS`); else InputError."""
    out = _name_tuple(names, f"{what} outputs")
    for name in out:
        if name not in CONTROL_OUTPUTS:
            raise InputError(f"{what} output {name!r} is not a command; accepted: "
                             f"{', '.join(f'{k} [{u}]' for k, u in CONTROL_OUTPUTS.items())}")
    return out


def _name_tuple(names, what: str) -> tuple[str, ...]:
    """``names`` (any iterable but a string) checked by :class:`bioflex_jsb.inputs.Names`;
    InputError ``<what>: <problem>``."""
    if not isinstance(names, str) and hasattr(names, "__iter__"):
        names = tuple(names)
    try:
        return Names().check(names)
    except Invalid as exc:
        raise problem(InputError, "", what, exc.text) from None


def check_controller(controller) -> Controller:
    """``controller`` if it is one (:class:`Controller`: ``inputs``, ``outputs`` and
    ``step``), its names checked; else InputError, one line."""
    if isinstance(controller, LinearController):
        return controller
    if not (callable(getattr(controller, "step", None)) and hasattr(controller, "inputs")
            and hasattr(controller, "outputs")):
        raise InputError(f"a controller has inputs, outputs and step(t_s, signals) "
                         f"(bioflex_jsb.simulation.controller), not {type(controller).__name__}")
    check_signals(controller.inputs)
    check_outputs(controller.outputs)
    return controller


class LinearController:
    """A linear controller (module docstring): ``system`` a :class:`StateSpace` whose
    inputs are signals and whose outputs are commands, discrete (``dt_s`` > 0 [s]) or
    continuous (``dt_s`` None); ``name`` what it is called in logs and tables.

    As a :class:`Controller` (the readable reference of the compiled update, and what a
    caller steps by hand): :meth:`reset` before the first step, then :meth:`step` every step
    of the run."""

    def __init__(self, system: StateSpace, name: str = "linear") -> None:
        if not isinstance(system, StateSpace):
            raise InputError(f"a linear controller's system is a StateSpace, not "
                             f"{type(system).__name__}")
        check_signals(system.inputs)
        check_outputs(system.outputs)
        for key in "abcd":
            if not np.all(np.isfinite(np.asarray(getattr(system, key), dtype=float))):
                raise InputError(f"controller {name!r}: its {key.upper()} matrix has a "
                                 "non-finite entry")
        self.system = system
        self.name = str(name)
        self._state: _Reference | None = None

    # -- what it is -------------------------------------------------------------------------
    @property
    def inputs(self) -> tuple[str, ...]:
        return self.system.inputs

    @property
    def outputs(self) -> tuple[str, ...]:
        return self.system.outputs

    @property
    def n_states(self) -> int:
        return self.system.n_states

    @property
    def dt_s(self) -> float | None:
        """Sample time [s]; None: continuous."""
        return self.system.dt_s

    def __repr__(self) -> str:
        kind = "continuous" if self.dt_s is None else f"dt {self.dt_s:g} s"
        return (f"LinearController({self.name!r}, {self.n_states} states, {kind}, "
                f"inputs {list(self.inputs)}, outputs {list(self.outputs)})")

    def at_step(self, dt_s: float) -> tuple[StateSpace, int]:
        """(the discrete system it runs as, its sample time in run steps) at the run's step
        ``dt_s`` [s]: a continuous controller discretised with a zero-order hold at the
        step (every step); a discrete one as it is, every ``dt_s``/step steps (a whole
        number, else InputError)."""
        dt = float(dt_s)
        if self.dt_s is None:
            return self.system.to_discrete(dt), 1
        ratio = self.dt_s / dt
        every = int(round(ratio))
        if every < 1 or abs(ratio - every) > SAMPLE_TIME_RTOL * ratio:
            raise InputError(f"controller {self.name!r} samples every {self.dt_s:g} s, not a "
                             f"whole number of the run's steps of {dt:g} s")
        return self.system, every

    # -- made from ----------------------------------------------------------------------------
    @classmethod
    def from_arrays(cls, a, b, c, d, dt_s: float | None, inputs, outputs,
                    name: str = "linear", notes: Mapping | None = None) -> LinearController:
        """From its matrices (``a`` (n, n), ``b`` (n, m), ``c`` (p, n), ``d`` (p, m); a
        static gain has n = 0: ``a``, ``b``, ``c`` None), ``dt_s`` [s] (None or 0:
        continuous), the ``inputs`` (signals) and ``outputs`` (commands)."""
        inputs, outputs = check_signals(inputs), check_outputs(outputs)
        m, p = len(inputs), len(outputs)
        try:
            d = np.atleast_2d(np.asarray(d, dtype=float))
            if d.shape != (p, m) and d.size == p * m and 1 in (p, m):
                d = d.reshape(p, m)  # one row or one column written flat
            n = 0 if a is None else int(np.atleast_2d(np.asarray(a, dtype=float)).shape[0])
            a = np.zeros((n, n)) if a is None else np.asarray(a, dtype=float).reshape(n, n)
            b = np.zeros((n, m)) if b is None else np.asarray(b, dtype=float).reshape(n, m)
            c = np.zeros((p, n)) if c is None else np.asarray(c, dtype=float).reshape(p, n)
        except (TypeError, ValueError) as exc:
            raise InputError(f"controller {name!r}: its matrices do not fit {m} inputs and "
                             f"{p} outputs ({' '.join(str(exc).split())})") from None
        if d.shape != (p, m):
            raise InputError(f"controller {name!r}: D is {d.shape}, expected ({p}, {m}) for "
                             f"{m} inputs and {p} outputs")
        dt = _sample_time(dt_s, name)
        system = StateSpace(
            model="controller", speed_m_s=0.0, a=a, b=b, c=c, d=d,
            states=tuple(f"x{i + 1}" for i in range(n)), state_units=("-",) * n,
            inputs=inputs, input_units=tuple(describe(s).unit for s in inputs),
            outputs=outputs, output_units=tuple(CONTROL_OUTPUTS[o] for o in outputs),
            notes=dict(notes or {}), dt_s=dt)
        return cls(system, name)

    @classmethod
    def from_state_space(cls, system: StateSpace, name: str | None = None) -> LinearController:
        """From the package's :class:`StateSpace` (its input and output names the signals and
        commands)."""
        if not isinstance(system, StateSpace):
            raise InputError(f"give a StateSpace, not {type(system).__name__}")
        return cls.from_arrays(system.a, system.b, system.c, system.d, system.dt_s,
                               system.inputs, system.outputs, name or system.model,
                               system.notes)

    @classmethod
    def from_control(cls, system, name: str | None = None) -> LinearController:
        """From python-control's ``StateSpace`` (or a transfer function it converts): its
        ``input_labels`` and ``output_labels`` are the signals and commands, its ``dt`` 0
        (continuous) or a sample time [s] (``dt=True``, an unspecified sample time, is
        refused)."""
        try:
            import control
        except ImportError:
            raise InputError("python-control is not installed: pip install "
                             "'bioflex-jsb[control]'") from None
        if isinstance(system, control.TransferFunction):
            system = control.ss(system)
        if not isinstance(system, control.StateSpace):
            raise InputError(f"give python-control's StateSpace, not {type(system).__name__}")
        dt = system.dt
        if dt is True:
            raise InputError("the controller is discrete with an unspecified sample time "
                             "(dt=True): give its dt [s]")
        return cls.from_arrays(system.A, system.B, system.C, system.D,
                               None if dt is None else float(dt), system.input_labels,
                               system.output_labels, name or system.name or "linear")

    def to_control(self):
        """This controller as python-control's ``StateSpace`` (named signals)."""
        return self.system.to_control()

    # -- files ------------------------------------------------------------------------------
    @classmethod
    def load(cls, path: str | Path) -> LinearController:
        """Read a controller file (``.npz`` arrays or a ``.toml`` ``[controller]`` table,
        keys :data:`FILE_KEYS`, :class:`ControllerFile`; at most
        :data:`MAX_CONTROLLER_BYTES`, a regular file); every problem is one line
        (InputError) naming the file and the key."""
        p = Path(path)
        if p.suffix.lower() not in FILE_SUFFIXES:
            raise InputError(f"controller file {str(p)!r}: give a .npz or .toml file")
        data = read_input_bytes(p, "controller file", MAX_CONTROLLER_BYTES, InputError)
        source = f"controller file {str(p)!r}"
        if p.suffix.lower() == ".npz":
            table = read_table(ControllerFile, _npz_fields(data, source), source, InputError)
        else:
            table = read_table(ControllerFile, _toml_table(data, source), source, InputError,
                               "controller")
        states = [k for k in "abc" if getattr(table, k) is not None]
        if states and len(states) != 3:
            raise InputError(f"{source}: a, b and c go together (a static gain has d alone)")
        name = table.name.strip() or p.stem
        try:
            return cls.from_arrays(table.a, table.b, table.c, table.d, table.dt_s,
                                   table.inputs, table.outputs, name, table.notes or {})
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None

    def save(self, path: str | Path, overwrite: bool = False) -> Path:
        """Write this controller to ``path`` (``.npz`` or ``.toml``, as :meth:`load` reads);
        an existing file only with ``overwrite``."""
        p = Path(path)
        if p.suffix.lower() not in FILE_SUFFIXES:
            raise InputError(f"controller file {str(p)!r}: give a .npz or .toml name")
        if p.exists() and not overwrite:
            raise InputError(f"{str(p)!r} exists: not overwritten")
        s = self.system
        dt = 0.0 if s.dt_s is None else float(s.dt_s)
        if p.suffix.lower() == ".npz":
            with open(p, "wb") as fh:
                np.savez(fh, a=s.a, b=s.b, c=s.c, d=s.d, dt_s=np.float64(dt),
                         inputs=np.array(s.inputs), outputs=np.array(s.outputs),
                         name=np.array(self.name), notes=np.array(json.dumps(s.notes)))
        else:
            p.write_text(_toml_text(self, dt), encoding="utf-8")
        return p

    # -- the reference step (module docstring) ----------------------------------------------
    def reset(self, trim: Mapping[str, float], dt_s: float) -> None:
        """Start at the trim: state 0, the inputs' trim values (``trim``: every channel at
        the trim) as the offsets the signals are read from, the run's step ``dt_s`` [s]."""
        system, every = self.at_step(dt_s)
        offsets = np.array([float(trim[s]) for s in self.inputs])
        self._state = _Reference(system, every, offsets)

    def step(self, t_s: float, signals: Mapping[str, float]) -> dict[str, float]:
        """One step of the run (after :meth:`reset`): the commands by name (held between the
        controller's samples)."""
        r = self._state
        if r is None:
            raise RuntimeError("LinearController.step before reset(trim, dt_s)")
        if r.count == 0:
            u = np.array([float(signals[s]) for s in self.inputs]) - r.offsets
            r.y = r.system.c @ r.x + r.system.d @ u
            r.x = r.system.a @ r.x + r.system.b @ u
        r.count = (r.count + 1) % r.every
        return dict(zip(self.outputs, r.y.tolist(), strict=True))


class ControllerFile(Table):
    """The keys of a controller file (:data:`FILE_KEYS`), checked by the one validator
    (:mod:`bioflex_jsb.inputs`): the matrices (``a``, ``b``, ``c`` together or absent: a
    static gain), the sample time [s] (0: continuous), the signals read and the commands
    written, a name and notes (a table; JSON text in an .npz)."""

    a: Matrix().type() | None = None
    b: Matrix().type() | None = None
    c: Matrix().type() | None = None
    d: Matrix().type()
    dt_s: Real("s", 0.0, hint=" (0: continuous, else the sample time)").type()
    inputs: Names().type()
    outputs: Names().type()
    name: Text(empty=True).type() = ""
    notes: dict | None = None


class _Reference:
    """The reference step's state: the discrete system, its sample in steps, the input
    offsets, x, the held output and the steps to the next sample."""

    def __init__(self, system: StateSpace, every: int, offsets: np.ndarray) -> None:
        self.system, self.every, self.offsets = system, every, offsets
        self.x = np.zeros(system.n_states)
        self.y = np.zeros(len(system.outputs))
        self.count = 0


def _sample_time(dt_s, name: str) -> float | None:
    """None (continuous) for None or 0; a positive finite sample time [s]; else InputError."""
    if dt_s is None:
        return None
    try:
        dt = float(np.asarray(dt_s, dtype=float).reshape(-1)[0])
    except (TypeError, ValueError, IndexError):
        raise InputError(f"controller {name!r}: dt_s must be a number [s], got {dt_s!r}") \
            from None
    if not math.isfinite(dt) or dt < 0.0:
        raise InputError(f"controller {name!r}: dt_s must be 0 (continuous) or a sample time "
                         f"> 0 s, got {dt!r}")
    return None if dt == 0.0 else dt


def _npz_fields(data: bytes, source: str) -> dict:
    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as z:
            out = {k: z[k] for k in z.files}
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as exc:
        raise InputError(f"{source} is not a controller .npz: "
                         f"{exc or type(exc).__name__}") from None
    for key in ("inputs", "outputs"):
        if key in out:
            out[key] = [str(x) for x in np.asarray(out[key]).reshape(-1)]
    for key in ("name", "notes"):
        if key in out:
            out[key] = str(np.asarray(out[key]).reshape(-1)[0]) if np.size(out[key]) else ""
    if out.get("notes"):
        try:
            out["notes"] = json.loads(out["notes"])
        except ValueError:
            raise InputError(f"{source}: its notes are not JSON") from None
        if not isinstance(out["notes"], dict):
            raise InputError(f"{source}: its notes are not a JSON object")
    if "dt_s" in out and np.size(out["dt_s"]) == 1:
        out["dt_s"] = np.asarray(out["dt_s"]).reshape(-1)[0].item()  # a Python scalar
    return out


def _toml_table(data: bytes, source: str) -> object:
    """The ``[controller]`` table of a .toml controller file (its keys are the
    :class:`ControllerFile`'s to check); InputError if the file holds another table."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(f"{source} is not UTF-8 text") from None
    doc = loads_toml(text, source, InputError)
    try:
        check_keys(doc, ("controller",))
    except Invalid as exc:
        raise problem(InputError, source, "", exc.text) from None
    if "controller" not in doc:
        raise problem(InputError, source, "controller", "missing table")
    return doc["controller"]


def _toml_text(controller: LinearController, dt_s: float) -> str:
    s = controller.system

    def matrix(m) -> str:
        return "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]"
                               for row in np.asarray(m)) + "]"

    lines = ["[controller]", f"name = {json.dumps(controller.name)}",
             f"dt_s = {dt_s!r}  # [s]; 0: continuous",
             f"inputs = {json.dumps(list(s.inputs))}",
             f"outputs = {json.dumps(list(s.outputs))}"]
    if s.n_states:
        lines += [f"a = {matrix(s.a)}", f"b = {matrix(s.b)}", f"c = {matrix(s.c)}"]
    lines.append(f"d = {matrix(s.d)}")
    notes = {k: v for k, v in s.notes.items() if isinstance(v, str | int | float | bool)}
    if notes:
        lines.append("[controller.notes]")
        lines += [f"{json.dumps(k)} = {json.dumps(v)}" for k, v in notes.items()]
    return "\n".join(lines) + "\n"


# The controllers shipped with the package (by name: ``--controller gla_optimised``), each
# a .toml file here with its design in its notes (scripts/design_gla.py writes them).
SHIPPED_DIR = Path(__file__).resolve().parent.parent / "data" / "controllers"


def shipped_controllers() -> tuple[str, ...]:
    """The names of the shipped controller files."""
    return tuple(sorted(p.stem for p in SHIPPED_DIR.glob("*.toml")))


def controller_path(source: str | Path) -> Path:
    """The file of ``source``: a path, or the name of a shipped controller; InputError (one
    line) for neither."""
    p = Path(source)
    if p.suffix or p.exists() or str(source) not in shipped_controllers():
        if not p.suffix and not p.exists():
            raise InputError(f"no controller {str(source)!r}: give a .npz or .toml file or a "
                             f"shipped controller ({', '.join(shipped_controllers())})")
        return p
    return SHIPPED_DIR / f"{source}.toml"


def load_controller(source) -> Controller:
    """A controller from ``source``: a controller file's path (:meth:`LinearController.load`)
    or a shipped controller's name (:func:`shipped_controllers`), a
    :class:`LinearController`, the package's :class:`StateSpace`, python-control's
    ``StateSpace`` or any object with ``inputs``, ``outputs`` and ``step`` (checked)."""
    if isinstance(source, str | Path):
        return LinearController.load(controller_path(source))
    if isinstance(source, StateSpace):
        return LinearController.from_state_space(source)
    module = type(source).__module__ or ""
    if module.split(".")[0] == "control":
        return LinearController.from_control(source)
    return check_controller(source)


class ControlLoop:
    """A controller bound to a run (module docstring): ``names`` the run's channels (the
    table's columns, the command channels among them), ``dt_s`` [s] its step, ``trim``
    every channel's value at the trim. :meth:`step` ``(table, k)`` reads row k's signals,
    writes the commands into row k's command columns and returns them in the controller's
    output order. A :class:`LinearController` runs as one compiled call
    (:mod:`bioflex_jsb.simulation.controller_kernel`; ``binding`` its
    :class:`~bioflex_jsb.simulation.controller_kernel.LinearBinding`, which the runtime
    calls directly; ``compiled=False``: its reference :meth:`LinearController.step`,
    ``binding`` None)."""

    def __init__(self, controller, names: tuple[str, ...], dt_s: float,
                 trim: Mapping[str, float], compiled: bool = True) -> None:
        controller = check_controller(controller)
        missing = [s for s in controller.inputs if s not in names]
        if missing:
            eta = sum(1 for n in names if re.fullmatch(r"eta\d+", n))
            raise InputError(f"the run has no channel {missing[0]!r} for the controller to "
                             f"read (its wing has {eta} modes)")
        self.controller = controller
        self.outputs = tuple(controller.outputs)
        self.command_names = tuple(COMMAND_CHANNELS[o] for o in self.outputs)
        self.in_cols = [names.index(s) for s in controller.inputs]
        self.out_cols = [names.index(c) for c in self.command_names]
        self.dt_s = float(dt_s)
        self.n_states = getattr(controller, "n_states", None)
        self.binding = None
        linear = isinstance(controller, LinearController)
        if linear and compiled:
            from bioflex_jsb.simulation.controller_kernel import LinearBinding

            system, every = controller.at_step(dt_s)
            offsets = [float(trim[s]) for s in controller.inputs]
            self.binding = LinearBinding(system, every, offsets, self.in_cols, self.out_cols)
            self.step = self.binding.step
            return
        reset = getattr(controller, "reset", None)
        if callable(reset):
            reset(MappingProxyType(dict(trim)), self.dt_s)
        self.step = self._python_step
        self._inputs = tuple(controller.inputs)
        self._steps = 0  # steps stepped: the controller's clock (a row k may be a scratch row)

    def _python_step(self, table: np.ndarray, k: int) -> tuple[float, ...]:
        row = table[k]
        signals = dict(zip(self._inputs, row[self.in_cols].tolist(), strict=True))
        t_s = self._steps * self.dt_s  # since it was bound: the run's start, a SITL reset
        self._steps += 1
        commands = self.controller.step(t_s, signals)
        try:
            values = tuple(float(commands[o]) for o in self.outputs)
        except (KeyError, TypeError, ValueError):
            raise InputError(f"controller {type(self.controller).__name__} returned "
                             f"{commands!r} at t = {t_s:.6f} s; expected a number "
                             f"for each of {list(self.outputs)}") from None
        if not all(math.isfinite(v) for v in values):
            raise InputError(f"controller {type(self.controller).__name__} commanded "
                             f"{dict(zip(self.outputs, values, strict=True))} at t = "
                             f"{t_s:.6f} s: not finite")
        row[self.out_cols] = values
        return values



def controller_meta(loop: ControlLoop) -> dict[str, object]:
    """What a run's controller was (a history's ``meta["controller"]``, the log's): its
    name, kind, signals read, commands written and their channels, states and sample time
    [s] (a linear controller's; None: every step, or a Python object's own)."""
    c = loop.controller
    linear = isinstance(c, LinearController)
    return {"name": c.name if linear else type(c).__name__,
            "kind": "linear" if linear else "python",
            "inputs": list(c.inputs), "outputs": list(loop.outputs),
            "channels": list(loop.command_names),
            "n_states": c.n_states if linear else None,
            "dt_s": (c.dt_s if linear else None)}
