"""The controller interface (bioflex_jsb.simulation.controller): names checked at load and at
bind, the file formats (.npz, .toml) round trip, python-control in and out, the compiled
update against the readable reference, sample times, and a controller in a coupled run
(its commands in the row, the surface one step later, the Python and compiled steps)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb.errors import InputError
from bioflex_jsb.simulation.controller import (
    COMMAND_CHANNELS,
    ControlLoop,
    LinearController,
    check_controller,
    load_controller,
)
from bioflex_jsb.state_space import StateSpace

NAMES = ("u", "alpha", "q", "theta", "n_z", "eta1", "eta1_dot", "ctrl_elevator_rad",
         "ctrl_throttle")
TRIM = {"u": 1e-7, "alpha": 0.0, "q": 0.0, "theta": 0.0, "n_z": 1.0003, "eta1": 0.0,
        "eta1_dot": 0.0, "ctrl_elevator_rad": 0.0, "ctrl_throttle": 0.0}
DT = 1.0 / 960.0


def _random(n: int = 10, m: int = 3, p: int = 2, seed: int = 3, dt=DT) -> LinearController:
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(n, n))
    a *= 0.9 / max(abs(np.linalg.eigvals(a)))  # a stable discrete controller
    inputs = ("q", "alpha", "n_z", "eta1")[:m]
    outputs = ("elevator", "throttle")[:p]
    return LinearController.from_arrays(a, rng.normal(size=(n, m)), rng.normal(size=(p, n)),
                                        rng.normal(size=(p, m)), dt, inputs, outputs, "rand")


@pytest.mark.parametrize("inputs, fragment", [
    (["q", "bogus"], "'bogus' is not a signal of the run"),
    (["loads_fs_bending_n_m_s0"], "one step behind"),
    (["ctrl_elevator_rad"], "a controller's own command"),
    (["q", "q"], "'q' more than once"),
    ([], "none given"),
    ("q", "must be a list of names"),
    (["alpha_inertial"], "not a signal of the run"),
])
def test_unknown_signals_are_one_line(inputs, fragment):
    with pytest.raises(InputError) as exc:
        LinearController.from_arrays(None, None, None, np.zeros((1, max(1, len(inputs)))),
                                     DT, inputs, ["elevator"])
    assert fragment in str(exc.value) and "\n" not in str(exc.value)


def test_unknown_command_is_one_line():
    with pytest.raises(InputError, match="'rudder' is not a command; accepted: elevator"):
        LinearController.from_arrays(None, None, None, [[1.0]], DT, ["q"], ["rudder"])


@pytest.mark.parametrize("d, dt, fragment", [
    ([[1.0, 2.0, 3.0]], DT, "D is (1, 3), expected (1, 2)"),
    ([[1.0, 2.0]], -1.0, "dt_s must be 0 (continuous) or a sample time"),
    ([[1.0, math.nan]], DT, "non-finite"),
])
def test_bad_matrices(d, dt, fragment):
    with pytest.raises(InputError) as exc:
        LinearController.from_arrays(None, None, None, d, dt, ["q", "alpha"], ["elevator"])
    assert fragment in str(exc.value)


@pytest.mark.parametrize("suffix", [".npz", ".toml"])
def test_file_round_trip(tmp_path, suffix):
    c = _random()
    path = c.save(tmp_path / f"c{suffix}")
    back = LinearController.load(path)
    assert back.inputs == c.inputs and back.outputs == c.outputs and back.name == "rand"
    assert back.dt_s == c.dt_s
    for key in "abcd":  # repr() of a float round-trips exactly in TOML too
        assert np.array_equal(getattr(back.system, key), getattr(c.system, key))
    with pytest.raises(InputError, match="exists: not overwritten"):
        c.save(path)


def test_toml_static_gain(tmp_path):
    path = tmp_path / "gain.toml"
    path.write_text('[controller]\ndt_s = 0\ninputs = ["alpha", "q"]\n'
                    'outputs = ["elevator"]\nd = [[2.0, 0.1]]\n')
    c = LinearController.load(path)
    assert c.n_states == 0 and c.dt_s is None and c.name == "gain"
    assert np.array_equal(c.system.d, [[2.0, 0.1]])


@pytest.mark.parametrize("text, fragment", [
    # the one validator's wording (bioflex_jsb.inputs): <file>: <table>: <problem>
    ('[controller]\ndt_s = 0\ninputs = ["q"]\noutputs = ["elevator"]\nd = [[1.0]]\n'
     'gain = 3\n', "c.toml': controller: unknown key 'gain'; accepted: a, b, c, d, dt_s, "
     "inputs, name, notes, outputs"),
    ('[controller]\ndt_s = 0\ninputs = ["q"]\noutputs = ["elevator"]\nd = [[1.0]]\n'
     'gain = 3\nk = 1\n', "unknown key 'gain'; accepted: a, b, c, d, dt_s, inputs, name, "
     "notes, outputs (and 1 more problem)"),
    ('[controller]\ndt_s = 0\ninputs = ["q"]\noutputs = ["elevator"]\n',
     "controller.d: missing (a list of rows of numbers)"),
    ('[controller]\ndt_s = -1\ninputs = "q"\noutputs = ["elevator"]\n',
     "controller.d: missing (a list of rows of numbers) (and 2 more problems)"),
    ('[controller]\ndt_s = 0\ninputs = ["q"]\noutputs = ["elevator"]\nd = [[1.0]]\n'
     'a = [[1.0]]\n', "a, b and c go together"),
    ('[controller]\ndt_s = 0\ninputs = ["q"]\noutputs = ["elevator"]\nd = [["x"]]\n',
     "controller.d: must be a list of rows of numbers, got [['x']]"),
    ('[controller]\ndt_s = 0\ninputs = ["q"]\noutputs = ["elevator"]\nd = [[1.0], []]\n',
     "controller.d: its rows differ in length (1, 0 numbers)"),
    ('[controller]\ndt_s = -0.5\ninputs = ["q"]\noutputs = ["elevator"]\nd = [[1.0]]\n',
     "controller.dt_s: must be ≥ 0 s, got -0.5 (0: continuous, else the sample time)"),
    ('[controller]\ndt_s = true\ninputs = ["q"]\noutputs = ["elevator"]\nd = [[1.0]]\n',
     "controller.dt_s: must be a finite number in s, got True"),
    ('[controller]\ndt_s = 0\ninputs = ["q", "q"]\noutputs = ["elevator"]\nd = [[1.0]]\n',
     "controller.inputs: name 'q' more than once"),
    ('[controller]\ndt_s = 0\ninputs = ["q"]\noutputs = ["elevator"]\nd = [[1.0]]\n'
     'notes = 3\n', "controller.notes: must be a table"),
    ('[controller]\ndt_s = 0\ninputs = ["q"]\noutputs = ["elevator"]\nd = [[1.0]]\n'
     'name = "a\\nb"\n', "controller.name: holds a control character"),
    ('[other]\nx = 1\n', "c.toml': unknown key 'other'; accepted: controller"),
    ('x = 1\n', "c.toml': unknown key 'x'; accepted: controller"),
    ('', "c.toml': controller: missing table"),
    ('controller = 3\n', "c.toml': controller: must be a table"),
    ('[controller\n', "is not valid TOML"),
    ('[controller]\ndt_s = 0\ninputs = ["eta9x"]\noutputs = ["elevator"]\nd = [[1.0]]\n',
     "'eta9x' is not a signal"),
])
def test_bad_toml_files(tmp_path, text, fragment):
    path = tmp_path / "c.toml"
    path.write_text(text)
    with pytest.raises(InputError) as exc:
        LinearController.load(path)
    assert fragment in str(exc.value) and "\n" not in str(exc.value)
    assert str(path) in str(exc.value)


def test_bad_npz_and_other_files(tmp_path):
    junk = tmp_path / "c.npz"
    junk.write_bytes(b"not a zip")
    with pytest.raises(InputError, match="is not a controller .npz"):
        LinearController.load(junk)
    with pytest.raises(InputError, match="give a .npz or .toml file"):
        LinearController.load(tmp_path / "c.txt")
    with pytest.raises(InputError, match="not found"):
        LinearController.load(tmp_path / "missing.npz")
    (tmp_path / "dir.npz").mkdir()
    with pytest.raises(InputError, match="not a regular file"):
        LinearController.load(tmp_path / "dir.npz")
    np.savez(tmp_path / "pickled.npz", d=np.array([object()], dtype=object))
    with pytest.raises(InputError):  # object arrays need pickle: refused, one line
        LinearController.load(tmp_path / "pickled.npz")



def _npz(path, **arrays):
    base = {"d": np.array([[1.0]]), "dt_s": np.float64(0.0), "inputs": np.array(["q"]),
            "outputs": np.array(["elevator"])}
    base.update(arrays)
    np.savez(path, **{k: v for k, v in base.items() if v is not None})
    return path


@pytest.mark.parametrize("arrays, needle", [
    ({"gain": np.array(3.0)}, "c.npz': unknown key 'gain'; accepted: a, b, c, d, dt_s, "
     "inputs, name, notes, outputs"),
    ({"gain": np.array(3.0), "k": np.array(1.0), "dt_s": None},
     "unknown key 'gain'; accepted: a, b, c, d, dt_s, inputs, name, notes, outputs "
     "(and 2 more problems)"),
    ({"d": np.array([["x"]])}, "c.npz': d: must be a matrix of numbers, got an array of <U1"),
    ({"d": None}, "c.npz': d: missing (a list of rows of numbers)"),
    ({"dt_s": np.float64(-1.0)}, "c.npz': dt_s: must be ≥ 0 s, got -1.0"),
    ({"inputs": np.array([], dtype=str)}, "c.npz': inputs: none given"),
])
def test_bad_npz_keys_are_one_line(tmp_path, arrays, needle):
    path = _npz(tmp_path / "c.npz", **arrays)
    with pytest.raises(InputError) as exc:
        LinearController.load(path)
    assert needle in str(exc.value) and "\n" not in str(exc.value)


def test_npz_static_gain_reads(tmp_path):
    c = LinearController.load(_npz(tmp_path / "c.npz"))
    assert c.n_states == 0 and c.dt_s is None and c.name == "c"

def test_python_control_in_and_out():
    control = pytest.importorskip("control")
    c = _random(n=4, m=2, p=1)
    sys_c = c.to_control()
    assert list(sys_c.input_labels) == ["q", "alpha"]
    back = LinearController.from_control(sys_c)
    assert np.array_equal(back.system.a, c.system.a) and back.dt_s == c.dt_s
    # a continuous lead filter from a transfer function, its labels set
    tf = control.tf([0.05, 1.0], [0.005, 1.0], inputs=["q"], outputs=["elevator"])
    lead = load_controller(tf)
    assert lead.dt_s is None and lead.n_states == 1
    with pytest.raises(InputError, match="unspecified sample time"):
        LinearController.from_control(control.ss([[0.5]], [[1]], [[1]], [[0]], True,
                                                 inputs=["q"], outputs=["elevator"]))


def test_compiled_update_equals_reference():
    """The compiled update and LinearController.step, fed the same rows: the commands agree
    to rounding (different summation order), held between samples of a slower controller."""
    rng = np.random.default_rng(7)
    for every in (1, 3):
        c = _random(m=3, p=2, dt=DT * every)
        fast = ControlLoop(c, NAMES, DT, TRIM, compiled=True)
        ref = ControlLoop(c, NAMES, DT, TRIM, compiled=False)
        table = rng.normal(size=(40, len(NAMES)))
        table2 = table.copy()
        for k in range(40):
            y1, y2 = fast.step(table, k), ref.step(table2, k)
            assert np.allclose(y1, y2, rtol=1e-12, atol=1e-12)
        cols = [NAMES.index(COMMAND_CHANNELS[o]) for o in c.outputs]
        assert np.allclose(table[:, cols], table2[:, cols], rtol=1e-12, atol=1e-12)
        held = table[:, cols[0]]
        if every == 3:  # held between samples
            assert held[0] == held[1] == held[2] and held[3] == held[4] == held[5]


def test_reference_is_the_difference_equation():
    """x[k+1] = A x + B u, y = C x + D u with u = signals − trim, by hand."""
    c = _random(n=2, m=1, p=1)
    c.reset({"q": 0.25}, DT)
    a, b, cc, d = (getattr(c.system, k) for k in "abcd")
    x = np.zeros(2)
    for q in (0.3, -0.1, 0.7):
        u = np.array([q - 0.25])
        want = cc @ x + d @ u
        x = a @ x + b @ u
        assert c.step(0.0, {"q": q})["elevator"] == pytest.approx(float(want[0]), rel=1e-14)


def test_continuous_controller_is_discretised_and_sample_times_checked():
    lag = LinearController.from_arrays([[-10.0]], [[10.0]], [[1.0]], [[0.0]], 0.0, ["q"],
                                       ["elevator"])
    system, every = lag.at_step(DT)
    assert every == 1 and system.a[0, 0] == pytest.approx(math.exp(-10.0 * DT), rel=1e-14)
    slow = _random(dt=4 * DT)
    assert slow.at_step(DT)[1] == 4
    with pytest.raises(InputError, match="not a whole number of the run's steps"):
        _random(dt=1.5 * DT).at_step(DT)


def test_bind_checks_the_run_channels():
    c = LinearController.from_arrays(None, None, None, [[1.0]], DT, ["eta4"], ["elevator"])
    with pytest.raises(InputError, match="no channel 'eta4'.*its wing has 1 modes"):
        ControlLoop(c, NAMES, DT, TRIM)


class _Gain:
    """A Python controller: δe = k (q − trim q), its trim from reset."""

    inputs = ("q", "n_z")
    outputs = ("elevator",)

    def __init__(self, k: float, bad: object = None) -> None:
        self.k, self.bad, self.trim = k, bad, None

    def reset(self, trim, dt_s):
        self.trim = dict(trim)

    def step(self, t_s, signals):
        if self.bad is not None:
            return self.bad
        return {"elevator": self.k * (signals["q"] - self.trim["q"])}


def test_python_controller():
    g = _Gain(0.5)
    loop = ControlLoop(g, NAMES, DT, TRIM)
    assert g.trim["n_z"] == TRIM["n_z"]
    table = np.zeros((2, len(NAMES)))
    table[1, NAMES.index("q")] = 0.2
    assert loop.step(table, 1) == (0.1,)
    assert table[1, NAMES.index("ctrl_elevator_rad")] == 0.1
    for bad, fragment in (({"thrust": 1.0}, "expected a number for each of ['elevator']"),
                          ({"elevator": math.inf}, "not finite")):
        loop = ControlLoop(_Gain(0.5, bad), NAMES, DT, TRIM)
        with pytest.raises(InputError, match=fragment.replace("[", r"\[").replace("]", r"\]")):
            loop.step(table, 1)
    with pytest.raises(InputError, match="a controller has inputs, outputs and step"):
        check_controller(object())


def test_state_space_source():
    ss = StateSpace(model="gla", speed_m_s=15.0, a=np.zeros((0, 0)), b=np.zeros((0, 2)),
                    c=np.zeros((1, 0)), d=np.array([[2.0, 0.1]]), states=(), state_units=(),
                    inputs=("alpha", "q"), input_units=("rad", "rad/s"),
                    outputs=("elevator",), output_units=("rad",), dt_s=DT)
    c = load_controller(ss)
    assert isinstance(c, LinearController) and c.name == "gla" and c.n_states == 0
