"""``bioflex-jsb sweep``: a campaign of gust runs and LTI metrics on local cores or Dask."""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from bioflex_jsb.cli.common import UsageError, print_json

HELP = """Run every case of a campaign file (wings or axis positions x speeds [m/s] x gusts x
turbulence seeds x models; docs/sweeps.md) and write one row per case with every input and
the asked metrics (gust-run peaks in SI: m/s, rad, rad/s, load factor; flutter speed [m/s];
LTI eigenvalues [rad/s]). Rows are written as cases finish, to --out (.parquet: a directory
of part files compacted at the end; .csv: appended). A case that fails or diverges is
recorded with its error; a worker process that dies has its case retried once. By default
the cases run on local processes, one per core; --scheduler sends them to a Dask cluster."""

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
    p.add_argument("--logs", metavar="DIR", default=None,
                   help="write each case's gust run to DIR/CASE_ID.mcap (on the worker's "
                   "filesystem)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(run=run)


def _progress(total: int, initial: int, label: str):
    """tqdm bar on a terminal (done/failed/remaining and ETA), None otherwise."""
    if not sys.stderr.isatty():
        return None
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, desc=label, unit="case", file=sys.stderr,
                dynamic_ncols=True)


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.sweep.campaign import CampaignError, load_campaign
    from bioflex_jsb.sweep.driver import missing_cases, run_sweep
    from bioflex_jsb.sweep.store import StoreError, open_store

    try:
        campaign = load_campaign(args.campaign)
    except CampaignError as exc:
        raise UsageError(f"campaign {args.campaign}: {exc}") from None
    if args.scheduler and args.scheduler != "local" and args.workers is not None:
        raise UsageError("--workers applies to local processes and --scheduler local; a "
                         "cluster's workers are started with it (dask worker)")
    out = Path(args.out) if args.out else Path(f"{campaign.name}.parquet")
    cases = campaign.cases()
    try:
        store = open_store(out, campaign.columns(), resume=args.resume)
    except StoreError as exc:
        raise UsageError(str(exc)) from None
    todo = missing_cases(cases, store.done_ids)

    executor = _executor(args)
    bar = _progress(len(cases), len(cases) - len(todo), campaign.name)

    def on_row(summary, row):
        if bar is not None:
            bar.update(1)
            bar.set_postfix_str(f"done {summary.run + summary.skipped} failed "
                                f"{summary.counts['failed']} remaining {summary.remaining}",
                                refresh=False)

    try:
        if todo:
            with executor:
                summary = run_sweep(todo, store, executor, total=len(cases), on_row=on_row)
        else:
            summary = run_sweep([], store, executor, total=len(cases))
    except (*_executor_errors(), StoreError) as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:  # the results output failed mid-sweep (disk full, removed, ...)
        raise UsageError(f"--out {str(out)!r}: cannot write: {exc.strerror or exc}") from None
    finally:
        if bar is not None:
            bar.close()
        store.close()
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
    if summary.interrupted:
        print(f"bioflex-jsb sweep: interrupted with {summary.remaining} cases left; "
              f"{out} keeps the finished ones: rerun with --resume", file=sys.stderr)
        return 130
    return 0


def _executor(args):
    if args.scheduler:
        from bioflex_jsb.sweep.dask_cluster import DaskExecutor

        if args.scheduler == "local":
            return DaskExecutor(None, workers=args.workers or 2, log_dir=args.logs)
        return DaskExecutor(args.scheduler, log_dir=args.logs)
    from bioflex_jsb.sweep.local import LocalExecutor

    return LocalExecutor(args.workers, log_dir=args.logs)


def _executor_errors() -> tuple[type[Exception], ...]:
    from bioflex_jsb.sweep.dask_cluster import DaskUnavailable

    return (DaskUnavailable,)
