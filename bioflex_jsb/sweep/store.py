"""Results tables on disk, written a row at a time as cases finish (adapter: file I/O).

* ``.csv``: one file, a header then one row per case. A row is written whole or not at all:
  it goes to the file in one ``write`` on an append descriptor, then ``fsync``; a write that
  fails part-way (disk full) is cut back to the previous end of the file before the error
  is raised. A row cut off by a kill (power loss) is dropped when the file is reopened with
  ``resume``.
* ``.parquet``: a Parquet *dataset*, a directory whose one visible file is the result,
  ``RESULT_NAME`` (``results.parquet``): what ``pyarrow.dataset`` /
  ``pyarrow.parquet.read_table(DIR)`` / ``pandas.read_parquet(DIR)`` read. While the sweep
  runs, each finished case is a part file in the hidden folder ``PARTS_DIR`` (``.parts``:
  dataset readers skip names that begin with a dot), written to a temporary name, flushed,
  ``fsync``-ed and renamed (the folder ``fsync``-ed), so no part is ever half a file. At the
  end the result and the parts are merged (:meth:`ParquetStore.close`): the new result is
  written under a hidden temporary name, ``fsync``-ed, and *renamed over* the old one (one
  atomic step), and only then are the parts deleted. A reader therefore sees exactly one
  result at every instant (the previous one until the rename, the merged one after; a kill
  between the steps leaves parts already merged, which :func:`read_results` and ``resume``
  read once, the last row of a case winning). On ``resume`` the result and every part are
  opened: a damaged one (a disk that lost it, an editor) is renamed ``.damaged-<name>``
  (hidden) and its cases run again. Outputs of earlier versions (visible ``part-*.parquet``
  files) are read as parts and merged.

Rows are keyed by ``case_id``; if a case appears twice (a kill between the merge's rename
and the parts' removal, or a failed case run again with ``--retry-failed``),
:func:`read_results` keeps the last one.

:class:`OutputLock`: one sweep at a time writes an output (an ``flock`` on a hidden file
beside it, released by the kernel if the sweep dies).
"""

from __future__ import annotations

import csv
import errno
import io
import os
import tempfile
import time
import uuid
from pathlib import Path
from typing import Any

SUFFIXES = (".csv", ".parquet")
RESULT_NAME = "results.parquet"  # the one visible file of a .parquet output
PARTS_DIR = ".parts"  # hidden: finished cases not merged yet
# Largest results table read back [bytes]: a row is ≈ 0.5-1 kB, so 10^7 cases are ≈ 10 GB.
MAX_TABLE_BYTES = 64 * 1024**3

# Called with the name of each step of the merge (ParquetStore.close) as it is reached:
# None in use; the fault tests kill the process at each step through it.
merge_checkpoint = None


def _checkpoint(step: str) -> None:
    if merge_checkpoint is not None:
        merge_checkpoint(step)


class StoreError(ValueError):
    """The results output cannot be used; one line."""


class OutputBusy(RuntimeError):
    """Another sweep holds the output's lock (one line)."""


def _fsync_dir(folder: Path) -> None:
    """Make a rename or a new file in ``folder`` durable (best effort where unsupported)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError as exc:  # e.g. EINVAL on file systems without directory fsync
        if exc.errno not in (errno.EINVAL, errno.EBADF, errno.ENOTSUP):
            raise
    finally:
        os.close(fd)


class OutputLock:
    """An exclusive, non-blocking ``flock`` on ``.<name>.lock`` beside ``path``: a second
    sweep on the same output is refused with :class:`OutputBusy` naming the holder's pid.
    The kernel releases the lock when its process dies, so a killed sweep never leaves a
    stale lock; :meth:`release` removes the file (checked by inode against a holder that
    raced the removal)."""

    def __init__(self, path: Path) -> None:
        import fcntl

        self.path = path.parent / f".{path.name}.lock"
        self.path.parent.mkdir(parents=True, exist_ok=True)
        while True:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.read(fd, 64).decode("ascii", "replace").strip() or "?"
                os.close(fd)
                raise OutputBusy(f"--out {str(path)!r} is being written by another sweep "
                                 f"(pid {holder}, lock {str(self.path)!r}); wait for it "
                                 "or choose another --out") from None
            try:
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)  # the holder removed the file as we locked it: take the new one
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        self._fd: int | None = fd

    def release(self) -> None:
        if self._fd is None:
            return
        try:
            os.unlink(self.path)
        except FileNotFoundError:
            pass
        os.close(self._fd)  # unlink first, then unlock: no one locks a file that then goes
        self._fd = None

    def __enter__(self) -> OutputLock:
        return self

    def __exit__(self, *exc) -> None:
        self.release()


def open_store(path: str | Path, columns: dict[str, str], resume: bool):
    """The store for ``path`` by its suffix; ``resume`` keeps (and reports) existing rows:
    ``done_ids`` (every case with a row) and ``failed_ids`` (those whose last row is
    ``failed``, run again with ``--retry-failed``)."""
    p = Path(path)
    if p.is_symlink() and not p.exists():  # the table would be created at its target
        raise StoreError(f"--out {str(p)!r} is a symbolic link to {os.readlink(p)!r}, which "
                         "does not exist; name the table's own path")
    suffix = p.suffix.lower()
    if suffix == ".csv":
        return CsvStore(p, columns, resume)
    if suffix == ".parquet":
        return ParquetStore(p, columns, resume)
    raise StoreError(f"--out {str(p)!r}: unknown suffix {p.suffix!r}; accepted: .parquet, .csv")


def _resumed_columns(path: Path, found: list[str], columns: dict[str, str]
                     ) -> dict[str, str]:
    """The columns to go on writing an existing table with: the campaign's, or those of the
    same campaign's table written before some of its columns existed (the RMS columns of
    turbulence, the flaperon's command peak: :data:`~bioflex_jsb.sweep.columns.LATER_COLUMNS`),
    which is resumed as it is, without them (its new rows then lack those values, as its
    earlier rows do); StoreError for any other table."""
    from bioflex_jsb.sweep.columns import LATER_COLUMNS

    if found == list(columns):
        return columns
    kept = [c for c in columns if c in found]
    if found == kept and all(c in LATER_COLUMNS for c in columns if c not in found):
        return {c: columns[c] for c in found}
    raise StoreError(f"--out {str(path)!r} has other columns than this campaign (other "
                     "metrics?); choose another --out")


def _exists_error(p: Path) -> StoreError:
    return StoreError(f"--out {str(p)!r} exists; add --resume to complete it, or choose "
                      "another --out")


def _check_writable(path: Path) -> None:
    """Refuse an output whose nearest existing folder cannot be written (before any run)."""
    folder = path if path.is_dir() else path.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    try:
        if not folder.is_dir():
            raise NotADirectoryError(20, "not a directory")
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise StoreError(f"--out {str(path)!r}: cannot write in {str(folder)!r}: "
                         f"{exc.strerror}") from None


def _open_table(path: Path):
    """A results table (or part) opened for reading: a regular file of at most
    :data:`MAX_TABLE_BYTES` (:func:`bioflex_jsb.files.open_input`); StoreError otherwise."""
    from bioflex_jsb.files import open_input

    return open_input(path, "results table", MAX_TABLE_BYTES, StoreError)


def _after_last_newline(fh, size: int) -> int:
    """The offset just after the last newline of the open file ``fh`` of ``size`` bytes (0
    without one), read backwards a block at a time."""
    block, end = 64 * 1024, size
    while end > 0:
        start = max(0, end - block)
        fh.seek(start)
        at = fh.read(end - start).rfind(b"\n")
        if at >= 0:
            return start + at + 1
        end = start
    return 0


def _text(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)  # round-trips exactly
    return str(value)


def _parse(text: str, kind: str) -> Any:
    if text == "":
        return None
    if kind == "float":
        return float(text)
    if kind == "int":
        return int(text)
    return text


class CsvStore:
    def __init__(self, path: Path, columns: dict[str, str], resume: bool) -> None:
        self.path = path
        self.columns = columns
        self.done_ids: set[str] = set()
        self.failed_ids: set[str] = set()
        self.damaged: list[str] = []
        if path.exists():
            if not resume:
                raise _exists_error(path)
            if not path.is_file():
                raise StoreError(f"--out {str(path)!r} is not a regular file")
            self._recover()
        _check_writable(path)
        self._fd: int | None = None  # opened with the first row: a sweep that never starts
        self._header = list(self.columns)  # leaves no file

    def _open(self) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_CLOEXEC,
                           0o644)
        if os.fstat(self._fd).st_size == 0:
            self._write_whole(self._line(self._header))
            _fsync_dir(self.path.parent)

    @staticmethod
    def _line(values: list[str]) -> bytes:
        buf = io.StringIO()
        csv.writer(buf).writerow(values)
        return buf.getvalue().encode("utf-8")

    def _write_whole(self, data: bytes) -> None:
        """Append ``data`` in full, durably, or leave the file as it was and raise."""
        end = os.fstat(self._fd).st_size
        view = memoryview(data)
        try:
            while view:
                n = os.write(self._fd, view)
                view = view[n:]
            os.fsync(self._fd)
        except OSError:
            try:
                os.ftruncate(self._fd, end)  # frees what the partial write took
            except OSError:
                pass  # the cut-off row is dropped on --resume
            raise

    def _recover(self) -> None:
        with _open_table(self.path) as raw:
            size = os.fstat(raw.fileno()).st_size
            end = _after_last_newline(raw, size)
        if end < size:  # a row cut off by a kill
            with open(self.path, "r+b") as fh:
                fh.truncate(end)
        with _open_table(self.path) as raw, io.TextIOWrapper(
                raw, newline="", encoding="utf-8", errors="replace") as fh:
            reader = csv.reader(fh)
            header = next(reader, None)
            if header is None:
                return
            self.columns = _resumed_columns(self.path, header, self.columns)
            k = header.index("case_id")
            st = header.index("status")
            for r in reader:
                if len(r) != len(header):
                    continue
                self.done_ids.add(r[k])
                if r[st] == "failed":
                    self.failed_ids.add(r[k])
                else:
                    self.failed_ids.discard(r[k])

    def append(self, row: dict[str, Any]) -> None:
        if self._fd is None:
            self._open()
        self._write_whole(self._line([_text(row.get(k)) for k in self.columns]))

    def close(self) -> None:
        if self._fd is not None:
            fd, self._fd = self._fd, None
            os.close(fd)


def _schema(columns: dict[str, str]):
    import pyarrow as pa

    types = {"str": pa.string(), "float": pa.float64(), "int": pa.int64()}
    return pa.schema([(name, types[kind]) for name, kind in columns.items()])


class ParquetStore:
    def __init__(self, path: Path, columns: dict[str, str], resume: bool) -> None:
        import pyarrow.parquet as pq

        self._pq = pq
        self.path = path
        self.columns = columns
        self.schema = _schema(columns)
        self.done_ids: set[str] = set()
        self.failed_ids: set[str] = set()
        self.damaged: list[str] = []  # parts set aside on resume (their cases run again)
        self._written = 0
        if path.exists():
            if not path.is_dir():
                raise StoreError(f"--out {str(path)!r} is a file; a .parquet output is a "
                                 "directory of part files")
            if any(path.iterdir()):
                if not resume:
                    raise _exists_error(path)
                for folder in (path, path / PARTS_DIR):  # a part or a merge cut by a kill
                    for tmp in folder.glob(".*.tmp"):
                        tmp.unlink()
                self._recover()
        _check_writable(path)

    def _recover(self) -> None:
        """Read the status of every case in every part; set damaged parts aside."""
        import pyarrow as pa

        for part in self._sources():
            try:
                with _open_table(part) as fh:
                    schema = self._pq.read_schema(fh)
                    if schema.names != self.schema.names:
                        self.columns = _resumed_columns(self.path, schema.names, self.columns)
                        self.schema = _schema(self.columns)
                    fh.seek(0)
                    table = self._pq.read_table(fh, columns=["case_id", "status"])
            except (pa.ArrowException, OSError, ValueError) as exc:
                if isinstance(exc, StoreError):
                    raise
                aside = part.with_name(f".damaged-{part.name}")
                os.replace(part, aside)
                self.damaged.append(aside.name)
                continue
            for cid, status in zip(table.column("case_id").to_pylist(),
                                   table.column("status").to_pylist(), strict=True):
                self.done_ids.add(cid)
                if status == "failed":
                    self.failed_ids.add(cid)
                else:
                    self.failed_ids.discard(cid)
        if self.damaged:
            _fsync_dir(self.path)
            _fsync_dir(self.path / PARTS_DIR)

    def _parts(self) -> list[Path]:
        """The finished cases not merged yet, oldest first (and parts of earlier versions,
        visible in the output folder)."""
        return _part_files(self.path)

    def _sources(self) -> list[Path]:
        """Everything that holds rows: the result, then the parts (a later row wins)."""
        result = self.path / RESULT_NAME
        return ([result] if result.is_file() else []) + self._parts()

    def _write(self, rows: list[dict[str, Any]], final: Path) -> Path:
        """Write ``rows`` as ``final``: temporary name, flush, fsync, rename, fsync of the
        folder. A failure (disk full) removes the temporary file and raises."""
        import pyarrow as pa

        table = pa.Table.from_pylist(
            [{k: r.get(k) for k in self.columns} for r in rows], schema=self.schema
        )
        final.parent.mkdir(parents=True, exist_ok=True)
        tmp = final.with_name(f".{final.name}.{uuid.uuid4().hex[:8]}.tmp")
        renamed = False
        try:
            with open(tmp, "wb") as fh:
                self._pq.write_table(table, fh)
                fh.flush()
                os.fsync(fh.fileno())
            if final.name == RESULT_NAME:
                _checkpoint("written")
            os.replace(tmp, final)  # atomic: the old file or the new, never neither/both
            renamed = True
        finally:
            if not renamed:  # whatever stopped it (disk full, Ctrl-C): no temporary stays
                tmp.unlink(missing_ok=True)
        _fsync_dir(final.parent)
        return final

    def append(self, row: dict[str, Any]) -> None:
        name = f"part-{time.time_ns():020d}-{row['case_id']}.parquet"
        self._write([row], self.path / PARTS_DIR / name)
        self._written += 1

    def close(self) -> None:
        """Merge the result and the parts into a new result, renamed over the old one,
        then delete the parts (module docstring: one visible result at every instant). A
        failure here (disk full) loses nothing: the parts stay, ``--resume`` merges."""
        parts = self._parts() if self.path.is_dir() else []
        if not parts:
            return
        rows = read_results(self.path, self.columns)
        _checkpoint("read")
        self._write(rows, self.path / RESULT_NAME)
        _checkpoint("renamed")
        for i, p in enumerate(parts):
            p.unlink()
            if i == 0:
                _checkpoint("part deleted")
        _fsync_dir(self.path / PARTS_DIR if (self.path / PARTS_DIR).is_dir() else self.path)
        _fsync_dir(self.path)
        _checkpoint("merged")


def _part_files(folder: Path) -> list[Path]:
    """The part files of a .parquet output: in PARTS_DIR, and visible ones of earlier
    versions; in the order they were written (their names begin with time.time_ns)."""
    found = list((folder / PARTS_DIR).glob("part-*.parquet")) + list(folder.glob("part-*.parquet"))
    return sorted(found, key=lambda p: p.name)


def read_results(path: str | Path, columns: dict[str, str] | None = None) -> list[dict]:
    """Rows of a results table (CSV or Parquet dataset), one per case id, in case order."""
    p = Path(path)
    rows: list[dict[str, Any]]
    if p.suffix.lower() == ".csv":
        with _open_table(p) as raw, io.TextIOWrapper(raw, newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            raw = [r for r in reader if None not in r.values()]
        if columns is None:
            from bioflex_jsb.sweep.columns import METRIC_COLUMNS, result_columns

            # every column a table can have, with its type (aero: text)
            columns = result_columns(list(METRIC_COLUMNS), "unsteady", turbulence=True,
                                     controller=True)
        rows = [{k: _parse(v, columns.get(k, "float")) for k, v in r.items()} for r in raw]
    else:
        import pyarrow.parquet as pq

        if p.is_dir():
            result = p / RESULT_NAME
            files = ([result] if result.is_file() else []) + _part_files(p)
        else:
            files = [p]
        rows = []
        for f in files:
            with _open_table(f) as fh:
                rows.extend(pq.read_table(fh).to_pylist())
    by_id: dict[str, dict[str, Any]] = {}
    for r in rows:
        by_id[r["case_id"]] = r
    return sorted(by_id.values(), key=lambda r: (r.get("case_index") or 0, r["case_id"]))
