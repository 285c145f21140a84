"""``bioflex-jsb export-jsbsim``: the modal wing as JSBSim systems, an aircraft that flies it,
its trim and a script for the ``jsbsim`` console program."""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path

from bioflex_jsb.cli.case import (
    DEFAULT_GUST,
    DEFAULT_SPEED_M_S,
    DEFAULT_WING,
    SPEED_MAX_M_S,
    SPEED_MIN_M_S,
    add_force_argument,
    airspeed,
    check_time_step,
    speed_help,
)
from bioflex_jsb.cli.common import (
    UsageError,
    add_wing_arguments,
    check_file_name,
    check_output,
    positive_float,
    print_json,
    wing_from_args,
)
from bioflex_jsb.files import read_input_bytes

HELP = f"""Write a JSBSim root under --out DIR: systems/bioflex_modal_<wing>.xml (the modal wing
integrated by JSBSim: each mode's structure exact, the aerodynamic coupling as a leapfrog kick),
aircraft/bioflex_<wing>/ (the bioflex airframe including it, the modal loads in its
aerodynamics, with its trim companion), the level trim at --speed as the initial condition
aircraft/bioflex_<wing>/trim.xml and the script scripts/bioflex_<wing>.xml (held at the trim
while the propellers spin up, 5 s, then flown 5 s, through --gust 0.5 s after the release).
Fly it with `jsbsim --root=DIR --script=scripts/bioflex_<wing>.xml --simulation-rate=960`
(960 = 1/--dt; the command is printed with DIR's absolute path); it writes
DIR/bioflex_<wing>.csv, columns and units in docs/native.md. --outputpath, if you add it, is
taken relative to DIR by JSBSim, not to the working directory, and must exist: else JSBSim
writes nothing and exits 0. The system holds for one time step, --dt [s] (default 1/960 s; a
step at which the integration's eigenvalues are more than 1 % off the exact ones up to 40 m/s
is refused, naming a halved step that is not); the trim lift coefficient and the reference
flow of the exact part are those of level flight at --speed, {SPEED_MIN_M_S:g} to
{SPEED_MAX_M_S:g} m/s (the airframe trims at about 9.4 to 32.7 m/s: outside, the export
refuses with the trim's reason). For `--model qsd` the names end in _qsd. --aircraft NAME|FILE
exports a definition's wing with its values (S, c-bar, mass, derivatives, modes): on the
generated airframe as --wing does; on a JSBSim aircraft file (e.g. sgs_elastic: the jsbsim
package's SGS glider) as aircraft/<definition name>/, a copy of that file with the wing added
(the original is never written) and the files it names (engines, propellers, systems: e.g.
c172_elastic's c172p engine and propeller from the jsbsim root's engine/) copied beside it,
its trim as the initial condition (a glider's glide, flown after 0.1 s; a powered
aircraft's level flight, its engines started by the script and held 8 s while the
propellers settle), at --speed within the aircraft's own speeds (coupled model only). See
docs/native.md."""


def register(sub) -> None:
    from bioflex_jsb.generators.native_wing import EXPORT_MODELS
    from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S, MAX_DT_S, MIN_DT_S

    p = sub.add_parser("export-jsbsim", help="write the modal wing as JSBSim systems, an "
                       "aircraft, its trim and a console-program script", description=HELP)
    add_wing_arguments(p, default=DEFAULT_WING)
    p.add_argument("--model", choices=EXPORT_MODELS, default="coupled",
                   help="coupled (modal states) or qsd (quasi-static deformation); "
                        "default coupled")
    p.add_argument("--out", required=True, metavar="DIR", help="JSBSim root to write into")
    p.add_argument("--dt", type=positive_float("time step", "s"), default=DEFAULT_DT_S,
                   help=f"JSBSim step the system is exported for [s], {MIN_DT_S:g}..{MAX_DT_S:g} "
                        f"(and fine enough for the wing's modes; default {DEFAULT_DT_S:.6g})")
    p.add_argument("--speed", type=airspeed, default=None, metavar="V",
                   help=speed_help(DEFAULT_SPEED_M_S,
                                   extra="; it sets the script's level trim (the airframe trims "
                                         "at about 9.4-32.7 m/s), the trim lift coefficient and "
                                         "the reference flow of the system; with --aircraft: "
                                         "within its airframe.speed_range_m_s, default its "
                                         "cruise_speed_m_s (a glider's glide trim)"))
    p.add_argument("--gust", default=DEFAULT_GUST, metavar="sharp:A|none",
                   help="the script's vertical gust: sharp-edged, A [m/s] up, 0.5 s after the "
                        f"release, or none (default {DEFAULT_GUST}, the paper's Fig. 21)")
    add_force_argument(p)
    p.add_argument("--json", action="store_true", help="print what was written as JSON")
    p.set_defaults(run=run)


def _gust_up_m_s(gust) -> float:
    """The script's sharp-edged gust [m/s] (0: none) of a parsed --gust (a GustSpec); other
    gust kinds are refused."""
    if gust.kind == "none":
        return 0.0
    if gust.kind != "sharp":
        raise UsageError(f"--gust {gust.text()!r}: the exported script flies a sharp-edged "
                         "gust (sharp:A) or none")
    return float(gust.amplitude_m_s)


# The export's record of what it wrote (file → SHA-256), in the root it writes: a later
# export replaces a file of ours only as it was written (an edited one needs --force, so a
# user's edit under the GENERATED header is never lost silently).
MANIFEST = ".bioflex-jsb-export.json"
# Largest generated file or manifest read back [bytes]: an export's files are tens of kB
# (an aircraft copy: at most the 16 MiB bound of the files JSBSim reads).
MAX_EXPORT_FILE_BYTES = 16 * 1024 * 1024


def _manifest(out: Path) -> dict[str, str] | None:
    """The root's manifest (relative path → SHA-256), or None without a readable one (an
    export of an earlier version: its files are judged by their header alone)."""
    import json

    try:
        data = json.loads(read_input_bytes(out / MANIFEST, "manifest", MAX_EXPORT_FILE_BYTES,
                                           UsageError))
    except (UsageError, ValueError):  # missing, not a regular file, too large, not JSON
        return None
    files = data.get("files") if isinstance(data, dict) else None
    return files if isinstance(files, dict) else None


def _digest(data: bytes) -> str:
    import hashlib

    return hashlib.sha256(data).hexdigest()


def _ours(path: Path, recorded: str | None = None, manifest: bool = False) -> bool:
    """A file an export (or the repository's generators) wrote, unedited: replaced without
    --force. With a manifest (``manifest``), also its content as recorded (``recorded``,
    its SHA-256; None: not recorded, a file of another export)."""
    try:
        data = read_input_bytes(path, "file", MAX_EXPORT_FILE_BYTES, UsageError)
    except UsageError:  # unreadable, special or too large: not known to be ours, so not
        return False    # replaced without --force
    if b"GENERATED by bioflex_jsb" not in data[:512]:
        return False
    return not manifest or recorded == _digest(data)


def _check_csv_target(path: Path) -> None:
    """JSBSim disables its output silently (exit 0) when it cannot open the CSV: refuse a
    root where that is already so."""
    if (path.exists() or path.is_symlink()) and not path.is_file():
        raise UsageError(f"{str(path)!r} exists and is not a regular file: the script's CSV "
                         "could not be written there; remove it or choose another --out")


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.drivers.native import aircraft_spec, export_flight, write_export
    from bioflex_jsb.generators import native_wing as J

    check_file_name(args.out, "--out")
    build = wing_from_args(args)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {args.out!r} is not a directory")
    parent = out.absolute().parent
    if not out.exists() and not parent.is_dir():  # a mistyped path: no tree made for it
        raise UsageError(f"cannot write into {args.out!r}: {str(parent)!r} "
                         + ("is not a directory" if parent.exists() else
                            "does not exist (DIR itself is made, not its parents)"))
    # the co-simulation's range (gust --dt): below it JSBSim's trim of the exported aircraft
    # fails and says "needs more thrust than the motor gives"
    check_time_step(args.dt)
    from bioflex_jsb.cli.aircraft_option import resolve_flight
    from bioflex_jsb.simulation.gusts import parse_gust

    args.gust = parse_gust(args.gust)  # GustSpecError: one line
    resolve_flight(args)  # --speed of the aircraft (default its cruise speed), one line
    gust_up = _gust_up_m_s(args.gust)
    aircraft = getattr(args, "aircraft_definition", None)
    try:
        if aircraft is not None:  # the definition's values (DefinitionError: one line)
            spec = aircraft_spec(aircraft, build, args.model, args.dt, args.speed)
        else:
            spec = J.ExportSpec(build.model, build.variant.name, args.model, args.dt,
                                args.speed)
    except J.ExportError as exc:
        raise UsageError(str(exc)) from None
    try:
        case, state, files = export_flight(spec, gust_up)  # TrimError: one line, no file
    except J.ExportError as exc:  # an aircraft file that cannot take the wing
        raise UsageError(str(exc)) from None
    recorded = _manifest(out)
    for rel in files:
        check_output(str(out / rel), args.force, "file (edited since it was generated?)",
                     ours=lambda p, rel=rel: _ours(p, (recorded or {}).get(rel),
                                                   recorded is not None))
    _check_csv_target(out / case.output)
    try:
        written = write_export(files, out)
        import json

        kept = dict(recorded or {})
        kept.update({rel: _digest(text.encode("utf-8")) for rel, text in files.items()})
        (out / MANIFEST).write_text(json.dumps({"files": kept}, indent=1, sort_keys=True),
                                    encoding="utf-8")
    except OSError as exc:
        raise UsageError(f"cannot write into {args.out!r}: {exc.strerror or exc}") from None
    root = out.resolve()
    command = case.command(shlex.quote(str(root)))
    info = {
        "out": str(root),
        "aircraft": case.aircraft,
        "system": J.system_name(spec.variant, spec.model),
        "model": spec.model,
        "dt_s": spec.dt_s,
        "speed_m_s": spec.speed_m_s,
        "gust_up_m_s": gust_up,
        "initial_condition": case.ic_path,
        "script": case.script,
        "command": command,
        "output_csv": str(root / case.output),
        "columns": [{"column": "Time", "property": "simulation/sim-time-sec",
                     "meaning": "simulation time [s]"}]
                   + [{"column": c.caption, "property": c.prop, "meaning": c.meaning}
                      for c in case.columns],
        "trim": {"propeller_rpm": state.propeller_rpm,
                 "throttle": state.controls.get("fcs/throttle-cmd-norm[0]"),  # None: no engine
                 "theta_rad": state.ic["theta"][1], "gamma_rad": state.gamma_rad},
        "files": [str(p) for p in written],
    }
    if spec.model == "coupled":
        nums = J.modal_matrices(spec.wing, spec.cl_trim)
        err, at = spec.eigen_error(nums)
        info["eigenvalue_error_max"] = err
        info["eigenvalue_error_at_speed_m_s"] = at
    if args.json:
        print_json(info)
    else:
        print(f"{spec.model} modal wing {spec.variant!r} for a {spec.dt_s:.6g} s step, trimmed "
              f"at {spec.speed_m_s:g} m/s: aircraft {case.aircraft} under {out} "
              f"({len(written)} files)")
        print(f"fly it: {command}")
        print(f"it writes {info['output_csv']} (columns and units: docs/native.md)")
    return 0
