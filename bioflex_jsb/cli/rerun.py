"""``bioflex-jsb rerun``: repeat the run recorded in an MCAP log and compare the results."""

from __future__ import annotations

import argparse
import json
import sys

from bioflex_jsb.cli.common import UsageError, print_json

HELP = """Repeat the gust run, sweep case or comparison recorded in FILE.mcap from its metadata
record bioflex.run (wing, mass basis, speed, gust and seed, duration, gust start, time step,
models), writing the new log to --out, and compare the two logs message by message (every
topic, log time and number; numbers agree when within --rtol relative or 1e-12 absolute).
Exit status 0 when they agree, 1 when they differ (the first difference is printed), 2 for a
bad file."""

ABS_TOL = 1e-12


def register(sub) -> None:
    p = sub.add_parser("rerun", help="repeat the run of an MCAP log and compare",
                       description=HELP)
    p.add_argument("file", metavar="FILE.mcap", help="the log of the original run")
    p.add_argument("--out", metavar="NEW.mcap", required=True, help="log of the repeated run")
    p.add_argument("--rtol", type=float, default=1e-8,
                   help="relative tolerance of the comparison [-] (default 1e-8)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def argv_from_log(path: str) -> list[str]:
    """The bioflex-jsb argument list (without --out) that repeats the logged run."""
    from bioflex_jsb.sinks.mcap_log import (
        REPEATABLE_COMMANDS,
        RUN_METADATA,
        LogError,
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
    if meta.get("command") not in REPEATABLE_COMMANDS:
        raise UsageError(f"{path!r} was written by {meta.get('command')!r}; only gust runs, "
                         "sweep cases and comparisons can be repeated")
    try:
        argv = json.loads(meta["argv"])
    except (KeyError, ValueError):
        raise UsageError(f"{path!r}: the run metadata has no usable argument list") from None
    if not isinstance(argv, list) or not all(isinstance(a, str) for a in argv):
        raise UsageError(f"{path!r}: the run metadata has no usable argument list")
    return argv


def _differs(a, b, rtol: float) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() != b.keys() or any(_differs(a[k], b[k], rtol) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) != len(b) or any(_differs(x, y, rtol) for x, y in zip(a, b, strict=True))
    if isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str) or a is None:
        return a != b
    if isinstance(a, int | float) and isinstance(b, int | float):
        return abs(a - b) > max(ABS_TOL, rtol * max(abs(a), abs(b)))
    return a != b


def compare_logs(old: str, new: str, rtol: float) -> dict:
    """Message-by-message comparison of two logs (topics, counts, log times, numbers)."""
    from bioflex_jsb.sinks.mcap_log import LogError, messages_by_topic

    try:
        a, b = messages_by_topic(old), messages_by_topic(new)
    except LogError as exc:
        raise UsageError(str(exc)) from None
    result = {"equal": True, "messages": sum(len(v) for v in a.values()), "topics": len(a),
              "first_difference": None}
    if a.keys() != b.keys():
        result.update(equal=False, first_difference=(
            f"topics differ: {sorted(set(a) ^ set(b))}"))
        return result
    for topic_name in sorted(a):
        ma, mb = a[topic_name], b[topic_name]
        if len(ma) != len(mb):
            result.update(equal=False, first_difference=(
                f"{topic_name}: {len(ma)} messages in the original, {len(mb)} in the rerun"))
            return result
        for (ta, xa), (tb, xb) in zip(ma, mb, strict=True):
            if ta != tb or _differs(xa, xb, rtol):
                result.update(equal=False, first_difference=(
                    f"{topic_name} at t = {ta * 1e-9:.6f} s: {json.dumps(xa)} != "
                    f"{json.dumps(xb)}"))
                return result
    return result


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from bioflex_jsb import cli
    from bioflex_jsb.sinks.mcap_log import check_file

    argv = argv_from_log(args.file)
    try:
        check_file(args.file)
    except Exception as exc:  # LogError
        raise UsageError(str(exc)) from None
    if Path(args.out).resolve() == Path(args.file).resolve():
        raise UsageError("--out must name a new file, not the original log")
    import contextlib
    import io

    full = [*argv, "--out", args.out, "--json", "--plot", ""]
    captured = io.StringIO()
    with contextlib.redirect_stdout(captured):
        status = cli.main(full)
    if status not in (0, 3):  # 3: the run diverged, as the original may have
        raise UsageError(f"the repeated run failed (exit status {status}): "
                         f"bioflex-jsb {' '.join(full)}")
    result = compare_logs(args.file, args.out, args.rtol)
    result.update(command=["bioflex-jsb", *full], original=args.file, rerun=args.out)
    if args.json:
        print_json(result)
    elif result["equal"]:
        print(f"rerun of {args.file} written to {args.out}: same result "
              f"({result['messages']} messages on {result['topics']} topics agree)")
    else:
        print(f"rerun of {args.file} written to {args.out}: DIFFERENT result: "
              f"{result['first_difference']}")
    if not result["equal"]:
        print("bioflex-jsb rerun: the repeated run differs from the log", file=sys.stderr)
        return 1
    return 0
