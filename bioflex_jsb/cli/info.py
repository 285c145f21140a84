"""``bioflex-jsb info``: what an MCAP log holds; recovery of a log whose writer was killed."""

from __future__ import annotations

import argparse
import json

from bioflex_jsb.cli.common import UsageError, print_json

HELP = """Summarise an MCAP log written by bioflex-jsb (or any MCAP file): its channels
(topic, schema, message count), the number of messages and chunks, the time span [s of
simulation time], the metadata records (the run's command and arguments, wing, gust, time
step, versions) and the events on /bioflex/events (time [s], level, text: a run that
diverged, a SITL session's STATUSTEXT: crashes, resets, mode changes). Read through the
mcap package's indexed reader. A log whose writer was killed (SIGKILL, power loss) has no
summary; --recover FIXED.mcap copies every complete chunk of it into a new, finished file
(at most the last chunk, 0.9 s of simulated time, is lost); a damaged chunk is skipped,
every intact chunk after it kept, and the skipped ones are named. --check decompresses
every chunk and verifies its CRC (and the data section's): exit status 1 and the damaged
chunks if any fails. Logs in protobuf (this version) and JSON (older versions) are read
alike."""


def register(sub) -> None:
    p = sub.add_parser("info", help="channels, counts, duration and metadata of an MCAP log",
                       description=HELP)
    p.add_argument("file", metavar="FILE.mcap", help="the log")
    p.add_argument("--recover", metavar="FIXED.mcap",
                   help="write the complete records of a truncated FILE.mcap to FIXED.mcap")
    p.add_argument("--check", action="store_true",
                   help="verify the CRC of every chunk (exit 1 if one fails)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import sys

    from bioflex_jsb.sinks.mcap import LogError, LogWriteError, check_chunks, recover, summarise

    if args.check and args.recover:
        raise UsageError("--check and --recover are separate jobs; give one")
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
        status = "damaged" if result["bad"] or result["data_crc"] == "bad" else "ok"
        print(f"{result['file']}: {status}: {result['chunks']} chunks, "
              f"{len(result['bad'])} with a bad CRC or record, data section CRC "
              f"{result['data_crc']}" + (f" ({'; '.join(result['bad'])})"
                                         if result["bad"] else ""))
    else:
        print_summary(result)
    if args.check and (result["bad"] or result["data_crc"] == "bad"):
        print(f"bioflex-jsb info: {args.file}: damaged chunks: recover the intact ones with "
              f"--recover FIXED.mcap", file=sys.stderr)
        return 1
    return 0


def print_summary(s: dict) -> None:
    print(f"{s['file']}: {s['messages']} messages in {s['chunks']} chunks, "
          f"t = {s['start_s']:.3f} … {s['end_s']:.3f} s ({s['duration_s']:.3f} s), "
          f"written by {s['library']}")
    width = max([len(c["topic"]) for c in s["channels"]] + [5])
    print(f"{'topic':<{width}}  {'schema':<24} {'messages':>8}")
    for c in s["channels"]:
        print(f"{c['topic']:<{width}}  {c['schema']:<24} {c['messages']:>8}")
    for name, record in s["metadata"].items():
        print(f"metadata {name}:")
        for key, value in record.items():
            if value.startswith(("{", "[")):
                try:
                    value = json.dumps(json.loads(value), separators=(", ", ": "))
                except ValueError:
                    pass
            print(f"  {key}: {value}")
    events = s.get("events") or []
    if events:
        print(f"events ({len(events)}):")
    for e in events:
        print(f"  t = {e['time_s']:.3f} s  {e['level']:<7}  {e['text']}")
