"""Hostile files: every input file is a regular file of bounded size, read with a bound
(bioflex_jsb/files.py); MCAP decompression bombs; names and logs that must not steer the
program (docs/reliability.md, "Input files")."""

from __future__ import annotations

import ast
import os
import socket
import time
from pathlib import Path

import pytest

from bioflex_jsb.errors import InputError
from tests.cli_helpers import run_cli

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "bioflex_jsb"


def one_line(code: int, err: str, status: int = 2) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == status, err[-3000:]
    assert len(lines) == 1 and "Traceback" not in err, err[-3000:]
    return lines[0]


# ---------------------------------------------------------------------------------------
# The one reader: regular files only, the caller's bound
# ---------------------------------------------------------------------------------------
def _special(tmp_path: Path, kind: str) -> Path:
    if kind == "fifo":
        p = tmp_path / "fifo"
        os.mkfifo(p)
        return p
    if kind == "dev-zero":
        return Path("/dev/zero")
    if kind == "proc-mem":
        return Path("/proc/self/mem")
    if kind == "directory":
        return tmp_path
    if kind == "socket":
        p = tmp_path / "sock"
        s = socket.socket(socket.AF_UNIX)
        s.bind(str(p))
        s.close()
        return p
    p = tmp_path / "big"
    with open(p, "wb") as fh:  # sparse: 100 MB of size, no disk
        fh.truncate(100 * 1000 * 1000)
    return p


SPECIALS = ["fifo", "dev-zero", "proc-mem", "directory", "socket", "huge"]
WHY = {"fifo": "FIFO", "dev-zero": "device", "proc-mem": "/proc", "directory": "directory",
       "socket": "not a regular file", "huge": "limit"}


@pytest.mark.parametrize("kind", SPECIALS)
def test_the_one_reader_refuses_what_is_not_a_small_regular_file_at_once(tmp_path, kind):
    from bioflex_jsb.files import open_input, read_input_bytes

    path = _special(tmp_path, kind)
    t0 = time.monotonic()
    with pytest.raises(InputError) as exc:
        read_input_bytes(path, "test file", 1024 * 1024)
    with pytest.raises(InputError):
        open_input(path, "test file", 1024 * 1024)
    assert time.monotonic() - t0 < 2.0
    msg = str(exc.value)
    assert "\n" not in msg and WHY[kind] in msg and "test file" in msg, msg


def test_the_one_reader_reads_within_its_bound_and_names_a_long_path_in_one_line(tmp_path):
    from bioflex_jsb.files import read_input_bytes, read_input_text

    p = tmp_path / "ok.txt"
    p.write_text("é\n", encoding="utf-8")
    assert read_input_text(p, "test file", 3) == "é\n"
    with pytest.raises(InputError, match="more than the limit of 2 bytes"):
        read_input_bytes(p, "test file", 2)
    with pytest.raises(InputError) as exc:
        read_input_bytes(tmp_path / ("x" * 5000), "test file", 10)
    assert "\n" not in str(exc.value) and len(str(exc.value)) < 400, str(exc.value)


# The readers of the package: every file is opened through bioflex_jsb.files. A call below
# outside files.py is a reader that bypasses it (the allowed ones write, or read the kernel's
# own /proc tables on purpose).
_READ_CALLS = {"read_bytes", "read_text", "fromfile", "loadtxt", "genfromtxt", "load", "parse",
               "loadmat", "read_table", "read_schema", "mmap"}
_ALLOWED = {
    ("sinks/mcap/writers.py", "open"),  # /proc/<pid>/fdinfo: which process writes a log
}


def _readers(tree: ast.AST) -> list[tuple[str, int]]:
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        f = node.func
        name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
        if name == "open" and isinstance(f, ast.Name):
            mode = node.args[1] if len(node.args) > 1 else next(
                (k.value for k in node.keywords if k.arg == "mode"), None)
            text = mode.value if isinstance(mode, ast.Constant) else "r"
            if "r" in text and "+" not in text:
                found.append(("open", node.lineno))
        elif name in _READ_CALLS and isinstance(f, ast.Attribute):
            base = f.value
            owner = base.id if isinstance(base, ast.Name) else getattr(base, "attr", "")
            if name == "load" and owner not in ("np", "numpy", "json", "tomllib", "pickle"):
                continue
            if name == "parse" and owner not in ("ET", "ElementTree", "etree"):
                continue
            first = node.args[0] if node.args else None
            if isinstance(first, ast.Name) and first.id == "fh":
                continue  # an open_input file handed to pyarrow
            if isinstance(first, ast.Call) and getattr(first.func, "attr", "") in (
                    "BytesIO", "fileno"):
                continue  # bytes read by the helper; the map of an open_input file
            found.append((name, node.lineno))
    return found


def test_every_reader_of_a_file_goes_through_the_one_helper():
    bypass = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel == "files.py":
            continue
        for name, line in _readers(ast.parse(path.read_text(encoding="utf-8"))):
            if (rel, name) not in _ALLOWED:
                bypass.append(f"{rel}:{line} {name}")
    assert not bypass, "files read without bioflex_jsb.files: " + ", ".join(bypass)


# ---------------------------------------------------------------------------------------
# Each reader through the command line or the API
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["dev-zero", "fifo", "huge"])
def test_a_signing_key_that_is_no_small_regular_file_is_one_line_exit_2(tmp_path, kind,
                                                                        capsys):
    from bioflex_jsb.links.mavlink import LinkError, read_signing_key

    path = _special(tmp_path, kind)
    t0 = time.monotonic()
    with pytest.raises(LinkError) as exc:
        read_signing_key(path)
    assert WHY[kind] in str(exc.value) and "signing key" in str(exc.value), str(exc.value)
    code, _out, err = run_cli(capsys, "sitl", "--signing-key", str(path), "--duration", "1",
                              "--mavlink", "udpin:127.0.0.1:0")
    assert "signing key" in one_line(code, err)
    assert time.monotonic() - t0 < 10.0


@pytest.mark.parametrize("argv", [["info"], ["info", "--check"], ["plot"]])
@pytest.mark.parametrize("kind", ["proc-mem", "dev-zero", "fifo", "directory"])
def test_a_log_that_is_no_regular_file_is_one_line_exit_2_not_4(tmp_path, capsys, argv,
                                                                 kind):
    path = _special(tmp_path, kind)
    code, _out, err = run_cli(capsys, *argv, str(path))
    assert WHY[kind] in one_line(code, err)


def test_recover_and_rerun_of_proc_self_mem_are_exit_2(tmp_path, capsys):
    code, _out, err = run_cli(capsys, "info", "/proc/self/mem", "--recover",
                              str(tmp_path / "fixed.mcap"))
    assert "/proc" in one_line(code, err)
    assert not (tmp_path / "fixed.mcap").exists()
    code, _out, err = run_cli(capsys, "rerun", "/proc/self/mem", "--out",
                              str(tmp_path / "again.mcap"))
    assert "/proc" in one_line(code, err)


def test_a_model_file_from_a_device_or_claiming_huge_arrays_is_one_line(tmp_path):
    import zipfile

    from bioflex_jsb.sinks.model_export import read_state_space

    os.symlink("/dev/zero", tmp_path / "zero.npz")
    with pytest.raises(InputError, match="device"):
        read_state_space(tmp_path / "zero.npz")
    bomb = tmp_path / "bomb.npz"  # 1 GB of zeros in a few kB
    with zipfile.ZipFile(bomb, "w", compression=zipfile.ZIP_DEFLATED) as z, \
            z.open("a.npy", "w", force_zip64=True) as member:
        block = bytes(1 << 20)
        for _ in range(1024):
            member.write(block)
    assert bomb.stat().st_size < 5 * 1024 * 1024
    with pytest.raises(InputError, match="declare"):
        read_state_space(bomb)


def test_an_op2_file_that_is_a_fifo_is_refused_without_hanging(tmp_path):
    pytest.importorskip("pyyeti")
    from bioflex_jsb.structures.nastran import NastranError, read_op2_modes

    with pytest.raises(NastranError, match="FIFO"):
        read_op2_modes(_special(tmp_path, "fifo"), [1, 2])


def test_a_plot_target_that_is_a_fifo_is_not_ours_and_not_read(tmp_path):
    from bioflex_jsb.plot_files import check_plot_target, is_our_plot

    fifo = tmp_path / "f.png"
    os.mkfifo(fifo)
    assert not is_our_plot(fifo)
    with pytest.raises(InputError, match="exists"):
        check_plot_target(fifo)
