"""``bioflex-jsb rerun``: repeat the run recorded in an MCAP log and compare the results."""

from __future__ import annotations

import argparse
import json
import sys

from bioflex_jsb.cli.common import (
    EXIT_NO_RESULT,
    UsageError,
    check_new_file,
    escaped,
    number_type,
    print_json,
)

HELP = """Repeat the gust run, sweep case or comparison recorded in FILE.mcap from its metadata
record bioflex.run (wing, mass basis, speed, gust and seed, duration, gust start, time step,
models), writing the new log to --out, and compare the two logs message by message (every
topic, log time and number; numbers agree when within --rtol relative or 1e-12 absolute).
Exit status 0 when they agree, 1 when they differ (the first difference is printed), 2 for a
bad file. Only what a run description holds is taken from the log: gust or compare, with
--wing, --aircraft, --mass-basis, --speed, --gust, --duration, --gust-start, --dt, --models,
--model, --aero, --structural-damping and --trim; a log asking for anything else (--live,
an output, another command) is refused (docs/logging.md)."""

LEGACY_REPEATABLE = ("gust", "sweep", "compare")  # commands whose old logs hold an argv
# What a log may ask a rerun to do: fly ``gust`` or ``compare`` with the options of a run
# description, each with its value. Nothing else a command line can hold: no network
# (--live, --live-any-host), no output (--out, --plot, --force, --no-log: the rerun's own
# --out is the one written), no other command. A log is a file someone may have sent.
RUN_COMMANDS = ("gust", "compare")
RUN_OPTIONS = ("--wing", "--aircraft", "--mass-basis", "--speed", "--gust", "--duration",
               "--gust-start", "--dt", "--models", "--model", "--aero",
               "--structural-damping", "--trim", "--controller", "--lateral-aero", "--span",
               "--aileron-step", "--aileron-doublet", "--aileron-start", "--aileron-width")


tolerance = number_type("rtol", low=0.0, high=1.0, high_open=True)
"""argparse type: a relative tolerance 0 <= rtol < 1 [-]."""


def register(sub) -> None:
    p = sub.add_parser("rerun", help="repeat the run of an MCAP log and compare",
                       description=HELP)
    p.add_argument("file", metavar="FILE.mcap", help="the log of the original run")
    p.add_argument("--out", metavar="NEW.mcap", required=True, help="log of the repeated run")
    p.add_argument("--rtol", type=tolerance, default=1e-8,
                   help="relative tolerance of the comparison [-], 0 <= rtol < 1 (default 1e-8)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def argv_for(description) -> list[str]:
    """The bioflex-jsb argument list (without --out/--plot/--json) that flies the run
    ``description`` (a :class:`~bioflex_jsb.simulation.run.RunDescription`) again: a gust
    run, a sweep case (as the gust run it is) or a comparison."""
    d = description
    if not d.repeatable:
        raise UsageError(f"the log was written by {d.kind!r}; only gust runs, sweep cases and "
                         "comparisons can be repeated (a SITL session follows the wall clock "
                         "and its ground station)")
    if d.altitude_m != 0.0:
        raise UsageError(f"the logged run flew at {d.altitude_m:g} m; gust and compare fly "
                         "at sea level only")
    # a run of an --aircraft definition (extra.aircraft: the shipped name or the file it was
    # read from) is flown from that definition again; its wing is the definition's
    wing = (["--aircraft", str(d.extra["aircraft"])] if d.extra.get("aircraft")
            else ["--wing", d.wing])
    common = [*wing, "--mass-basis", d.mass_basis,
              "--speed", repr(float(d.speed_m_s)), "--gust", d.gust,
              "--duration", repr(float(d.duration_s)),
              "--gust-start", repr(float(d.gust_start_s)), "--dt", repr(float(d.dt_s))]
    if d.extra.get("aero", "quasi-steady") != "quasi-steady":
        common += ["--aero", str(d.extra["aero"])]
    if d.extra.get("structural_damping") is not None:
        common += ["--structural-damping", repr(float(d.extra["structural_damping"]))]
    if d.extra.get("trim", "rigid") != "rigid":
        common += ["--trim", str(d.extra["trim"])]
    if d.extra.get("controller"):
        common += ["--controller", str(d.extra["controller"])]
    if d.extra.get("span"):  # both halves and an aileron input (cli/lateral_options.py)
        common += ["--span", str(d.extra["span"])]
        for key in ("aileron_step", "aileron_doublet", "aileron_start", "aileron_width"):
            if key in d.extra:
                common += [f"--{key.replace('_', '-')}", repr(float(d.extra[key]))]
    if d.extra.get("lateral_aero"):  # both halves on the recorded loading
        common += ["--lateral-aero", str(d.extra["lateral_aero"])]
        if not d.extra.get("span"):
            common += ["--span", "full"]
    if d.kind == "compare":
        if len(d.models) != 1:
            raise UsageError(f"a comparison flies one model; the log names {list(d.models)}")
        return run_argv(["compare", *common, "--model", d.models[0]], "the log")
    return run_argv(["gust", *common, "--models", ",".join(d.models)], "the log")


def run_argv(argv: list[str], source: str) -> list[str]:
    """``argv`` as a run a log may ask for (:data:`RUN_COMMANDS` with :data:`RUN_OPTIONS`,
    each with its value), every option written ``--option=value`` (a value can never be
    read as another option); UsageError naming the first token that is not one
    (``source``: where the list came from)."""
    if not argv or argv[0] not in RUN_COMMANDS:
        raise UsageError(f"{source} asks for the command {str(argv[:1])[1:-1] or 'none'}; a "
                         f"rerun flies {' or '.join(RUN_COMMANDS)} only")
    out, rest = [argv[0]], list(argv[1:])
    while rest:
        token = rest.pop(0)
        name, eq, value = token.partition("=")
        if name not in RUN_OPTIONS:
            raise UsageError(f"{source} holds {token[:60]!r}, not an option of a run "
                             f"description ({', '.join(RUN_OPTIONS)}); a rerun takes no "
                             "network, output or other options from a log")
        if not eq:
            if not rest:
                raise UsageError(f"{source} gives {name} without its value")
            value = rest.pop(0)
        out.append(f"{name}={value}")
    return out


def argv_from_log(path: str) -> list[str]:
    """The bioflex-jsb argument list (without --out) that repeats the logged run: from the
    run description the log records, or (logs written before descriptions) its ``argv``."""
    from bioflex_jsb.sinks.mcap import (
        RUN_METADATA,
        LogError,
        description_from_metadata,
        open_reader,
        read_metadata,
    )

    try:
        with open_reader(path) as (reader, _summary):
            meta = read_metadata(reader).get(RUN_METADATA)
    except LogError as exc:
        raise UsageError(str(exc)) from None
    if meta is None:
        raise UsageError(f"{path!r} has no {RUN_METADATA} metadata record; nothing to repeat")
    try:
        description = description_from_metadata(meta)
    except LogError as exc:
        raise UsageError(f"{path!r}: {exc}") from None
    if description is not None:
        return argv_for(description)
    return legacy_argv(path, meta)


def legacy_argv(path: str, meta: dict[str, str]) -> list[str]:
    """The argument list an old log (``arguments``/``argv`` metadata, no description)
    recorded."""
    if meta.get("command") not in LEGACY_REPEATABLE:
        raise UsageError(f"{path!r} was written by {meta.get('command')!r}; only gust runs, "
                         "sweep cases and comparisons can be repeated")
    try:
        argv = json.loads(meta["argv"])
    except (KeyError, ValueError):
        raise UsageError(f"{path!r}: the run metadata has no usable argument list") from None
    if not isinstance(argv, list) or not all(isinstance(a, str) for a in argv):
        raise UsageError(f"{path!r}: the run metadata has no usable argument list")
    return run_argv(argv, f"the argument list of {path!r}")


def compare_logs(old: str, new: str, rtol: float) -> dict:
    """Message-by-message comparison of two logs
    (:func:`bioflex_jsb.sinks.mcap.compare.compare_logs`); an unreadable log is a
    UsageError."""
    from bioflex_jsb.sinks.mcap import LogError
    from bioflex_jsb.sinks.mcap import compare_logs as compare

    try:
        return compare(old, new, rtol)
    except LogError as exc:
        raise UsageError(str(exc)) from None


def _check_intact(path: str) -> None:
    """The original log's chunks and CRCs all check (``info --check``), else one line."""
    from bioflex_jsb.sinks.mcap import LogError, check_chunks

    try:
        result = check_chunks(path)
    except LogError as exc:
        raise UsageError(str(exc)) from None
    if result["problems"]:
        raise UsageError(f"{path!r} is damaged ({'; '.join(result['problems'][:2])}): a run "
                         "is repeated from an intact log; `bioflex-jsb info FILE --recover "
                         "FIXED.mcap` copies its intact chunks")


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from bioflex_jsb import cli

    if Path(args.out).resolve() == Path(args.file).resolve():
        raise UsageError("--out must name a new file, not the original log")
    check_new_file(args.out, False, "--out", (".mcap",))  # before flying, not after
    argv = argv_from_log(args.file)  # also checks that the file is a finished log
    _check_intact(args.file)  # every byte, before a run of hours is flown to compare with it
    import contextlib
    import io

    full = [*argv, "--out", args.out, "--json", "--plot", ""]
    captured = io.StringIO()
    with contextlib.redirect_stdout(captured):
        status = cli.main(full)
    if status not in (0, 3):  # 3: the run diverged, as the original may have
        return status  # the repeated run said why, in its one line
    result = compare_logs(args.file, args.out, args.rtol)
    result.update(command=["bioflex-jsb", *full], original=args.file, rerun=args.out)
    if args.json:
        print_json(result)
    elif result["equal"]:
        print(f"rerun of {args.file} written to {args.out}: same result "
              f"({result['messages']} messages on {result['topics']} topics agree)")
    else:
        print(f"rerun of {args.file} written to {args.out}: DIFFERENT result: "
              f"{escaped(result['first_difference'])}")  # names of the log's topics
    if not result["equal"]:
        print("bioflex-jsb rerun: the repeated run differs from the log", file=sys.stderr)
        return EXIT_NO_RESULT
    return 0
