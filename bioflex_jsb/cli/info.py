"""``bioflex-jsb info``: what an MCAP log holds; recovery of a log whose writer was killed."""

from __future__ import annotations

import argparse
import json

from bioflex_jsb.cli.common import (
    EXIT_NO_RESULT,
    UsageError,
    check_new_file,
    escaped,
    print_json,
)

HELP = """Summarise an MCAP log written by bioflex-jsb (or any MCAP file): its channels
(topic, schema, message count), the number of messages and chunks, the time span [s of
simulation time], the metadata records (the run's command and arguments, wing, gust, time
step, versions) and the events on /bioflex/events (time [s], level, text: a run that
diverged, a SITL session's STATUSTEXT: crashes, resets, mode changes). Read through the
mcap package's indexed reader. A log whose writer was killed (SIGKILL, power loss) has no
summary; --recover FIXED.mcap copies every complete chunk of it into a new, finished file
(at most the last chunk, 0.9 s of simulated time, is lost); a damaged chunk is skipped,
every intact chunk after it kept, and the skipped ones are named. --check decompresses
every chunk and verifies it (its zstd checksum or CRC), the data section's CRC and the
summary's, and that the file is finished (Data End, summary, footer): exit status 1 and
one line saying what is wrong if not. Without --check, info verifies the same and refuses
(exit 2, one line) a damaged or unfinished file; an unfinished one is told apart: still
being written (a process has it open for writing, or it changed in the last 10 s) or cut
off (its writer was killed). Logs in protobuf (this version) and JSON (older versions) are
read alike."""


def register(sub) -> None:
    p = sub.add_parser("info", help="channels, counts, duration and metadata of an MCAP log",
                       description=HELP)
    p.add_argument("file", metavar="FILE.mcap", help="the log")
    p.add_argument("--recover", metavar="FIXED.mcap",
                   help="write the complete records of a truncated FILE.mcap to FIXED.mcap")
    p.add_argument("--force", action="store_true",
                   help="replace an existing --recover file")
    p.add_argument("--check", action="store_true",
                   help="verify every chunk's checksum or CRC, the data section's and the "
                        "summary's CRCs and that the file is finished (exit 1 if not)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import sys

    from bioflex_jsb.sinks.mcap import LogError, LogWriteError, check_chunks, recover, summarise

    if args.check and args.recover is not None:
        raise UsageError("--check and --recover are separate jobs; give one")
    if args.force and args.recover is None:
        raise UsageError("--force replaces an existing --recover file; give --recover")
    if args.recover is not None:  # a user's file is never replaced without --force
        check_new_file(args.recover, args.force, "--recover", (".mcap",))
    try:
        if args.recover:
            result = recover(args.file, args.recover)
        elif args.check:
            result = check_chunks(args.file)
        else:
            result = summarise(args.file)
    except (LogError, LogWriteError) as exc:  # unreadable log, unwritable --recover file
        raise UsageError(str(exc)) from None
    if args.json:
        print_json(result)
    elif args.recover:
        last = result["last_time_s"]
        skipped = result["skipped"]
        print(f"recovered {result['messages']} messages on {result['channels']} channels "
              f"into {result['out']}" + (f", up to t = {last:.3f} s" if last is not None else "")
              + f" (read stopped at: {result['stopped_at']})"
              + (f"; skipped {len(skipped)} damaged: {'; '.join(skipped)}" if skipped else ""))
    elif args.check:
        print(f"{result['file']}: {_check_status(result)}: {result['chunks']} chunks, "
              f"{len(result['bad'])} with a bad checksum, CRC or record, data section CRC "
              f"{result['data_crc']}, summary CRC {result['summary_crc']}"
              + (f" ({'; '.join(result['bad'])})" if result["bad"] else ""))
    else:
        print_summary(result)
    if args.check and _check_status(result) != "ok":  # one line: what is wrong, the repair
        from bioflex_jsb.sinks.mcap.writers import unfinished_message

        line = (unfinished_message(args.file, f"no {', '.join(result['missing'])}")
                if _check_status(result) == "unfinished" else
                f"{args.file!r} is damaged: {'; '.join(result['problems'])}; "
                "--recover FIXED.mcap copies the intact chunks")
        print(f"bioflex-jsb info: {line}", file=sys.stderr)
        return EXIT_NO_RESULT
    return 0


def _check_status(result: dict) -> str:
    """ok, unfinished (no Data End/summary/footer, nothing else wrong) or damaged."""
    return "damaged" if result["problems"] else "unfinished" if not result["finished"] else "ok"


def print_summary(s: dict) -> None:
    """The summary of a log as text; every name and value read from the log
    :func:`escaped` (a hostile log cannot drive the terminal)."""
    e = escaped
    print(f"{e(s['file'])}: {s['messages']} messages in {s['chunks']} chunks, "
          f"t = {s['start_s']:.3f} … {s['end_s']:.3f} s ({s['duration_s']:.3f} s), "
          f"written by {e(s['library'])}")
    channels = [(e(c["topic"]), e(c["schema"]), c["messages"]) for c in s["channels"]]
    width = max([len(topic) for topic, _, _ in channels] + [5])
    print(f"{'topic':<{width}}  {'schema':<24} {'messages':>8}")
    for topic, schema, messages in channels:
        print(f"{topic:<{width}}  {schema:<24} {messages:>8}")
    for name, record in s["metadata"].items():
        print(f"metadata {e(name)}:")
        for key, value in record.items():
            if value.startswith(("{", "[")):
                try:
                    value = json.dumps(json.loads(value), separators=(", ", ": "))
                except ValueError:
                    pass
            print(f"  {e(key)}: {e(value)}")
    events = s.get("events") or []
    if events:
        print(f"events ({len(events)}):")
    for ev in events:
        print(f"  t = {ev['time_s']:.3f} s  {e(ev['level']):<7}  {e(ev['text'])}")
