"""``bioflex-jsb sweep``: a campaign of gust runs and LTI metrics on local cores or Dask."""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from bioflex_jsb.cli.common import (
    EXIT_ENVIRONMENT,
    EXIT_NO_RESULT,
    EnvironmentFault,
    UsageError,
    closing,
    print_json,
)

HELP = """Run every case of a campaign file (wings or axis positions x speeds [m/s] x gusts x
turbulence seeds x models; docs/sweeps.md) and write one row per case with every input and
the asked metrics (gust-run peaks in SI: m/s, rad, rad/s, load factor; flutter speed [m/s];
LTI eigenvalues [rad/s]). Rows are written as cases finish, to --out (.parquet: a dataset
directory whose one file results.parquet is merged at the end from hidden per-case parts;
.csv: appended). A case that fails or diverges is
recorded with its error; a worker process that dies has its case retried once. A case the
machine could not run or record (no space for its log, an unwritable --logs directory, a
lost Dask scheduler or workers, the results table itself unwritable) is not recorded: the
sweep stops with exit status 4 and one line, and --resume runs it and the rest once the
cause is fixed (docs/reliability.md). The sweep exits 0 when every case has a row and one
has a result (failed cases are counted on stderr, their errors are in the table); when
every case of the table failed it exits 1 with one line and the first error. One sweep at
a time may write an --out. By default the cases run on local processes, one per core;
--scheduler sends them to a Dask cluster."""

_SCHEDULER = re.compile(r"^(tcp|tls|ucx|inproc)://[^\s/]+(:\d+)?/?$")


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--workers must be a whole number, got {text!r}")\
            from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"--workers must be ≥ 1, got {text!r}")
    return value


def scheduler_address(text: str) -> str:
    if text == "local" or _SCHEDULER.match(text):
        return text
    raise argparse.ArgumentTypeError(
        f"--scheduler must be tcp://HOST:PORT (or 'local' for a Dask LocalCluster), got {text!r}"
    )


def register(sub) -> None:
    p = sub.add_parser("sweep", help="parameter sweeps on local cores or a Dask cluster",
                       description=HELP)
    p.add_argument("campaign", metavar="CAMPAIGN.toml", help="campaign file (docs/sweeps.md)")
    p.add_argument("--out", metavar="RESULTS.parquet|RESULTS.csv", default=None,
                   help="results table; the suffix picks the format (default: the campaign's "
                   "name + .parquet in the current directory)")
    p.add_argument("--workers", type=positive_int, default=None,
                   help="local worker processes (default: one per core); with --scheduler "
                   "local, the LocalCluster's workers (default 2)")
    p.add_argument("--scheduler", type=scheduler_address, default=None,
                   metavar="tcp://HOST:PORT",
                   help="run the cases on this Dask scheduler ('local': a Dask LocalCluster)")
    p.add_argument("--resume", action="store_true",
                   help="complete an existing --out: run only the cases it does not hold")
    p.add_argument("--retry-failed", action="store_true",
                   help="with --resume: also run again the cases recorded as failed (their "
                   "new rows replace the old)")
    p.add_argument("--logs", metavar="DIR", default=None,
                   help="write each case's gust run to DIR/CASE_ID.mcap (on the worker's "
                   "filesystem)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(run=run)


def progress_bar(total: int, initial: int, label: str):
    """tqdm bar on a terminal (done/failed/remaining and ETA), None otherwise."""
    if not sys.stderr.isatty():
        return None
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, desc=label, unit="case", file=sys.stderr,
                dynamic_ncols=True)


def _check_log_dir(logs: str | None) -> None:
    """Refuse a --logs directory that cannot be created or written, before any case runs
    (one that stops being writable later stops the sweep: exit 4)."""
    if not logs:
        return
    import tempfile

    folder = Path(logs)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise UsageError(f"--logs {logs!r}: cannot write there: {exc.strerror}") from None


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.sweep.campaign import CampaignError, load_campaign
    from bioflex_jsb.sweep.store import SUFFIXES, OutputBusy, OutputLock

    try:
        campaign = load_campaign(args.campaign)
    except CampaignError as exc:
        raise UsageError(f"campaign {args.campaign}: {exc}") from None
    if args.scheduler and args.scheduler != "local" and args.workers is not None:
        raise UsageError("--workers applies to local processes and --scheduler local; a "
                         "cluster's workers are started with it (dask worker)")
    if args.retry_failed and not args.resume:
        raise UsageError("--retry-failed applies to --resume (an existing --out)")
    out = Path(args.out) if args.out else Path(f"{campaign.name}.parquet")
    if out.suffix.lower() not in SUFFIXES:
        raise UsageError(f"--out {str(out)!r}: unknown suffix {out.suffix!r}; accepted: "
                         ".parquet, .csv")
    _check_log_dir(args.logs)
    try:
        lock = OutputLock(out)
    except OutputBusy as exc:
        raise EnvironmentFault(str(exc)) from None
    except OSError as exc:
        raise UsageError(f"--out {str(out)!r}: cannot lock: {exc.strerror}") from None
    try:
        return _run_locked(args, campaign, out)
    finally:
        with closing():
            lock.release()


def _run_locked(args, campaign, out: Path) -> int:
    """The sweep once ``out`` is locked: open the table, run the missing cases, close."""
    from bioflex_jsb.sweep.driver import MissingCases, run_sweep
    from bioflex_jsb.sweep.store import StoreError, open_store

    try:
        store = open_store(out, campaign.columns(), resume=args.resume)
    except StoreError as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:  # e.g. setting a damaged part aside on a full disk
        raise EnvironmentFault(f"--out {str(out)!r}: cannot open: {exc.strerror}") from None
    if store.damaged:
        print(f"bioflex-jsb sweep: {len(store.damaged)} damaged part(s) of {out} set aside "
              f"as {', '.join(store.damaged[:3])}{' …' if len(store.damaged) > 3 else ''}; "
              "their cases run again", file=sys.stderr)
    if store.done_ids:  # a table of another campaign (or other settings) is not merged into
        ours = {c.case_id for c in campaign.iter_cases()}
        foreign = len(store.done_ids - ours)
        if foreign:
            store.close()
            raise UsageError(f"--resume {str(out)!r}: {foreign} of its {len(store.done_ids)} "
                             f"cases are not cases of campaign {campaign.name!r} (another "
                             "campaign, or its settings or axes changed); give another --out")
    done = store.done_ids - store.failed_ids if args.retry_failed else store.done_ids
    # rows of an earlier session with a result (ok or diverged): kept whatever runs now
    earlier_results = len(store.done_ids - store.failed_ids)
    first_error: list[str] = []  # the first failed case's error, for the closing line
    todo = MissingCases(campaign.iter_cases(), done)
    total = campaign.n_cases

    executor = _executor(args)
    bar = progress_bar(total, 0, campaign.name)
    if bar is not None:
        todo.on_skip = lambda: bar.update(1)

    def on_row(summary, row):
        if row.get("status") in (None, "failed") and not first_error:
            first_error.append(str(row.get("error") or "no error recorded"))
        if bar is not None:
            bar.update(1)
            bar.set_postfix_str(f"done {summary.run + summary.skipped} failed "
                                f"{summary.counts['failed']} remaining {summary.remaining}",
                                refresh=False)

    try:
        if todo.any():  # a complete table starts no workers
            with executor:
                summary = run_sweep(todo, store, executor, total=total, on_row=on_row)
        else:
            summary = run_sweep(todo, store, executor, total=total, on_row=on_row)
    except executor_errors() as exc:  # the cluster cannot be reached: nothing ran
        raise UsageError(str(exc)) from None
    finally:
        if bar is not None:
            bar.close()
    compacted = None
    with closing():  # a signal now is deferred: the table is finished first
        try:
            store.close()
        except OSError as exc:  # compaction failed (disk full): every part is still there
            compacted = (f"--out {str(out)!r}: cannot merge the parts ({exc.strerror}); "
                         "every row is kept in them: rerun with --resume to merge")
    if summary.stopped is None and compacted is not None:
        summary.stopped = compacted
    result = {"campaign": campaign.name, "out": str(out),
              "executor": executor.name, **summary.as_dict()}
    if args.json:
        print_json(result)
    else:
        c = summary.counts
        print(f"campaign {campaign.name}: {summary.total} cases, {summary.skipped} already in "
              f"{out}, {summary.run} run now ({c['ok']} ok, {c['diverged']} diverged, "
              f"{c['failed']} failed) in {summary.wall_time_s:.1f} s on {executor.name} "
              "workers")
        print(f"results written to {out}")
    if summary.stopped is not None:
        print(f"bioflex-jsb sweep: stopped: {summary.stopped}; {summary.remaining} cases "
              f"left, not recorded: fix the cause and rerun with --resume", file=sys.stderr)
        return EXIT_ENVIRONMENT
    if summary.interrupted:
        print(f"bioflex-jsb sweep: interrupted with {summary.remaining} cases left; "
              f"{out} keeps the finished ones: rerun with --resume", file=sys.stderr)
        return 130
    return _failures(summary, earlier_results, first_error, out)


def _failures(summary, earlier_results: int, first_error: list[str], out: Path) -> int:
    """The exit status of a finished sweep and its one stderr line about failed cases:
    EXIT_NO_RESULT when no row of the table has a result (every case failed: an aircraft
    that cannot fly these cases, a campaign outside its envelope), 0 otherwise (a line
    counting the failed cases run now, if any)."""
    failed = summary.counts["failed"]
    if not failed:
        return 0
    results = earlier_results + summary.counts["ok"] + summary.counts["diverged"]
    first = first_error[0] if first_error else "see the table's error column"
    if results == 0:
        print(f"bioflex-jsb sweep: every case failed ({failed} run now, no result in "
              f"{out}); the first: {first}", file=sys.stderr)
        return EXIT_NO_RESULT
    print(f"bioflex-jsb sweep: {failed} of the {summary.run} cases run now failed (their "
          f"errors are in {out}'s error column); the first: {first}", file=sys.stderr)
    return 0


def _executor(args):
    if args.scheduler:
        from bioflex_jsb.sweep.dask_cluster import DaskExecutor

        if args.scheduler == "local":
            return DaskExecutor(None, workers=args.workers or 2, log_dir=args.logs)
        return DaskExecutor(args.scheduler, log_dir=args.logs)
    from bioflex_jsb.sweep.local import LocalExecutor

    return LocalExecutor(args.workers, log_dir=args.logs)


def executor_errors() -> tuple[type[Exception], ...]:
    from bioflex_jsb.sweep.dask_cluster import DaskUnavailable

    return (DaskUnavailable,)
