"""Stop signals that land where Python cannot raise (docs/reliability.md, "Runs, logs and
signals"): inside a JSBSim callback into Python (its logger) and inside an import. Each must
end the command with exit 130 and one line, like a signal anywhere else.

The fast tests send the signal from inside the callback itself (deterministic); the slow
test sends SIGINT/SIGTERM at random moments to real ``gust`` and ``sitl`` processes."""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from bioflex_jsb import interrupts

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable

HARNESS = """
import os, signal, sys, time
sys.argv = ["bioflex-jsb", *sys.argv[1:]]
{patch}
from bioflex_jsb.cli import main
sys.exit(main())
"""

# A wrapper around one method of the logger JSBSim calls back: on its N-th call it sends
# the signal to this process and keeps running Python code inside the callback (the
# handler runs at the next bytecode boundary, here: inside the callback). The wrapper is
# itself marked as a native callback, as every function JSBSim calls must be.
IN_CALLBACK = """
from bioflex_jsb.interrupts import native_callback
from bioflex_jsb.runtime import jsbsim_log as _jl
_orig = getattr(_jl.CapturingLogger, {method!r})
_n = [0]
@native_callback
def _wrapped(self, *a):
    _n[0] += 1
    if _n[0] == {nth}:
        os.kill(os.getpid(), signal.{sig})
        for _ in range(1000):  # many bytecode boundaries inside the callback
            pass
    return _orig(self, *a)
setattr(_jl.CapturingLogger, {method!r}, _wrapped)
"""


def env(**extra) -> dict[str, str]:
    e = dict(os.environ)
    e.update({"PYTHONPATH": str(ROOT), "PYTHONUNBUFFERED": "1", **extra})
    return e


def harness(tmp_path: Path, patch: str, *argv, timeout=300):
    script = tmp_path / "harness.py"
    script.write_text(HARNESS.format(patch=textwrap.dedent(patch)))
    return subprocess.run([PY, str(script), *map(str, argv)], capture_output=True, text=True,
                          timeout=timeout, env=env(BIOFLEX_LOG_DIR=str(tmp_path / "logs")))


def one_line(err: str) -> str:
    lines = [x for x in err.strip().splitlines() if x.strip()]
    assert len(lines) == 1, err[-3000:]
    assert "Traceback" not in err and "SystemError" not in err
    return lines[0]


GUST = ["gust", "--duration", "2", "--gust-start", "0.1", "--models", "rigid", "--json",
        "--plot", ""]


def test_every_method_jsbsim_calls_back_is_marked_a_native_callback():
    """JSBSim calls these FGLogger methods from C++; a new override left unmarked would bring
    the SystemError back."""
    import jsbsim

    from bioflex_jsb.runtime.jsbsim_log import CapturingLogger

    called_back = [n for n in dir(jsbsim.FGLogger) if not n.startswith("_")]
    overridden = [n for n in called_back if n in vars(CapturingLogger)]
    assert set(overridden) >= {"set_level", "message", "flush"}, overridden
    unmarked = [n for n in overridden
                if not interrupts.is_native_callback(getattr(CapturingLogger, n))]
    assert not unmarked, unmarked


# (method, which call): set_level's 200th call falls in the trim (JSBSim logs through it on
# every run() call, trims included); flush's 1500th in the loop of the 2 s rigid run
# (one call per step of 1 ms, after ~500 in the trim); message's 20th in the model load/trim.
@pytest.mark.parametrize("method,nth", [("set_level", 200), ("flush", 1500), ("message", 20)])
@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_signal_inside_a_jsbsim_callback_exits_130_in_one_line(tmp_path, method, nth, sig):
    patch = IN_CALLBACK.format(method=method, nth=nth, sig=sig)
    t0 = time.monotonic()
    r = harness(tmp_path, patch, *GUST)
    assert r.returncode == 130, r.stderr[-3000:]
    assert "interrupted" in one_line(r.stderr)
    # the stop is prompt: the run ends at the next step or the end of JSBSim's call, not
    # after the 2 s flight would have finished (a run of GUST takes ~4 s unloaded)
    assert time.monotonic() - t0 < 120


def test_signal_inside_a_jsbsim_callback_during_a_sitl_session(tmp_path):
    patch = IN_CALLBACK.format(method="flush", nth=3000, sig="SIGTERM")
    t0 = time.monotonic()
    r = harness(tmp_path, patch, "sitl", "--mavlink", "udpin:127.0.0.1:0", "--speedup", "4",
                "--json", "--duration", "600", "--no-log", timeout=300)
    assert r.returncode == 130, r.stderr[-3000:]
    assert "interrupted" in one_line(r.stderr)
    assert time.monotonic() - t0 < 120  # stopped: the session would fly 150 s


# The stop handler run between a chunk's bytes written and their offset and CRC counted:
# where Python runs a handler for a signal caught just before the writer blocked the
# signals. It raised KeyboardInterrupt there, and 5 of 22 logs of SIGINT-ed `gust` runs had
# their footer and data CRC wrong (the review of 2026-12-03).
IN_CHUNK_WRITE = """
from bioflex_jsb.sinks.mcap_io import writer as _w
_orig = _w.McapFileWriter._write_now
_n = [0]
def _wrapped(self, data):
    _n[0] += 1
    if _n[0] == {nth}:  # the handler runs as the bytes are written, before they are counted
        real = self._stream
        class _Stream:
            def write(_, b):
                real.write(b)
                signal.getsignal(signal.{sig})(signal.{sig}, sys._getframe())
            def __getattr__(_, name):
                return getattr(real, name)
        self._stream = _Stream()
        try:
            return _orig(self, data)
        finally:
            self._stream = real
    return _orig(self, data)
_w.McapFileWriter._write_now = _wrapped
"""


# the 4th write: a schema record at the first run's start; the 29th: the second block's
# steps' chunk of the rigid run (a 3 s rigid,coupled run writes 24 records, then chunks)
@pytest.mark.parametrize("nth", [4, 29])
@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_stop_handler_inside_a_chunk_write_leaves_a_finished_log(tmp_path, sig, nth):
    """Exit 130 in one line, and the log finished: the official reader reads its summary
    and every message, and ``info --check`` passes."""
    from mcap.reader import make_reader

    out = tmp_path / "run.mcap"
    argv = ["gust", "--duration", "3", "--gust-start", "0.1", "--models", "rigid,coupled",
            "--json", "--plot", "", "--out", str(out)]
    r = harness(tmp_path, IN_CHUNK_WRITE.format(nth=nth, sig=sig), *argv)
    assert r.returncode == 130, r.stderr[-3000:]
    assert "interrupted" in one_line(r.stderr)
    with out.open("rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        n = sum(1 for _ in reader.iter_messages())
    assert summary is not None and n == summary.statistics.message_count
    assert n > 0 if nth > 24 else n >= 0
    check = subprocess.run([PY, "-m", "bioflex_jsb", "info", "--check", str(out)],
                           capture_output=True, text=True, timeout=120, env=env())
    assert check.returncode == 0, check.stdout + check.stderr


def test_signal_inside_an_import_exits_130_in_one_line(tmp_path):
    """A signal while a module is being imported (here: from inside the import system, as
    an extension module's initialisation would run Python code) is raised once the import
    is complete, not inside it (an extension turns it into ``ImportError: initialization
    failed``)."""
    patch = """
    import importlib.abc
    class _Finder(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name == "bioflex_jsb.sinks.plotting":
                os.kill(os.getpid(), signal.SIGINT)
                for _ in range(1000):
                    pass
            return None
    sys.meta_path.insert(0, _Finder())
    import atexit
    atexit.register(lambda: print("imported" if "bioflex_jsb.sinks.plotting" in sys.modules
                                  else "cut", flush=True))
    """
    r = harness(tmp_path, textwrap.dedent(patch), "gust", "--duration", "1", "--models",
                "rigid", "--no-log", "--plot", str(tmp_path / "g.png"))
    assert r.returncode == 130, r.stderr[-3000:]
    assert "interrupted" in one_line(r.stderr)
    # the import was let finish before the stop was raised (raised inside it, the import
    # is abandoned: "cut"; an extension module would have turned it into an ImportError)
    assert r.stdout.split()[-1] == "imported", r.stdout


def test_a_deferred_stop_is_raised_at_the_next_safe_point():
    """The flag's own contract: raise_if_stopped raises once, then the flag is clear."""
    interrupts.STOP.pending = True
    with pytest.raises(KeyboardInterrupt):
        interrupts.raise_if_stopped()
    assert not interrupts.STOP.pending
    interrupts.raise_if_stopped()  # nothing pending: no exception


def test_unsafe_frame_sees_a_native_callback_and_its_callees():
    import sys as _sys

    seen = {}

    def inner():
        seen["inner"] = interrupts.unsafe_frame(_sys._getframe())

    @interrupts.native_callback
    def callback():
        seen["callback"] = interrupts.unsafe_frame(_sys._getframe())
        inner()

    callback()
    seen["outside"] = interrupts.unsafe_frame(_sys._getframe())
    assert seen == {"callback": True, "inner": True, "outside": False}


def test_unsafe_frame_sees_a_finalizer_and_its_callees():
    """A ``__del__`` and a ``weakref.finalize`` callback: Python ignores (prints) what they
    raise, so a stop raised there was lost (a fresh-cache CI run, 2026-12-03)."""
    import sys as _sys
    import weakref

    seen = []

    def inner():
        seen.append(interrupts.unsafe_frame(_sys._getframe()))

    class Dropped:
        def __del__(self):
            inner()

    class Target:
        pass

    Dropped()  # dropped at once: its __del__ runs here
    target = Target()
    weakref.finalize(target, inner)
    del target
    assert seen == [True, True]


def test_unsafe_frame_sees_llvmlites_bindings():
    """A frame of llvmlite's bindings (here: code compiled under its file name) and what it
    calls are unsafe; llvmlite's package elsewhere (its top level) is not."""
    import sys as _sys
    from pathlib import Path as _Path

    import llvmlite
    import llvmlite.binding.ffi

    seen = []

    def probe():
        seen.append(interrupts.unsafe_frame(_sys._getframe()))

    for filename in (llvmlite.binding.ffi.__file__, llvmlite.__file__):
        assert _Path(filename).exists()
        code = compile("probe()", filename, "exec")
        exec(code, {"probe": probe})
    assert seen == [True, False]


# The stop handler run by the garbage collector inside a finalizer, where Python ignores an
# exception: numba's compiler (a fresh cache) drops llvmlite objects whose __del__ the
# re-delivered signal of a deferred stop landed in; the run then went on to its end with
# "Exception ignored in: <function ObjectRef.__del__ …> … KeyboardInterrupt" on stderr.
IN_FINALIZER = """
from bioflex_jsb.drivers import gust as _g
_orig = _g.raise_if_stopped
_n = [0]
class _Dropped:
    def __del__(self):
        signal.getsignal(signal.{sig})(signal.{sig}, sys._getframe())
def _wrapped():
    _n[0] += 1
    if _n[0] == 2:  # after the rigid run's second block, in the loop (no critical section)
        _Dropped()
    return _orig()
_g.raise_if_stopped = _wrapped
"""


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_stop_inside_a_finalizer_exits_130_in_one_line(tmp_path, sig):
    out = tmp_path / "run.mcap"
    t0 = time.monotonic()
    r = harness(tmp_path, IN_FINALIZER.format(sig=sig), "gust", "--duration", "3",
                "--gust-start", "0.1", "--models", "rigid,coupled", "--json", "--plot", "",
                "--out", str(out))
    assert r.returncode == 130, r.stderr[-3000:]
    assert "interrupted" in one_line(r.stderr)
    assert time.monotonic() - t0 < 120
    check = subprocess.run([PY, "-m", "bioflex_jsb", "info", "--check", str(out)],
                           capture_output=True, text=True, timeout=120, env=env())
    assert check.returncode == 0, check.stdout + check.stderr


# ---------------------------------------------------------------------------------------
# Random moments, real processes
# ---------------------------------------------------------------------------------------
def _handlers_installed(pid: int) -> bool:
    """Whether bioflex-jsb's main() has installed its SIGTERM handler (SigCgt bit 15).
    Before that, the interpreter's start-up (≈ 0.2 s) runs with Python's defaults
    (docs/reliability.md: not promised)."""
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return False
    caught = int(next(x for x in text.splitlines() if x.startswith("SigCgt:")).split()[1], 16)
    return bool(caught >> (signal.SIGTERM - 1) & 1)


def _stop_at_random(argv: list[str], tmp_path: Path, rng: random.Random, window_s: float):
    proc = subprocess.Popen([PY, "-m", "bioflex_jsb", *argv], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True,
                            env=env(BIOFLEX_LOG_DIR=str(tmp_path / "logs")))
    deadline = time.monotonic() + 60
    while not _handlers_installed(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.005)
    delay = rng.uniform(0.0, window_s)
    time.sleep(delay)
    sig = rng.choice([signal.SIGINT, signal.SIGTERM])
    proc.send_signal(sig)
    try:
        _, err = proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        proc.kill()
        _, err = proc.communicate()
        err = "did not stop within 120 s\n" + err
    return proc.returncode, err, f"{sig.name} after {delay:.2f} s"


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs /proc (Linux)")
@pytest.mark.parametrize("command", ["gust", "sitl"])
def test_ten_stop_signals_at_random_moments_all_exit_130_in_one_line(tmp_path, command):
    """10 runs, each stopped once at a random moment of its first 6 s after start-up: the
    imports, the model load and trim, the loop and (gust) the runs' ends. Before the fix,
    about 1 in 4 such stops of gust ended in SystemError / ImportError with exit 1."""
    seed = int(os.environ.get("BIOFLEX_SIGNAL_SEED", time.time_ns() % 2**32))
    rng = random.Random(seed)
    argv = (["gust", "--duration", "600", "--no-log", "--plot", "", "--json"]
            if command == "gust" else
            ["sitl", "--mavlink", "udpin:127.0.0.1:0", "--speedup", "4", "--json"])
    bad = []
    for i in range(10):
        if command == "sitl":
            argv_i = [*argv, "--out", str(tmp_path / f"s{i}.mcap")]
        else:
            argv_i = argv
        rc, err, when = _stop_at_random(argv_i, tmp_path, rng, 6.0)
        lines = [x for x in err.strip().splitlines() if x.strip()]
        if rc != 130 or len(lines) != 1 or "Traceback" in err:
            bad.append(f"{when}: exit {rc}: {err[-600:]}")
    assert not bad, f"seed {seed}: " + "\n".join(bad)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_ends_a_blocking_wait_for_ardupilot_promptly(tmp_path, sig):
    """``ardupilot`` waiting on its socket for a peer that never comes: the stop ends the
    wait at once (a handler that did not raise would let PEP 475 resume the wait)."""
    proc = subprocess.Popen([PY, "-m", "bioflex_jsb", "ardupilot", "--port", "0", "--no-log"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env())
    try:
        line = proc.stderr.readline()  # "... waiting for ArduPilot; Ctrl-C stops"
        assert "waiting for ArduPilot" in line, line + proc.stderr.read()
        time.sleep(0.3)  # inside the wait
        t0 = time.monotonic()
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
        waited_s = time.monotonic() - t0
    finally:
        proc.kill()
        proc.wait()
    assert proc.returncode == 130, err
    assert "interrupted" in one_line(err)  # after the banner read above: one line
    # the socket wait is select() with a 0.5 s timeout: a stop that only took effect at the
    # timeout would still pass 5 s; this bound is for a stop ignored by the wait (PEP 475)
    # and the summary's output under load
    assert waited_s < 20, waited_s


def test_a_deferred_stop_never_cuts_a_close(tmp_path):
    """A stop deferred in a callback whose re-delivery arrives while the command closes its
    files (``closing()``): the close completes, then exit 130 (one line)."""
    patch = """
    from bioflex_jsb.cli import common
    from bioflex_jsb.cli import info as _info
    from bioflex_jsb.interrupts import native_callback

    @native_callback
    def callback():
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(1000):
            pass

    def run(args):
        callback()  # deferred: STOP.pending, re-delivered in 5 ms
        with common.closing():
            time.sleep(0.5)  # the re-delivery lands here
            print("closed", flush=True)
        return 0
    _info.run = run  # what register() hands to argparse
    """
    r = harness(tmp_path, patch, "info", tmp_path / "none.mcap")
    assert r.returncode == 130, r.stderr
    assert r.stdout.strip() == "closed"
    assert "closing its files" in one_line(r.stderr)
