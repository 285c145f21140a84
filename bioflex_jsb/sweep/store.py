"""Results tables on disk, written a row at a time as cases finish (adapter: file I/O).

* ``.csv``: one file, a header then one row per case, appended and flushed per case. A row
  cut off by a kill is dropped when the file is reopened with ``resume``.
* ``.parquet``: a Parquet *dataset*, a directory of part files (``part-*.parquet``), one per
  finished case while the sweep runs (written to a hidden name, then renamed, so a reader
  never sees half a file); at the end of the sweep the parts are compacted into one.
  ``pyarrow.parquet.read_table(DIR)`` / ``pandas.read_parquet(DIR)`` read the directory.

Rows are keyed by ``case_id``; if a case appears twice (a crash between writing the
compacted file and removing the parts), :func:`read_results` keeps the last one.
"""

from __future__ import annotations

import csv
import os
import tempfile
import time
import uuid
from pathlib import Path
from typing import Any

SUFFIXES = (".csv", ".parquet")


class StoreError(ValueError):
    """The results output cannot be used; one line."""


def open_store(path: str | Path, columns: dict[str, str], resume: bool):
    """The store for ``path`` by its suffix; ``resume`` keeps (and reports) existing rows."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".csv":
        return CsvStore(p, columns, resume)
    if suffix == ".parquet":
        return ParquetStore(p, columns, resume)
    raise StoreError(f"--out {str(p)!r}: unknown suffix {p.suffix!r}; accepted: .parquet, .csv")


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
        if path.exists():
            if not resume:
                raise _exists_error(path)
            self._recover()
        _check_writable(path)
        self._fh = None  # opened with the first row: a sweep that never starts leaves no file
        self._writer = None

    def _open(self) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        new = not self.path.exists() or self.path.stat().st_size == 0
        self._fh = open(self.path, "a", newline="", encoding="utf-8")  # noqa: SIM115
        self._writer = csv.DictWriter(self._fh, fieldnames=list(self.columns))
        if new:
            self._writer.writeheader()

    def _recover(self) -> None:
        data = self.path.read_bytes()
        if data and not data.endswith(b"\n"):  # a row cut off by a kill
            with open(self.path, "r+b") as fh:
                fh.truncate(data.rfind(b"\n") + 1)
        with open(self.path, newline="", encoding="utf-8") as fh:
            reader = csv.reader(fh)
            header = next(reader, None)
            if header is None:
                return
            if header != list(self.columns):
                raise StoreError(f"--out {str(self.path)!r} has other columns than this "
                                 "campaign (other metrics?); choose another --out")
            k = header.index("case_id")
            self.done_ids = {r[k] for r in reader if len(r) == len(header)}

    def append(self, row: dict[str, Any]) -> None:
        if self._fh is None:
            self._open()
        self._writer.writerow({k: _text(row.get(k)) for k in self.columns})
        self._fh.flush()

    def close(self) -> None:
        if self._fh is not None and not self._fh.closed:
            self._fh.close()


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
        self._written = 0
        if path.exists():
            if not path.is_dir():
                raise StoreError(f"--out {str(path)!r} is a file; a .parquet output is a "
                                 "directory of part files")
            if any(path.iterdir()):
                if not resume:
                    raise _exists_error(path)
                for tmp in path.glob(".*.tmp"):  # a part cut off by a kill
                    tmp.unlink()
                parts = self._parts()
                if parts:
                    schema = pq.read_schema(parts[0])
                    if schema.names != self.schema.names:
                        raise StoreError(f"--out {str(path)!r} has other columns than this "
                                         "campaign (other metrics?); choose another --out")
                    table = pq.read_table(path, columns=["case_id"], schema=self.schema)
                    self.done_ids = set(table.column("case_id").to_pylist())
        _check_writable(path)

    def _parts(self) -> list[Path]:
        return sorted(self.path.glob("part-*.parquet"))

    def _write(self, rows: list[dict[str, Any]], stem: str) -> Path:
        import pyarrow as pa

        table = pa.Table.from_pylist(
            [{k: r.get(k) for k in self.columns} for r in rows], schema=self.schema
        )
        self.path.mkdir(parents=True, exist_ok=True)
        final = self.path / f"{stem}.parquet"
        tmp = self.path / f".{stem}.parquet.tmp"
        self._pq.write_table(table, tmp)
        os.replace(tmp, final)
        return final

    def append(self, row: dict[str, Any]) -> None:
        self._write([row], f"part-{time.time_ns():020d}-{row['case_id']}")
        self._written += 1

    def close(self) -> None:
        """Compact the part files into one (new file first, then the old ones go)."""
        parts = self._parts() if self.path.is_dir() else []
        if len(parts) <= 1:
            return
        rows = read_results(self.path, self.columns)
        keep = self._write(rows, f"part-{time.time_ns():020d}-all-{uuid.uuid4().hex[:8]}")
        for p in parts:
            if p != keep:
                p.unlink()


def read_results(path: str | Path, columns: dict[str, str] | None = None) -> list[dict]:
    """Rows of a results table (CSV or Parquet dataset), one per case id, in case order."""
    p = Path(path)
    rows: list[dict[str, Any]]
    if p.suffix.lower() == ".csv":
        with open(p, newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            raw = [r for r in reader if None not in r.values()]
        if columns is None:
            from bioflex_jsb.sweep.campaign import METRIC_COLUMNS, result_columns

            columns = result_columns(list(METRIC_COLUMNS))
        rows = [{k: _parse(v, columns.get(k, "float")) for k, v in r.items()} for r in raw]
    else:
        import pyarrow.parquet as pq

        files = sorted(p.glob("part-*.parquet")) if p.is_dir() else [p]
        rows = []
        for f in files:
            rows.extend(pq.read_table(f).to_pylist())
    by_id: dict[str, dict[str, Any]] = {}
    for r in rows:
        by_id[r["case_id"]] = r
    return sorted(by_id.values(), key=lambda r: (r.get("case_index") or 0, r["case_id"]))
