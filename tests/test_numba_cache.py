"""numba's cache of the compiled kernels is per user and per version of the kernels' sources
(bioflex_jsb/__init__.py), and a first run that has to compile says so on a terminal
(step_kernel.say_if_compiling)."""

import io
import os
import subprocess
import sys

WHERE = "import numba; print(numba.config.CACHE_DIR)"


def _cache_dir(env: dict) -> str:
    code = "import bioflex_jsb; " + WHERE
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120, env=env)
    assert run.returncode == 0, run.stderr[-2000:]
    return run.stdout.strip()


def test_the_cache_is_the_users_unless_numba_cache_dir_says_otherwise(tmp_path):
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME")}
    import bioflex_jsb

    key = bioflex_jsb.kernel_sources_key()
    home = tmp_path / "home"
    assert _cache_dir({**env, "HOME": str(home)}) == str(home / ".cache" / "bioflex-jsb"
                                                          / "numba" / key)
    xdg = tmp_path / "xdg"
    assert _cache_dir({**env, "HOME": str(home), "XDG_CACHE_HOME": str(xdg)}) == \
        str(xdg / "bioflex-jsb" / "numba" / key)
    own = tmp_path / "own"
    assert _cache_dir({**env, "NUMBA_CACHE_DIR": str(own)}) == str(own)


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


class _Dispatcher:
    """What say_if_compiling reads of a numba dispatcher: its overloads in memory and its
    cache's files (none here: a cold cache)."""

    def __init__(self, path: str) -> None:
        self.overloads = {}
        files = type("Files", (), {"_cache_path": path, "_index_path": os.path.join(path, "x.nbi"),
                                   "_data_name_pattern": "x-{number:d}.nbc"})()
        self._cache = type("Cache", (), {"_cache_file": files})()


def test_a_cold_compile_is_said_once_on_a_terminal_and_never_on_a_pipe(tmp_path, monkeypatch):
    from bioflex_jsb.simulation import step_kernel as K

    monkeypatch.setattr(K, "COMPILING_SAID", [])
    cold = _Dispatcher(str(tmp_path))
    pipe = io.StringIO()
    monkeypatch.setattr(sys, "stderr", pipe)
    K.say_if_compiling(cold, "coupled step")
    assert pipe.getvalue() == ""  # a script's or a test's stderr: errors only
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    K.say_if_compiling(cold, "coupled step")
    K.say_if_compiling(cold, "coupled step")  # once a process
    lines = term.getvalue().splitlines()
    assert len(lines) == 1 and "compiling the coupled step" in lines[0], lines
    (tmp_path / "x.nbi").write_bytes(b"index")  # cached: nothing to say
    monkeypatch.setattr(K, "COMPILING_SAID", [])
    warm = _Terminal()
    monkeypatch.setattr(sys, "stderr", warm)
    K.say_if_compiling(cold, "coupled step")
    assert warm.getvalue() == ""


def test_the_cache_key_covers_every_module_that_compiles(tmp_path):
    """The cache folder is named by the content of every module that imports numba (a
    kernel calling another file's kernel kept its stale machine code when only that file
    changed: the full-span kernel, cached against the half wing's kernel before its
    flaperon block, flew wrong values until the cache was cleared); an edit of any of them
    is a new folder."""
    import ast
    import hashlib
    from pathlib import Path

    import bioflex_jsb

    package = Path(bioflex_jsb.__file__).parent
    users = set()
    for path in package.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            if any(n == "numba" or n.startswith("numba.") for n in names):
                users.add(path.relative_to(package).as_posix())
    assert users == set(bioflex_jsb.NUMBA_MODULES)
    digest = hashlib.sha256()
    for rel in bioflex_jsb.NUMBA_MODULES:
        digest.update((package / rel).read_bytes())
    assert bioflex_jsb.kernel_sources_key() == digest.hexdigest()[:16]
