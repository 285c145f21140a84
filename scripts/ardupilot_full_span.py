#!/usr/bin/env python3
"""The roll of an ArduPlane flight with both wing halves, from its session logs
(docs/ardupilot.md, "Both wing halves with a real ArduPlane").

    python scripts/ardupilot_full_span.py ELASTIC.mcap [RIGID.mcap] [--aircraft c172_elastic]
        [--speed 57.8] [--altitude-m A] [--window-s 4]

Each log is a ``bioflex-jsb ardupilot --span full`` session (the physics of
``scripts/ardupilot_sitl.py fly``): its run (``api.read_log``) and its autopilot topic (the
servo frames ArduPlane sent); or its ``--table FILE.npz`` written with ``--record-every 1``
(a row a frame: the state after the frame, its servos). For each flight it reports, in
flight only (the launcher excluded): the largest |asym_eta1| [rad], |modal_roll_n_m| [N·m]
(the antisymmetric deformation's rolling moment given to JSBSim) and its sign against the
roll rate, the largest |p| [rad/s] and |phi| [rad]; and each *turn entry* (wings level,
|phi| < LEVEL_DEG for LEVEL_S, then a roll past ENTRY_DEG within ENTRY_WITHIN_S: the
waypoint turns of the mission), from PRE_S before the last level sample with |p| <
P_START_RAD_S (the roll's start; ``t0_s``) for ``--window-s``: the peak |p − p(t0)| flown,
and the linear lateral models' (rigid and coupled, docs/lateral.md, built at the flight's
trim: ``--speed`` and ``--altitude-m``, default the mean true airspeed and altitude of the
turn entries' starts) driven by the aileron and rudder that turn flew over their values at
t0: the aileron is JSBSim's (``aileron_rad``), the rudder the frames' ``rudder_cmd_norm``
through the aircraft's JSBSim rudder map, measured on a fresh instance (``fcs/rudder-pos-
rad`` per unit of ``fcs/rudder-cmd-norm``; JSBSim's rudder has no actuator lag in the
c172p).

``open_loop_ratio``: the coupled model's peak over the rigid model's, both driven by the
same surfaces (the elastic flight's): what the elastic wing alone does to the same aileron.
With two logs, ``flown_ratio``: the elastic flight's peak over the rigid flight's, turn by
turn (each flown by ArduPlane's closed roll loop, which answers a wing that rolls less with
more aileron), and ``linear_ratio``: the coupled model driven by the elastic flight's surfaces
over the rigid model driven by the rigid flight's (what the linear models predict of the two
flights, as ``tests/test_lateral_turn.py`` compares sitl's turns).

Exit status 0; 2 for bad input (one line).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

# DEFINITION of a turn entry: wings level (|phi| below LEVEL_DEG) for LEVEL_S, then |phi|
# past ENTRY_DEG within ENTRY_WITHIN_S (a waypoint turn rolls to ArduPlane's 45 deg
# ROLL_LIMIT_DEG in about 2 s; the straight legs hold |phi| within a degree)
LEVEL_DEG = 3.0
LEVEL_S = 3.0
ENTRY_DEG = 15.0
ENTRY_WITHIN_S = 4.0
# the roll's start: the last level sample before the entry with |p| below this [rad/s]
# (the straight legs' roll rate stays within ±0.005 rad/s); the window starts PRE_S before
# it, in the level flight: the surfaces begin to move a few steps before p passes the bar
P_START_RAD_S = 0.01
PRE_S = 0.5
WINDOW_S = 4.0  # the turn entry compared [s from t0]: the roll-in and the bank's hold
# the full-span channels a flight's report reads
LATERAL_CHANNELS = ("asym_eta1", "modal_roll_n_m", "tip_twist_port_rad",
                    "tip_twist_starboard_rad")


class AnalysisError(Exception):
    """One line for the user."""


def _flight(path: Path) -> tuple[str, dict[str, np.ndarray], dict[str, np.ndarray]]:
    """(model, the run's channels and ``time_s``, the autopilot frames: ``time_s``,
    ``rudder_cmd_norm``, ``phase``) of a session log."""
    from bioflex_jsb import api
    from bioflex_jsb.sinks.mcap.reader import iter_messages, open_reader

    if not path.is_file():
        raise AnalysisError(f"{path}: no such log")
    runs = api.read_log(path)
    if len(runs) != 1:
        raise AnalysisError(f"{path}: {len(runs)} runs, expected one ArduPilot session's")
    model, run = next(iter(runs.items()))
    if "asym_eta1" not in run:
        raise AnalysisError(f"{path}: no antisymmetric modes (not a --span full session)")
    ch = {k: np.asarray(v, dtype=float) for k, v in run.channels.items()}
    ch["time_s"] = np.asarray(run.time_s, dtype=float)
    topic = f"/bioflex/{model}/autopilot"
    t, rud, phase = [], [], []
    with open_reader(path) as (reader, _summary):
        for _top, ns, msg in iter_messages(reader, topics=[topic]):
            t.append(ns * 1e-9)
            rud.append(float(msg.get("rudder_cmd_norm", 0.0)))
            phase.append(float(msg.get("phase", 0.0)))
    if not t:
        raise AnalysisError(f"{path}: no {topic} (not an ardupilot session's log)")
    return model, ch, {"time_s": np.array(t), "rudder_cmd_norm": np.array(rud),
                       "phase": np.array(phase)}


def _flight_table(path: Path, aircraft, need_modes: bool = True
                  ) -> tuple[str, dict[str, np.ndarray], dict]:
    """The same as :func:`_flight` from a session's ``--table`` (``--record-every 1``: a row
    a frame, the state after the frame's steps; the rudder command from servo 4 through the
    aircraft's channel map, as the session applied it). The model is not in the table:
    ``table``."""
    from bioflex_jsb.drivers import ardupilot as ad
    from bioflex_jsb.runtime.control_power import measure_control_power
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

    with np.load(path) as z:
        names, table = [str(n) for n in z["names"]], z["table"]
    if need_modes and "asym_eta1" not in names:
        raise AnalysisError(f"{path}: no antisymmetric modes (not a --span full session)")
    col = {n: table[:, i] for i, n in enumerate(names)}
    flying = ((col["phase"] == ad.PHASES.index(ad.FLIGHT))
              & (col["action"] != ad.ACTIONS.index(ad.RESEND))
              & np.isfinite(col["p_rad_s"]))  # the launch's last frame has no step yet
    if not flying.any():
        raise AnalysisError(f"{path}: no row in flight")
    speed = flight_speeds_of(aircraft)
    channels = ad.aircraft_channels(measure_control_power(airframe_for(aircraft), speed, 0.0))
    rows = {n: v[flying] for n, v in col.items()}
    rud = np.array([channels[3].value(int(us)) for us in rows["servo4_us"]])
    if "aileron_rad" not in rows:  # a half wing's table: JSBSim's aileron from servo 1
        up, down = aileron_gains_rad(aircraft)
        cmd = np.array([channels[0].value(int(us)) for us in rows["servo1_us"]])
        rows["aileron_rad"] = np.where(cmd >= 0.0, up * cmd, down * cmd)
    ch = {n: v for n, v in rows.items() if n not in ad.RECORD_HEAD}
    ch["time_s"] = rows["time_s"]
    for name in LATERAL_CHANNELS:  # a half wing's reference flight has none: zero
        ch.setdefault(name, np.zeros_like(ch["time_s"]))
    return "table", ch, {"time_s": rows["time_s"], "rudder_cmd_norm": rud}


def flight_speeds_of(aircraft) -> float:
    """The aircraft's cruise speed [m/s]."""
    from bioflex_jsb.definition.flying import flight_speeds

    return flight_speeds(aircraft)[0]


def aileron_gains_rad(aircraft) -> tuple[float, float]:
    """JSBSim's aileron ½ (left − right) [rad] per unit of ``fcs/aileron-cmd-norm`` above and
    below zero (the c172p's surfaces deflect 20 deg up, 15 down: the two differ), measured on
    a fresh instance at commands ±0.5."""
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

    fdm = airframe_for(aircraft)._fdm
    fdm.run_ic()
    out = []
    for cmd in (0.5, -0.5):
        fdm["fcs/aileron-cmd-norm"] = cmd
        fdm.run()
        out.append(0.5 * (fdm["fcs/left-aileron-pos-rad"] - fdm["fcs/right-aileron-pos-rad"])
                   / cmd)
    return out[0], out[1]


def held(frame_t: np.ndarray, values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``values`` of the frames at ``frame_t`` [s] held until the next frame, at ``t``
    (a frame's outputs act from its time on: docs/ardupilot.md, "The log")."""
    i = np.searchsorted(frame_t, t, side="right") - 1
    return values[np.clip(i, 0, len(values) - 1)]


def rudder_gain_rad(aircraft) -> float:
    """JSBSim's rudder angle per unit rudder command [rad] of ``aircraft`` (a fresh
    instance: fcs/rudder-pos-rad at commands 0 and 0.5)."""
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

    fdm = airframe_for(aircraft)._fdm
    fdm.run_ic()
    pos = []
    for cmd in (0.0, 0.5):
        fdm["fcs/rudder-cmd-norm"] = cmd
        fdm.run()
        pos.append(fdm["fcs/rudder-pos-rad"])
    return (pos[1] - pos[0]) / 0.5


def turn_entries(t: np.ndarray, phi: np.ndarray, p: np.ndarray) -> list[int]:
    """Indices t0 of the turn entries (module docstring's DEFINITION)."""
    dt = float(np.median(np.diff(t)))
    n_level, n_within = int(round(LEVEL_S / dt)), int(round(ENTRY_WITHIN_S / dt))
    level = np.abs(phi) < math.radians(LEVEL_DEG)
    # how many samples each one has been level for, itself included
    run = np.zeros(t.size, dtype=int)
    for k in range(t.size):
        run[k] = (run[k - 1] + 1 if k else 1) if level[k] else 0
    out, k = [], n_level
    while k < t.size:
        if run[k] >= n_level:
            ahead = np.flatnonzero(np.abs(phi[k:k + n_within]) > math.radians(ENTRY_DEG))
            if ahead.size:
                cross = k + int(ahead[0])
                j = cross
                while j > 0 and not (level[j] and abs(p[j]) < P_START_RAD_S):
                    j -= 1
                out.append(max(0, j - int(round(PRE_S / dt))))
                k = cross
                while k < t.size and level[k]:
                    k += 1
                while k < t.size and not level[k]:
                    k += 1
                continue
        k += 1
    return out


def linear_models(aircraft, speed_m_s: float, altitude_m: float) -> dict:
    """The rigid and coupled lateral models (coupled with the aileron's generalised force
    on the modes, what the nonlinear full-span step has) at ``speed_m_s`` [m/s],
    ``altitude_m`` [m], as tests/test_lateral_turn.py builds them."""
    from bioflex_jsb.aeroelasticity.antisymmetric_strips import (
        antisymmetric_strips,
        lateral_elastic_with_aileron,
    )
    from bioflex_jsb.flight_dynamics.lateral_elastic import (
        antisymmetric_wing,
        build_lateral_elastic,
    )
    from bioflex_jsb.runtime.identification import identify_lateral
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for, complete

    build = aircraft.wing()
    point = identify_lateral(airframe_for(aircraft), speed_m_s,
                             complete(aircraft).airframe_data().reference, altitude_m,
                             "the ArduPlane flight's trim")
    wing_a = antisymmetric_wing(build, point.trim.ixx_kg_m2)
    coupled = build_lateral_elastic("coupled", point.trim, point.aero, wing_a)
    strips = antisymmetric_strips(wing_a, aircraft.definition.aileron, build.aero.chord_m)
    q_pa = 0.5 * coupled.notes["density_kg_m3"] * speed_m_s**2
    return {"rigid": build_lateral_elastic("rigid", point.trim, point.aero, None),
            "coupled": lateral_elastic_with_aileron(coupled, strips, q_pa)}


def predict(ss, t: np.ndarray, aileron_rad: np.ndarray, rudder_rad: np.ndarray) -> dict:
    """The linear model ``ss`` from rest driven by the aileron and rudder increments [rad]:
    its outputs by name."""
    from scipy.signal import lsim

    u = np.zeros((t.size, len(ss.inputs)))
    u[:, ss.inputs.index("aileron")] = aileron_rad - aileron_rad[0]
    u[:, ss.inputs.index("rudder")] = rudder_rad - rudder_rad[0]
    _, y, _ = lsim((ss.a, ss.b, ss.c, ss.d), u, t - t[0])
    return {name: y[:, i] for i, name in enumerate(ss.outputs)}


def _nrmse(got: np.ndarray, want: np.ndarray) -> float:
    return float(np.sqrt(np.mean((got - want) ** 2)) / np.ptp(want))


def flight_report(ch: dict, frames: dict, rudder_gain: float,
                  window_s: float = WINDOW_S) -> dict:
    """The flight's figures and its turn entries' windows of ``window_s`` [s] (the module
    docstring)."""
    t = ch["time_s"]
    p, phi = ch["p_rad_s"], ch["phi_rad"]
    roll = ch["modal_roll_n_m"]
    k = int(np.argmax(np.abs(p)))
    kr = int(np.argmax(np.abs(roll)))
    flying = np.abs(p) > 0.05  # rolling: the sign of the modes' moment against p
    opposing = float(np.mean(roll[flying] * p[flying] < 0.0)) if flying.any() else None
    rudder = rudder_gain * held(frames["time_s"], frames["rudder_cmd_norm"], t)
    windows = []
    n = int(round(window_s / float(np.median(np.diff(t)))))
    for i0 in turn_entries(t, phi, p):
        sl = slice(i0, min(i0 + n, t.size))
        windows.append({"t0_s": float(t[i0]), "slice": sl,
                        "aileron_rad": ch["aileron_rad"][sl], "rudder_rad": rudder[sl],
                        "p": p[sl] - p[i0], "phi": phi[sl] - phi[i0],
                        "eta1": ch["asym_eta1"][sl] - ch["asym_eta1"][i0]})
    return {
        "flown_s": float(t[-1] - t[0]),
        "peak_abs_p_rad_s": float(abs(p[k])), "peak_p_at_s": float(t[k]),
        "peak_abs_phi_rad": float(np.max(np.abs(phi))),
        "peak_abs_asym_eta1_rad": float(np.max(np.abs(ch["asym_eta1"]))),
        "peak_abs_modal_roll_n_m": float(abs(roll[kr])), "peak_modal_roll_at_s": float(t[kr]),
        "modal_roll_opposes_p_fraction": opposing,
        "modal_roll_over_p_at_peak_p_n_m_s": float(roll[k] / p[k]) if p[k] else None,
        "tip_twists_opposite_at_peak_p": bool(
            ch["tip_twist_port_rad"][k] * ch["tip_twist_starboard_rad"][k] < 0.0),
        "peak_abs_aileron_rad": float(np.max(np.abs(ch["aileron_rad"]))),
        "airspeed_m_s_mean": float(np.mean(ch["airspeed_m_s"])),
        "altitude_m_mean": float(np.mean(ch["altitude_m"])),
        "_windows": windows, "_t": t, "_altitude": ch["altitude_m"],
        "_airspeed": ch["airspeed_m_s"],
    }


def turn_figures(w: dict, t: np.ndarray, models: dict) -> dict:
    """One turn entry's flown and linear figures."""
    tw = t[w["slice"]]
    lin = {m: predict(ss, tw, w["aileron_rad"], w["rudder_rad"]) for m, ss in models.items()}
    out = {"t0_s": w["t0_s"], "peak_abs_p_rad_s": float(np.max(np.abs(w["p"]))),
           "peak_abs_phi_change_rad": float(np.max(np.abs(w["phi"]))),
           "peak_abs_aileron_change_rad": float(np.max(np.abs(w["aileron_rad"]
                                                             - w["aileron_rad"][0]))),
           "peak_abs_asym_eta1_change_rad": float(np.max(np.abs(w["eta1"])))}
    for m, y in lin.items():
        out[f"{m}_model_peak_abs_p_rad_s"] = float(np.max(np.abs(y["p"])))
        out[f"{m}_model_nrmse_p"] = _nrmse(y["p"], w["p"])
    out["coupled_model_peak_abs_eta1_rad"] = float(np.max(np.abs(lin["coupled"]["eta1"])))
    out["coupled_model_nrmse_eta1"] = (_nrmse(lin["coupled"]["eta1"], w["eta1"])
                                       if np.ptp(w["eta1"]) > 0.0 else None)  # rigid: none
    out["open_loop_ratio"] = (out["coupled_model_peak_abs_p_rad_s"]
                              / out["rigid_model_peak_abs_p_rad_s"])
    return out


def analyse(elastic: Path, rigid: Path | None, aircraft_name: str, speed_m_s: float | None,
            altitude_m: float | None, window_s: float = WINDOW_S) -> dict:
    from bioflex_jsb import api

    aircraft = api.load_aircraft(aircraft_name)
    gain = rudder_gain_rad(aircraft)
    flights = {}
    for label, path in (("elastic", elastic), ("rigid", rigid)):
        if path is None:
            continue
        if path.suffix == ".npz":
            model, ch, frames = _flight_table(path, aircraft, need_modes=label == "elastic")
        else:
            model, ch, frames = _flight(path)
        rep = flight_report(ch, frames, gain, window_s)
        rep["model"], rep["log"] = model, str(path)
        flights[label] = rep
    if not flights["elastic"]["_windows"]:
        raise AnalysisError(f"{elastic}: no turn entry (wings level {LEVEL_S:g} s, then past "
                            f"{ENTRY_DEG:g} deg within {ENTRY_WITHIN_S:g} s)")
    starts = [(f["_airspeed"][w["slice"].start], f["_altitude"][w["slice"].start])
              for f in flights.values() for w in f["_windows"]]
    speed = float(np.mean([v for v, _ in starts])) if speed_m_s is None else speed_m_s
    if altitude_m is None:
        altitude_m = float(np.mean([h for _, h in starts]))
    models = linear_models(aircraft, speed, altitude_m)
    for rep in flights.values():
        rep["turns"] = [turn_figures(w, rep["_t"], models) for w in rep["_windows"]]
    out = {"aircraft": aircraft_name, "linear_models_at": {"speed_m_s": speed,
                                                           "altitude_m": altitude_m},
           "rudder_rad_per_cmd": gain, "window_s": window_s,
           "flights": {k: {n: v for n, v in f.items() if not n.startswith("_")}
                       for k, f in flights.items()}}
    if "rigid" in flights:
        pairs = []
        for e, r in zip(flights["elastic"]["turns"], flights["rigid"]["turns"], strict=False):
            pairs.append({
                "t0_s": (e["t0_s"], r["t0_s"]),
                "flown_ratio": e["peak_abs_p_rad_s"] / r["peak_abs_p_rad_s"],
                "linear_ratio": (e["coupled_model_peak_abs_p_rad_s"]
                                 / r["rigid_model_peak_abs_p_rad_s"]),
                "aileron_ratio": (e["peak_abs_aileron_change_rad"]
                                  / r["peak_abs_aileron_change_rad"])})
        out["elastic_over_rigid_by_turn"] = pairs
    return out


@contextlib.contextmanager
def _stdout_to_stderr():
    """File descriptor 1 (C libraries' stdout too) onto stderr, so stdout is the JSON."""
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("elastic", type=Path, help="the --span full session's log (coupled)")
    parser.add_argument("rigid", type=Path, nargs="?", default=None,
                        help="the same mission flown with --model rigid")
    parser.add_argument("--aircraft", default="c172_elastic")
    parser.add_argument("--speed", type=float, default=None,
                        help="the linear models' trim speed [m/s] (default the turn "
                        "entries' mean true airspeed)")
    parser.add_argument("--altitude-m", type=float, default=None,
                        help="their trim altitude [m] (default the turn entries' mean)")
    parser.add_argument("--window-s", type=float, default=WINDOW_S,
                        help=f"each turn entry's window [s] (default {WINDOW_S:g})")
    args = parser.parse_args(argv)
    try:
        if not (math.isfinite(args.window_s) and 0.5 <= args.window_s <= 30.0):
            raise AnalysisError(f"--window-s must be 0.5 to 30 s, got {args.window_s:g}")
        with _stdout_to_stderr():  # JSBSim prints its loading reports on stdout
            out = analyse(args.elastic, args.rigid, args.aircraft, args.speed,
                          args.altitude_m, args.window_s)
    except AnalysisError as exc:
        print(f"ardupilot_full_span: {exc}", file=sys.stderr)
        return 2
    print(json.dumps(out, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
