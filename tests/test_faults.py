"""The fault table of docs/reliability.md as tests: concurrency with real processes, full
disks (a real small tmpfs where this machine lets root mount one, and a writer that raises
ENOSPC everywhere), kills, signals at awkward moments, hostile input files.

Every fault must end with one line on stderr and the documented exit status (0 done, 2 bad
input, 3 diverged, 4 the machine stopped the work, 130 SIGINT/SIGTERM). Nothing here
depends on PATH (``sys.executable``) or on how loaded the machine is (deadlines are minutes
where the normal time is seconds; waits poll for the state they need).
"""

from __future__ import annotations

import errno
import json
import os
import signal
import stat
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from bioflex_jsb import cli
from bioflex_jsb.sweep.campaign import (
    RUN_INFO_COLUMNS,
    CampaignError,
    RecordingError,
    case_id,
    load_campaign,
    parse_campaign,
)
from bioflex_jsb.sweep.driver import MissingCases, run_sweep
from bioflex_jsb.sweep.local import LocalExecutor
from bioflex_jsb.sweep.store import OutputBusy, OutputLock, open_store, read_results

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable

# 6 short gust cases (rigid model, 0.4 s flown): ≈ 0.2 s each, logs ≈ 150 kB each
SHORT = """
name = "short"
metrics = ["gust"]

[run]
duration_s = 0.4
gust_start_s = 0.1

[axes]
wings = ["optimised"]
speeds_m_s = [14.0, 15.0, 16.0, 17.0, 18.0, 19.0]
gusts = ["sharp:3"]
models = ["rigid"]
"""


def env(**extra) -> dict[str, str]:
    e = dict(os.environ)
    e.update({"PYTHONPATH": str(ROOT), "PYTHONUNBUFFERED": "1", **extra})
    return e


def bioflex(*argv, timeout=300, **kw) -> subprocess.CompletedProcess:
    """``python -m bioflex_jsb ARGV`` in a fresh interpreter (this one's, not PATH's)."""
    return subprocess.run([PY, "-m", "bioflex_jsb", *map(str, argv)], capture_output=True,
                          text=True, timeout=timeout, env=kw.pop("env", env()), **kw)


def one_line(err: str) -> str:
    lines = [x for x in err.strip().splitlines() if x.strip()]
    assert len(lines) == 1, err[-3000:]
    assert "Traceback" not in err
    return lines[0]


def visible(out: Path) -> list[str]:
    """What a dataset reader sees of a .parquet output (it skips names starting with '.')."""
    return sorted(p.name for p in out.iterdir() if not p.name.startswith((".", "_")))


def comparable(rows):
    return [{k: v for k, v in r.items() if k not in RUN_INFO_COLUMNS} for r in rows]


def sweep(argv, monkeypatch=None):
    if "sweep" not in cli.COMMAND_MODULES and monkeypatch is not None:
        monkeypatch.setattr(cli, "COMMAND_MODULES", cli.COMMAND_MODULES + ("sweep",))
    return cli.main(["sweep", *map(str, argv)])


@pytest.fixture()
def short(tmp_path):
    p = tmp_path / "short.toml"
    p.write_text(SHORT)
    return p


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted table of SHORT (local processes)."""
    d = tmp_path_factory.mktemp("reference")
    (d / "short.toml").write_text(SHORT)
    out = d / "ref.csv"
    r = bioflex("sweep", d / "short.toml", "--out", out, "--workers", 2)
    assert r.returncode == 0, r.stderr
    rows = read_results(out)
    assert len(rows) == 6 and all(x["status"] == "ok" for x in rows)
    return comparable(rows)


# ---------------------------------------------------------------------------------------
# A small real file system (tmpfs) where root may mount one
# ---------------------------------------------------------------------------------------
def _can_mount() -> bool:
    return hasattr(os, "geteuid") and os.geteuid() == 0 and Path("/proc/filesystems").is_file() \
        and "tmpfs" in Path("/proc/filesystems").read_text()


class Tmpfs:
    def __init__(self, path: Path, size: str) -> None:
        self.path = path
        path.mkdir(parents=True, exist_ok=True)
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(path)],
                           capture_output=True, text=True)
        if r.returncode:
            pytest.skip(f"cannot mount a tmpfs here: {r.stderr.strip()}")

    def remount(self, opts: str) -> None:
        subprocess.run(["mount", "-o", f"remount,{opts}", str(self.path)], check=True)

    def unmount(self) -> None:
        subprocess.run(["umount", "-l", str(self.path)], check=False)


@pytest.fixture()
def tmpfs(tmp_path):
    if not _can_mount():
        pytest.skip("mounting a small file system needs root (CI runs as root)")
    made: list[Tmpfs] = []

    def make(name: str, size: str) -> Tmpfs:
        fs = Tmpfs(tmp_path / name, size)
        made.append(fs)
        return fs

    yield make
    for fs in made:
        fs.unmount()


# ---------------------------------------------------------------------------------------
# Logs never overwrite
# ---------------------------------------------------------------------------------------
def test_six_gust_runs_started_at_once_leave_six_distinct_readable_logs(tmp_path):
    logs = tmp_path / "logs"
    speeds = [13.0, 14.0, 15.0, 16.0, 17.0, 18.0]
    procs = [subprocess.Popen(
        [PY, "-m", "bioflex_jsb", "gust", "--duration", "0.5", "--gust-start", "0.1",
         "--speed", str(v), "--models", "rigid", "--json", "--plot", ""],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path,
        env=env(BIOFLEX_LOG_DIR=str(logs))) for v in speeds]
    outs = {}
    for v, p in zip(speeds, procs, strict=True):
        out, err = p.communicate(timeout=300)
        assert p.returncode == 0, err
        outs[v] = json.loads(out)["out"]
    assert len(set(outs.values())) == 6
    assert sorted(str(p) for p in logs.iterdir()) == sorted(outs.values())
    for v, path in outs.items():
        info = bioflex("info", "--json", path)
        assert info.returncode == 0, info.stderr
        run = json.loads(json.loads(info.stdout)["metadata"]["bioflex.run"]["description"])
        assert run["speed_m_s"] == v  # its own speed: no run wrote into another's file


def test_default_log_names_are_created_exclusively(tmp_path, monkeypatch):
    import argparse

    from bioflex_jsb.cli.common import log_path

    monkeypatch.setenv("BIOFLEX_LOG_DIR", str(tmp_path))
    monkeypatch.setattr(time, "strftime", lambda fmt, t=None: "20260101T000000Z")
    args = argparse.Namespace(out=None, no_log=False, force=False)
    names = [log_path(args, "gust", "optimised") for _ in range(3)]
    assert [Path(n).name for n in names] == [
        "gust-optimised-20260101T000000Z.mcap", "gust-optimised-20260101T000000Z-2.mcap",
        "gust-optimised-20260101T000000Z-3.mcap"]
    assert all(Path(n).is_file() and Path(n).stat().st_size == 0 for n in names)  # reserved
    # an aircraft's wing name has a colon: no default name carries one (Windows refuses it,
    # scp reads it as a host), nor any other character Windows refuses
    name = Path(log_path(args, "gust", 'aircraft:sgs_elastic<>"|?*')).name
    assert name == "gust-aircraft_sgs_elastic______-20260101T000000Z.mcap", name


def test_existing_out_is_refused_unless_force(tmp_path, capsys):
    out = tmp_path / "run.mcap"
    out.write_bytes(b"not a log of ours")
    argv = ["gust", "--duration", "0.2", "--gust-start", "0.1", "--models", "rigid",
            "--json", "--plot", "", "--out", str(out)]
    assert cli.main(argv) == 2
    assert "already exists" in one_line(capsys.readouterr().err)
    assert out.read_bytes() == b"not a log of ours"
    assert cli.main([*argv, "--force"]) == 0
    capsys.readouterr()
    assert out.read_bytes()[:8] == b"\x89MCAP0\r\n"
    # a directory is refused even with --force
    assert cli.main([*argv[:-1], str(tmp_path), "--force"]) == 2
    assert "not a regular file" in one_line(capsys.readouterr().err)


# ---------------------------------------------------------------------------------------
# Hostile input files: one line, exit 2, at once
# ---------------------------------------------------------------------------------------
def _hostile(tmp_path: Path, kind: str) -> Path:
    if kind == "fifo":
        p = tmp_path / "in.toml"
        os.mkfifo(p)
        return p
    if kind == "dev-zero":
        return Path("/dev/zero")
    if kind == "directory":
        p = tmp_path / "dir.toml"
        p.mkdir()
        return p
    p = tmp_path / "in.toml"
    if kind == "huge":
        with open(p, "wb") as fh:  # sparse: 200 MiB of size, no disk
            fh.truncate(200 * 1024 * 1024)
    elif kind == "latin-1":
        p.write_bytes('name = "caf\xe9"\n'.encode("latin-1"))
    elif kind == "deep":
        p.write_text("x = " + "[" * 5000 + "]" * 5000 + "\n")
    return p


KINDS = ["fifo", "dev-zero", "directory", "huge", "latin-1", "deep"]
NEEDLE = {"fifo": "FIFO", "dev-zero": "device", "directory": "directory", "huge": "limit",
          "latin-1": "UTF-8", "deep": "too deep"}


@pytest.mark.parametrize("kind", KINDS)
def test_hostile_campaign_file_is_one_line_exit_2(tmp_path, kind):
    bad = _hostile(tmp_path, kind)
    t0 = time.monotonic()
    r = bioflex("sweep", bad, "--out", tmp_path / "r.csv", timeout=120)
    assert r.returncode == 2, r.stderr
    line = one_line(r.stderr)
    assert NEEDLE[kind] in line and "campaign" in line, line
    assert not (tmp_path / "r.csv").exists()
    assert time.monotonic() - t0 < 120


@pytest.mark.parametrize("kind", KINDS)
def test_hostile_wing_and_modes_files_are_one_line(tmp_path, kind):
    from bioflex_jsb.flight_dynamics.wing_model import VariantError, load_variant_file
    from bioflex_jsb.structures.modal_file import ModalFileError, read_modal_file

    bad = _hostile(tmp_path, kind)
    with pytest.raises(VariantError) as wing:
        load_variant_file(bad)
    with pytest.raises(ModalFileError) as modes:
        read_modal_file(bad)
    for exc in (wing.value, modes.value):
        assert "\n" not in str(exc) and NEEDLE[kind] in str(exc), str(exc)


def test_fifo_as_wing_file_through_the_cli(tmp_path):
    bad = _hostile(tmp_path, "fifo")
    r = bioflex("modes", "--wing", bad, "--speed", 15, timeout=120)
    assert r.returncode == 2, r.stderr
    assert "FIFO" in one_line(r.stderr)


@pytest.mark.parametrize("kind", ["fifo", "dev-zero"])
def test_fifo_or_device_as_modes_file_through_the_cli(tmp_path, kind):
    bad = _hostile(tmp_path, kind)
    variant = tmp_path / "v.toml"
    variant.write_text(f'name = "v"\nmodes_file = "{bad}"\n')
    r = bioflex("modes", "--wing", variant, "--speed", 15, timeout=120)
    assert r.returncode == 2, r.stderr
    assert NEEDLE[kind] in one_line(r.stderr)


def test_inputs_within_the_limits_still_read(tmp_path):
    from bioflex_jsb.tomlfile import read_toml

    p = tmp_path / "ok.toml"
    p.write_text("x = " + "[" * 50 + "1" + "]" * 50 + '\nname = "é"\n', encoding="utf-8")
    assert read_toml(p, "test file", CampaignError)["name"] == "é"


# ---------------------------------------------------------------------------------------
# Sweeps: a case that failed vs a run that could not record it
# ---------------------------------------------------------------------------------------
def full_disk_case(case, log_dir):
    """run_case with a log file system of ``budget`` bytes shared by every worker: the
    writes that would pass it raise ENOSPC, as a full disk does (the budget is the size of
    the files in the directory, so every process sees the same disk)."""
    import builtins

    from bioflex_jsb.sinks.mcap import log as log_module
    from bioflex_jsb.sweep.evaluate import run_case

    budget = int(Path(log_dir, "budget").read_text())

    class Full:
        def __init__(self, fh):
            self._fh = fh

        def write(self, data):
            used = sum(p.stat().st_size for p in Path(log_dir).glob("*.mcap"))
            if used + len(data) > budget:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            n = self._fh.write(data)
            self._fh.flush()
            return n

        def __getattr__(self, name):
            return getattr(self._fh, name)

    def opener(path, mode="r", *a, **k):
        fh = builtins.open(path, mode, *a, **k)
        return Full(fh) if "w" in mode else fh

    log_module.open = opener
    try:
        return run_case(case, log_dir)
    finally:
        del log_module.open


def test_full_log_disk_stops_the_sweep_and_resume_matches_an_uninterrupted_run(
        short, tmp_path, reference, monkeypatch, capsys):
    logs = tmp_path / "logs"
    logs.mkdir()
    (logs / "budget").write_text(str(400_000))  # ≈ 2 of the 6 logs
    campaign = load_campaign(short)
    out = tmp_path / "r.csv"
    store = open_store(out, campaign.columns(), resume=False)
    with LocalExecutor(2, log_dir=str(logs), fn=full_disk_case) as ex:
        summary = run_sweep(campaign.cases(), store, ex)
    store.close()
    assert summary.stopped is not None and "No space left" in summary.stopped
    assert summary.counts["failed"] == 0  # nothing recorded as a case failure
    rows = read_results(out)
    assert len(rows) < 6 and all(r["status"] == "ok" for r in rows)
    # space again: --resume runs exactly the missing cases
    assert sweep([short, "--out", out, "--resume", "--logs", logs, "--workers", 2,
                  "--json"], monkeypatch) == 0
    done = json.loads(capsys.readouterr().out)
    assert done["already_done"] == len(rows) and done["run"] == 6 - len(rows)
    assert comparable(read_results(out)) == reference


def test_full_log_tmpfs_stops_the_sweep_exit_4_and_resume_completes_it(
        short, tmp_path, reference, tmpfs):
    fs = tmpfs("logs", "400k")
    out = tmp_path / "r.parquet"
    r = bioflex("sweep", short, "--out", out, "--workers", 2, "--logs", fs.path)
    assert r.returncode == 4, r.stderr
    line = one_line(r.stderr)
    assert "No space left on device" in line and "--resume" in line
    partial = read_results(out)
    assert len(partial) < 6 and all(x["status"] == "ok" for x in partial)
    fs.remount("size=8m")
    r = bioflex("sweep", short, "--out", out, "--workers", 2, "--logs", fs.path, "--resume")
    assert r.returncode == 0, r.stderr
    assert comparable(read_results(out)) == reference
    assert visible(out) == ["results.parquet"] and not list(out.rglob("part-*"))


def test_full_results_disk_keeps_whole_rows_exit_4(tmp_path, tmpfs):
    # 14 rows of ≈ 310 bytes: the table crosses its first 4 kB page, which the disk lacks
    camp = tmp_path / "rows.toml"
    camp.write_text(SHORT.replace("speeds_m_s = [14.0, 15.0, 16.0, 17.0, 18.0, 19.0]",
                                  "speeds_m_s = {start = 14.0, stop = 20.5, step = 0.5}"))
    ref = tmp_path / "ref.csv"
    assert bioflex("sweep", camp, "--out", ref, "--workers", 2).returncode == 0
    fs = tmpfs("out", "8k")  # one page for the lock file, one for the table
    out = fs.path / "r.csv"
    r = bioflex("sweep", camp, "--out", out, "--workers", 2)
    assert r.returncode == 4, r.stderr
    assert "results table" in one_line(r.stderr)
    data = out.read_bytes()
    assert data.endswith(b"\n") and len(data) <= 4096  # whole rows only
    n = len(read_results(out))
    assert 0 < n < 14
    fs.remount("size=4m")
    r = bioflex("sweep", camp, "--out", out, "--workers", 2, "--resume")
    assert r.returncode == 0, r.stderr
    assert comparable(read_results(out)) == comparable(read_results(ref))


def test_unwritable_log_directory_is_refused_before_any_case(short, tmp_path, tmpfs):
    fs = tmpfs("ro", "1m")
    fs.remount("ro")
    r = bioflex("sweep", short, "--out", tmp_path / "r.csv", "--logs", fs.path)
    assert r.returncode == 2
    assert "--logs" in one_line(r.stderr)
    assert not (tmp_path / "r.csv").exists()


def denied_case(case, log_dir):
    """run_case with a log directory that became unwritable during the sweep (root ignores
    modes, so opening the log raises EACCES as the kernel would for another user)."""
    import builtins

    from bioflex_jsb.sinks.mcap import log as log_module
    from bioflex_jsb.sweep.evaluate import run_case

    def opener(path, mode="r", *a, **k):
        if "w" in mode and case.speed_m_s >= 16.0:
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
        return builtins.open(path, mode, *a, **k)

    log_module.open = opener
    try:
        return run_case(case, log_dir)
    finally:
        del log_module.open


def test_log_directory_unwritable_mid_sweep_stops_it_unrecorded(short, tmp_path):
    campaign = load_campaign(short)
    out = tmp_path / "r.csv"
    store = open_store(out, campaign.columns(), resume=False)
    with LocalExecutor(1, log_dir=str(tmp_path), fn=denied_case) as ex:
        summary = run_sweep(MissingCases(campaign.iter_cases(), set()), store, ex,
                            total=campaign.n_cases)
    store.close()
    assert "Permission denied" in summary.stopped
    rows = read_results(out)
    assert {r["speed_m_s"] for r in rows} <= {14.0, 15.0}  # nothing at 16+ recorded
    assert summary.remaining == 6 - len(rows)


def test_retry_failed_runs_the_failed_cases_again(tmp_path, monkeypatch, capsys):
    camp = tmp_path / "f.toml"
    camp.write_text(SHORT.replace("speeds_m_s = [14.0, 15.0, 16.0, 17.0, 18.0, 19.0]",
                                  "speeds_m_s = [6.0, 15.0]"))
    out = tmp_path / "f.csv"
    assert sweep([camp, "--out", out, "--workers", 1], monkeypatch) == 0
    capsys.readouterr()
    first = {r["speed_m_s"]: r for r in read_results(out)}
    assert first[6.0]["status"] == "failed" and first[15.0]["status"] == "ok"
    assert sweep([camp, "--out", out, "--resume", "--json"], monkeypatch) == 0
    assert json.loads(capsys.readouterr().out)["run"] == 0  # failed counts as done
    assert sweep([camp, "--out", out, "--retry-failed", "--json"], monkeypatch) == 2
    assert "--resume" in one_line(capsys.readouterr().err)
    assert sweep([camp, "--out", out, "--resume", "--retry-failed", "--json"],
                 monkeypatch) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["run"] == 1 and res["already_done"] == 1
    again = {r["speed_m_s"]: r for r in read_results(out)}
    assert len(again) == 2
    assert again[6.0]["started_unix_s"] > first[6.0]["started_unix_s"]
    assert again[15.0]["started_unix_s"] == first[15.0]["started_unix_s"]


def test_damaged_parquet_part_is_set_aside_and_its_case_run_again(short, tmp_path, reference,
                                                                  monkeypatch, capsys):
    out = tmp_path / "r.parquet"
    campaign = load_campaign(short)
    store = open_store(out, campaign.columns(), resume=False)
    with LocalExecutor(2) as ex:
        run_sweep(campaign.cases(), store, ex)  # not closed: one part per case
    parts = sorted((out / ".parts").glob("part-*.parquet"))
    assert len(parts) == 6 and visible(out) == []  # unmerged: nothing visible yet
    victim = parts[2]
    victim.write_bytes(victim.read_bytes()[: victim.stat().st_size // 2])  # half a file
    assert sweep([short, "--out", out, "--resume", "--json"], monkeypatch) == 0
    captured = capsys.readouterr()
    assert "damaged" in one_line(captured.err)
    assert json.loads(captured.out)["run"] == 1
    assert (victim.parent / f".damaged-{victim.name}").is_file()
    assert comparable(read_results(out)) == reference


def test_parquet_part_written_atomically_on_a_full_disk(short, tmp_path, tmpfs):
    fs = tmpfs("pq", "64k")
    campaign = load_campaign(short)
    out = fs.path / "r.parquet"
    store = open_store(out, campaign.columns(), resume=False)
    row = {k: None for k in campaign.columns()}
    row.update(campaign.cases()[0].inputs(), status="ok")
    (fs.path / "filler").write_bytes(b"x" * (64 * 1024 - 4096))
    with pytest.raises(OSError) as exc:
        for _ in range(50):
            store.append(row)
    assert exc.value.errno == errno.ENOSPC
    assert not list(out.rglob(".*.tmp"))  # no temporary left behind
    import pyarrow.parquet as pq

    for part in out.rglob("part-*.parquet"):
        pq.read_table(part)  # every part that exists is whole


def test_a_second_sweep_on_the_same_output_is_refused(short, tmp_path):
    out = tmp_path / "r.csv"
    with OutputLock(out):
        with pytest.raises(OutputBusy, match=str(os.getpid())):
            OutputLock(out)
        r = bioflex("sweep", short, "--out", out, "--resume")
        assert r.returncode == 4
        assert "another sweep" in one_line(r.stderr)
    assert not (tmp_path / f".{out.name}.lock").exists()
    OutputLock(out).release()  # free again


def test_two_concurrent_resumes_do_not_run_cases_twice(short, tmp_path):
    out = tmp_path / "r.csv"
    procs = [subprocess.Popen([PY, "-m", "bioflex_jsb", "sweep", str(short), "--out",
                               str(out), "--resume", "--workers", "1"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              env=env()) for _ in range(2)]
    results = [(p.wait(timeout=300), p.stderr.read()) for p in procs]
    for p in procs:
        p.stdout.close()
        p.stderr.close()
    codes = sorted(c for c, _ in results)
    assert codes in ([0, 0], [0, 4]), results  # the second waits its turn or is refused
    with open(out, encoding="utf-8") as fh:
        assert len(fh.readlines()) == 1 + 6  # header + each case once


# ---------------------------------------------------------------------------------------
# Workers die with their driver
# ---------------------------------------------------------------------------------------
def _descendants(pid: int) -> set[int]:
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                stat_line = Path(f"/proc/{entry}/stat").read_text()
            except OSError:
                continue
            ppid = int(stat_line.rsplit(")", 1)[1].split()[1])
            children.setdefault(ppid, []).append(int(entry))
    out, todo = set(), [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            out.add(c)
            todo.append(c)
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


LONG = SHORT.replace("duration_s = 0.4", "duration_s = 600.0")


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc (Linux)")
@pytest.mark.parametrize("executor", [[], ["--scheduler", "local"]], ids=["local", "dask"])
def test_sigkill_of_the_sweep_driver_leaves_no_process(tmp_path, executor):
    camp = tmp_path / "long.toml"
    camp.write_text(LONG)
    proc = subprocess.Popen([PY, "-m", "bioflex_jsb", "sweep", str(camp), "--out",
                             str(tmp_path / "r.csv"), "--workers", "2", *executor],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env())
    deadline = time.monotonic() + 120
    seen: set[int] = set()
    while time.monotonic() < deadline:  # until both workers run a case
        seen |= _descendants(proc.pid)
        if _cpu_busy(seen) >= 2:
            break
        time.sleep(0.2)
    else:
        proc.kill()
        pytest.fail(f"the workers did not start: {sorted(seen)}")
    seen |= _descendants(proc.pid)
    proc.kill()
    proc.wait()
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and any(_alive(p) for p in seen):
        time.sleep(0.2)
    left = [p for p in seen if _alive(p)]
    for p in left:
        os.kill(p, signal.SIGKILL)
    assert not left, f"left running after the driver's SIGKILL: {left}"


def _cpu_busy(pids, min_s: float = 0.5) -> int:
    """How many of ``pids`` have used more than ``min_s`` of CPU (workers running a case)."""
    tick = os.sysconf("SC_CLK_TCK")
    n = 0
    for p in pids:
        try:
            fields = Path(f"/proc/{p}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if (int(fields[11]) + int(fields[12])) / tick > min_s and _is_worker(p):
            n += 1
    return n


def _cmdline(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def _parent(pid: int) -> int:
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    except OSError:
        return 0


def _is_worker(pid: int) -> bool:
    """A process that runs cases: not the resource tracker, not the forkserver itself (a
    forkserver's children, the local workers, share its command line)."""
    cmd = _cmdline(pid)
    if b"resource_tracker" in cmd:
        return False
    return b"forkserver" not in cmd or b"forkserver" in _cmdline(_parent(pid))


# ---------------------------------------------------------------------------------------
# Dask: a lost scheduler, no workers
# ---------------------------------------------------------------------------------------
def _free_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_lost_dask_scheduler_stops_the_sweep_exit_4_unrecorded(tmp_path):
    camp = tmp_path / "long.toml"
    camp.write_text(LONG)
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env())
    sched = subprocess.Popen([PY, "-m", "distributed.cli.dask_scheduler", "--host",
                              "127.0.0.1", "--port", str(port), "--no-dashboard"], **quiet)
    worker = subprocess.Popen([PY, "-m", "distributed.cli.dask_worker", address,
                               "--nthreads", "1", "--nworkers", "1", "--no-dashboard"], **quiet)
    try:
        out = tmp_path / "r.csv"
        driver = subprocess.Popen([PY, "-m", "bioflex_jsb", "sweep", str(camp), "--out",
                                   str(out), "--scheduler", address],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                  env=env())
        deadline = time.monotonic() + 180
        while _cpu_busy(_descendants(worker.pid), min_s=1.5) < 1:  # a case is running
            assert time.monotonic() < deadline and driver.poll() is None, \
                driver.communicate()[1] if driver.poll() is not None else "no case started"
            time.sleep(0.2)
        sched.kill()
        _, err = driver.communicate(timeout=120)
        assert driver.returncode == 4, err
        assert "lost the Dask scheduler" in one_line(err)
        assert not out.exists() or len(read_results(out)) == 0  # nothing recorded failed
    finally:
        for p in (sched, worker):
            if p.poll() is None:
                p.kill()
            p.wait()


def test_no_dask_worker_for_too_long_stops_the_sweep(short, tmp_path):
    from bioflex_jsb.sweep.dask_cluster import DaskExecutor

    campaign = load_campaign(short)
    store = open_store(tmp_path / "r.csv", campaign.columns(), resume=False)
    with DaskExecutor(None, workers=1) as ex:
        ex.no_workers_s = 2.0
        ex.cluster.scale(0)  # every worker gone, none coming back
        deadline = time.monotonic() + 60
        while ex.n_workers and time.monotonic() < deadline:
            time.sleep(0.1)
        summary = run_sweep(campaign.cases(), store, ex)
    store.close()
    assert summary.stopped is not None and "no worker" in summary.stopped
    assert summary.run == 0 and summary.remaining == 6


# ---------------------------------------------------------------------------------------
# A million cases start at once
# ---------------------------------------------------------------------------------------
def test_a_million_cases_start_without_expanding_the_campaign():
    t0 = time.monotonic()
    c = parse_campaign({"metrics": ["coefficients"], "axes": {
        "x_inertial_frac": {"start": 0.2, "stop": 0.8, "num": 1000},
        "x_elastic_frac": {"start": 0.2, "stop": 0.6, "num": 10},
        "speeds_m_s": {"start": 10.0, "stop": 20.0, "num": 100}}})
    assert c.n_cases == 1_000_000
    todo = MissingCases(c.iter_cases(), set())
    assert todo.any()
    first = next(iter(todo))
    assert time.monotonic() - t0 < 30.0  # 0.1 s on a laptop; the was > 60 s
    assert first.index == 0 and first.case_id == case_id(first)


def test_fast_case_ids_equal_the_reference_hash():
    c = load_campaign(ROOT / "scripts" / "campaigns" / "example.toml")
    assert [x.case_id for x in c.iter_cases()] == [case_id(x) for x in c.iter_cases()]


# ---------------------------------------------------------------------------------------
# Signals at any moment, including the final close and the interpreter's exit
# ---------------------------------------------------------------------------------------
HARNESS = """
import os, signal, sys, time
if __name__ == "__main__":  # not in the forkserver, which imports this module too
    sys.argv = ["bioflex-jsb", *sys.argv[1:]]
{patch}
    from bioflex_jsb.cli import main
    sys.exit(main())
"""


def harness(tmp_path: Path, patch: str, *argv, timeout=300):
    script = tmp_path / "harness.py"
    script.write_text(HARNESS.format(patch=textwrap.indent(textwrap.dedent(patch), "    ")))
    return subprocess.run([PY, str(script), *map(str, argv)], capture_output=True, text=True,
                          timeout=timeout, env=env(BIOFLEX_LOG_DIR=str(tmp_path / "logs")))


GUST = ["gust", "--duration", "0.3", "--gust-start", "0.1", "--models", "rigid", "--json",
        "--plot", ""]


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGINT"])
def test_signal_just_after_the_command_returned_exits_130_in_one_line(tmp_path, sig):
    patch = f"""
    import atexit
    def late():
        os.kill(os.getpid(), signal.{sig})
        time.sleep(5)  # a signal handler that did not exit would let this finish (0)
    atexit.register(late)
    """
    r = harness(tmp_path, patch, *GUST)
    assert r.returncode == 130, r.stderr
    assert "interrupted while exiting" in one_line(r.stderr)
    assert json.loads(r.stdout)["summary"]  # the complete output was flushed first


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGINT"])
def test_signal_during_the_final_close_of_a_log_exits_130_in_one_line(tmp_path, sig):
    patch = f"""
    from bioflex_jsb.sinks.mcap import log as _log
    _close = _log.RunLog.close
    def close(self, *a, **k):
        os.kill(os.getpid(), signal.{sig})
        return _close(self, *a, **k)
    _log.RunLog.close = close
    """
    r = harness(tmp_path, patch, *GUST)
    assert r.returncode == 130, r.stderr
    assert "interrupted" in one_line(r.stderr)


def test_signal_while_a_sweep_compacts_its_table_defers_until_it_is_whole(short, tmp_path):
    patch = """
    from bioflex_jsb.sweep import store as _store
    _close = _store.ParquetStore.close
    def close(self):
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(0.2)
        os.kill(os.getpid(), signal.SIGINT)  # a second one is deferred too
        return _close(self)
    _store.ParquetStore.close = close
    """
    out = tmp_path / "r.parquet"
    r = harness(tmp_path, patch, "sweep", short, "--out", out, "--workers", 2)
    assert r.returncode == 130, r.stderr
    assert "closing its files" in one_line(r.stderr)
    assert visible(out) == ["results.parquet"] and len(read_results(out)) == 6


def test_a_third_signal_while_closing_ends_at_once(tmp_path):
    patch = """
    from bioflex_jsb.cli import common
    from bioflex_jsb.cli import info as _info
    def run(args):
        with common.closing():
            for _ in range(3):
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.1)
            time.sleep(30)  # a hung close: the third signal must not wait for it
        return 0
    _info.run = run  # what register() hands to argparse
    """
    t0 = time.monotonic()
    r = harness(tmp_path, patch, "info", tmp_path / "none.mcap")
    assert r.returncode == 130 and time.monotonic() - t0 < 25, r.stderr
    assert "third signal" in one_line(r.stderr)


def test_sigterm_mid_sweep_keeps_the_finished_rows_exit_130(short, tmp_path):
    camp = tmp_path / "long.toml"
    camp.write_text(LONG.replace("[14.0, 15.0, 16.0, 17.0, 18.0, 19.0]",
                                 "[14.0, 15.0, 16.0]"))
    out = tmp_path / "r.csv"
    proc = subprocess.Popen([PY, "-m", "bioflex_jsb", "sweep", str(camp), "--out", str(out),
                             "--workers", "1"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env())
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and _cpu_busy(_descendants(proc.pid)) < 1:
        time.sleep(0.2)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "interrupted" in one_line(err) and "--resume" in err


# ---------------------------------------------------------------------------------------
# Disk full during a gust run
# ---------------------------------------------------------------------------------------
def test_disk_full_during_a_gust_run_is_one_line_exit_4(tmp_path, tmpfs):
    fs = tmpfs("gustlogs", "64k")
    r = bioflex("gust", "--duration", "2", "--gust-start", "0.1", "--models", "rigid",
                "--json", "--plot", "", env=env(BIOFLEX_LOG_DIR=str(fs.path)))
    assert r.returncode == 4, r.stderr
    assert "No space left on device" in one_line(r.stderr)


def test_recording_error_pickles_with_its_message():
    import pickle

    e = pickle.loads(pickle.dumps(RecordingError("case x: No space\nleft")))
    assert str(e) == "case x: No space left"


def test_lock_file_is_not_a_regular_stat_problem(tmp_path):
    out = tmp_path / "sub" / "r.csv"
    lock = OutputLock(out)
    st = os.stat(lock.path)
    assert stat.S_ISREG(st.st_mode) and lock.path.read_text().strip() == str(os.getpid())
    lock.release()
    assert not lock.path.exists()


# ---------------------------------------------------------------------------------------
# A damaged numba cache of the compiled step kernel heals itself
# ---------------------------------------------------------------------------------------
KERNEL = ("from bioflex_jsb.simulation import step_kernel as K; K.compile_now(); "
          "print(len(K.cache_files(K.step_kernel)))")


def _kernel(cache_dir: Path) -> subprocess.CompletedProcess:
    return subprocess.run([PY, "-c", KERNEL], capture_output=True, text=True, timeout=600,
                          env=env(NUMBA_CACHE_DIR=str(cache_dir)))


@pytest.fixture(scope="module")
def kernel_cache(tmp_path_factory):
    """A good cache of the kernel, compiled once in a fresh NUMBA_CACHE_DIR."""
    good = tmp_path_factory.mktemp("numba-good")
    r = _kernel(good)
    assert r.returncode == 0 and r.stdout.strip() == "2", r.stderr  # the index and the code
    return good


def _damage(path: Path, kind: str) -> None:
    import random

    data = path.read_bytes()
    if kind == "truncated":
        path.write_bytes(data[:len(data) // 2])
    elif kind == "empty":
        path.write_bytes(b"")
    else:  # garbage: the same length of random bytes (a fixed seed: the same bytes each run)
        path.write_bytes(random.Random(25).randbytes(len(data)))


@pytest.mark.parametrize("suffix", [".nbi", ".nbc"])
@pytest.mark.parametrize("kind", [
    pytest.param("truncated", marks=pytest.mark.slow), pytest.param("empty"),
    pytest.param("garbage", marks=pytest.mark.slow)])
def test_a_damaged_kernel_cache_is_discarded_recompiled_and_said_once(
        tmp_path, kernel_cache, kind, suffix):
    """Before: every run exited 1 (UnpicklingError / EOFError) until the file was deleted."""
    import shutil

    cache = tmp_path / "numba"
    shutil.copytree(kernel_cache, cache)
    (victim,) = [p for p in cache.rglob(f"step_kernel.step_kernel-*{suffix}")]
    _damage(victim, kind)
    r = _kernel(cache)
    assert r.returncode == 0, r.stderr[-3000:]
    line = one_line(r.stderr)
    assert "cache" in line and "damaged" in line and "compiling anew" in line, line
    assert r.stdout.strip() == "2"  # cached anew: an index and a code file
    again = _kernel(cache)  # healed: loaded from the new cache, nothing said
    assert again.returncode == 0 and again.stderr.strip() == "", again.stderr


# ---------------------------------------------------------------------------------------
# The Parquet merge is atomic: one visible result at every instant, whatever kills it
# ---------------------------------------------------------------------------------------
MERGE = """
import os, signal, sys
from bioflex_jsb.sweep import store
from bioflex_jsb.sweep.campaign import load_campaign
out, step, first, n = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
columns = load_campaign(sys.argv[5]).columns()
s = store.open_store(out, columns, resume=True)
for i in range(first, first + n):
    s.append({"case_id": f"case{i:02d}", "case_index": i, "status": "ok"})
def kill(reached):
    if reached == step:
        os.kill(os.getpid(), signal.SIGKILL)
store.merge_checkpoint = kill
s.close()
"""
MERGE_STEPS = ["read", "written", "renamed", "part deleted", "merged"]


def _merge(out: Path, step: str, first: int, n: int, campaign: Path):
    return subprocess.run([PY, "-c", MERGE, str(out), step, str(first), str(n), str(campaign)],
                          capture_output=True, text=True, timeout=120, env=env())


def _dataset_ids(out: Path) -> list[str]:
    """The case ids an independent reader (pyarrow.dataset) sees in the output."""
    import pyarrow.dataset as ds

    return sorted(ds.dataset(out, format="parquet").to_table(columns=["case_id"])
                  .column("case_id").to_pylist()) if visible(out) else []


@pytest.mark.parametrize("step", MERGE_STEPS)
def test_a_kill_at_any_step_of_the_merge_leaves_one_visible_result(short, tmp_path, step):
    """A result of 3 cases, then 3 more cases merged and the process SIGKILLed at ``step``:
    a dataset reader sees the old 3 rows or the new 6, each once, never both (before: 120
    rows for 60 cases after a kill between the merged file and the parts' removal); resume
    then merges to the 6."""
    out = tmp_path / "r.parquet"
    r = _merge(out, "none", 0, 3, short)  # the first session: merged, 3 rows
    assert r.returncode == 0, r.stderr
    old = [f"case{i:02d}" for i in range(3)]
    assert _dataset_ids(out) == old
    r = _merge(out, step, 3, 3, short)
    assert r.returncode == -signal.SIGKILL, r.stderr
    new = [f"case{i:02d}" for i in range(6)]
    seen = _dataset_ids(out)
    assert seen in (old, new), seen
    assert visible(out) == ["results.parquet"]
    assert [x["case_id"] for x in read_results(out)] == new  # our reader: every row, once
    s = open_store(out, load_campaign(short).columns(), resume=True)
    assert sorted(s.done_ids) == new
    s.close()
    assert _dataset_ids(out) == new and not list(out.rglob("part-*.parquet"))
    assert not list(out.rglob(".*.tmp"))


def test_sigkill_during_a_sweep_merge_then_resume(short, tmp_path):
    """The whole command: a sweep killed right after its merged result replaced the old one
    (the parts not yet deleted) shows 6 rows for 6 cases; --resume runs nothing again."""
    patch = """
    from bioflex_jsb.sweep import store as _store
    def _kill(step):
        if step == "renamed":
            os.kill(os.getpid(), signal.SIGKILL)
    _store.merge_checkpoint = _kill
    """
    out = tmp_path / "r.parquet"
    r = harness(tmp_path, patch, "sweep", short, "--out", out, "--workers", 2)
    assert r.returncode == -signal.SIGKILL, r.stderr
    assert len(_dataset_ids(out)) == 6 == len(set(_dataset_ids(out)))
    r = bioflex("sweep", short, "--out", out, "--workers", 2, "--resume", "--json")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["run"] == 0
    assert len(_dataset_ids(out)) == 6 and not list(out.rglob("part-*.parquet"))


@pytest.mark.parametrize("name", ["../../../x", "a/b", "..", ".hidden", "a\\b", "x\ny"])
def test_a_campaign_name_that_is_not_a_plain_file_name_is_refused(tmp_path, name):
    work = tmp_path / "deep" / "er"
    work.mkdir(parents=True)
    camp = work / "c.toml"
    camp.write_text(SHORT.replace('name = "short"', f"name = {json.dumps(name)}"))
    r = bioflex("sweep", camp, "--workers", 1, cwd=work)
    assert r.returncode == 2, r.stderr
    line = one_line(r.stderr)
    assert "name" in line and "plain file name" in line
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["c.toml", "deep", "er"]
