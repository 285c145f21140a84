"""The documentation site: the tutorials (notebooks in docs/tutorials/) execute without an
error, and the site builds with no warning (``mkdocs build --strict``: no broken link, no
missing reference) from the executed copies, so their figures are on the site; its API
reference covers every public name of ``bioflex_jsb.api``.

Each notebook is executed once (nbclient, the kernel nbmake drives too), in a copy of docs/ in
a temporary directory, so nothing is written into the working tree; the site is then built
from that copy with execution switched off."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # executes the notebooks (SITL, gusts): not in the fast subset

REPO = Path(__file__).resolve().parents[1]
TUTORIALS = sorted(p.name for p in (REPO / "docs" / "tutorials").glob("*.ipynb"))
CELL_TIMEOUT_S = 600  # generous: a loaded machine (load 10 on 2 cores) was seen 3x slower


@pytest.fixture(scope="module")
def executed_docs(tmp_path_factory) -> dict[str, object]:
    """docs/ copied to a temporary directory with every tutorial executed in place: the
    copy's path and, per notebook, None or the error it raised (and its wall time [s])."""
    import nbformat
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError

    docs = tmp_path_factory.mktemp("site-src") / "docs"
    shutil.copytree(REPO / "docs", docs)
    errors: dict[str, str | None] = {}
    seconds: dict[str, float] = {}
    for name in TUTORIALS:
        path = docs / "tutorials" / name
        nb = nbformat.read(path, as_version=4)
        start = time.perf_counter()
        try:
            NotebookClient(nb, timeout=CELL_TIMEOUT_S, kernel_name="python3",
                           resources={"metadata": {"path": str(path.parent)}}).execute()
            errors[name] = None
        except CellExecutionError as exc:
            errors[name] = str(exc)[-3000:]
        seconds[name] = time.perf_counter() - start
        nbformat.write(nb, path)
    return {"docs": docs, "errors": errors, "seconds": seconds}


@pytest.fixture(scope="module")
def site(executed_docs, tmp_path_factory) -> Path:
    import yaml  # MkDocs' own dependency

    out = tmp_path_factory.mktemp("site")
    config = yaml.safe_load((REPO / "mkdocs.yml").read_text())
    config["docs_dir"] = str(executed_docs["docs"])
    config["site_dir"] = str(out)
    config["hooks"] = [str(REPO / h) for h in config["hooks"]]
    for plugin in config["plugins"]:
        if isinstance(plugin, dict) and "mkdocs-jupyter" in plugin:
            plugin["mkdocs-jupyter"]["execute"] = False  # executed above, once
        if isinstance(plugin, dict) and "mkdocstrings" in plugin:
            options = plugin["mkdocstrings"]["handlers"]["python"]["options"]
            options["extensions"] = [str(REPO / e) for e in options.get("extensions", [])]
    for ext in config["markdown_extensions"]:
        if isinstance(ext, dict) and "pymdownx.snippets" in ext:
            ext["pymdownx.snippets"]["base_path"] = [str(REPO)]  # the README
    cfg = out.parent / "mkdocs.yml"
    cfg.write_text(yaml.safe_dump(config, sort_keys=False))
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q",
                           "-f", str(cfg)],
                          cwd=out.parent, env=env, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-4000:]
    return out


@pytest.mark.parametrize("name", TUTORIALS)
def test_tutorial_executes_without_an_error(executed_docs, name):
    err = executed_docs["errors"][name]
    assert err is None, f"{name} (ran {executed_docs['seconds'][name]:.0f} s): {err}"


def test_the_site_builds_strict_and_the_readme_is_its_front_page(site):
    index = (site / "index.html").read_text(encoding="utf-8")
    assert "python -m pip install . &amp;&amp; bioflex-jsb gust" in index
    assert 'href="docs/' not in index  # the README's links rewritten for the site


@pytest.mark.parametrize("name", TUTORIALS)
def test_tutorial_figures_are_on_the_site(site, name):
    page = (site / "tutorials" / Path(name).stem / "index.html").read_text(encoding="utf-8")
    assert page.count("data:image/png;base64") >= 1, f"{name}: no figure on its page"


def test_every_public_api_name_has_a_reference_entry(site):
    from bioflex_jsb import api

    page = (site / "api" / "index.html").read_text(encoding="utf-8")
    anchors = set(re.findall(r'id="(bioflex_jsb\.api\.[A-Za-z_][A-Za-z0-9_]*)"', page))
    missing = [n for n in api.__all__ if f"bioflex_jsb.api.{n}" not in anchors]
    assert not missing, f"public names of bioflex_jsb.api without a reference entry: {missing}"


def test_docstring_units_render_as_text_not_links(site):
    page = (site / "api" / "index.html").read_text(encoding="utf-8")
    assert "[m/s]" in page  # escaped by docs/griffe_docstrings.py, else a broken reference


def _nav_pages(items) -> set[str]:
    pages: set[str] = set()
    for item in items:
        value = next(iter(item.values())) if isinstance(item, dict) else item
        pages |= _nav_pages(value) if isinstance(value, list) else {value}
    return pages


def test_every_page_and_tutorial_in_docs_is_in_the_navigation():
    import yaml

    config = yaml.safe_load((REPO / "mkdocs.yml").read_text())
    listed = _nav_pages(config["nav"])
    pages = {p.relative_to(REPO / "docs").as_posix() for p in (REPO / "docs").rglob("*")
             if p.suffix in (".md", ".ipynb") and ".ipynb_checkpoints" not in p.parts}
    assert pages <= listed, f"docs pages missing from mkdocs.yml nav: {sorted(pages - listed)}"


def test_the_tutorials_leave_only_ignored_files(executed_docs):
    """What building the site writes beside the notebooks (their figures, logs, the wing
    files of own_wing.ipynb) is ignored by git: a build leaves the working tree clean."""
    made = sorted(p.relative_to(executed_docs["docs"]).as_posix()
                  for p in (executed_docs["docs"] / "tutorials").iterdir()
                  if not (REPO / "docs" / p.relative_to(executed_docs["docs"])).exists())
    assert made, "the tutorials wrote nothing: this test checks nothing"
    proc = subprocess.run(["git", "check-ignore", "--no-index", *[f"docs/{m}" for m in made]],
                          cwd=REPO, capture_output=True, text=True)
    ignored = set(proc.stdout.split())
    assert not [m for m in made if f"docs/{m}" not in ignored], (made, proc.stdout)


def test_no_cell_shows_a_stray_return_value(executed_docs):
    """A cell's last expression is shown: a file write's byte count (own_wing's 584) is
    noise on the page."""
    import nbformat

    stray = []
    for name in TUTORIALS:
        nb = nbformat.read(executed_docs["docs"] / "tutorials" / name, as_version=4)
        for i, cell in enumerate(nb.cells):
            for out in cell.get("outputs", []):
                text = out.get("data", {}).get("text/plain", "")
                if out.get("output_type") == "execute_result" and text.strip().isdigit():
                    stray.append((name, i, text))
    assert not stray, stray


def test_figures_fill_the_page_and_enlarge_on_a_click(site):
    page = (site / "tutorials" / "figures" / "index.html").read_text(encoding="utf-8")
    images = page.count("<img")
    assert images >= 8 and page.count('class="glightbox"') >= images - 1  # the logo: not
    assert "stylesheets/extra.css" in page
    css = (site / "stylesheets" / "extra.css").read_text(encoding="utf-8")
    assert "white-space: pre-wrap" in css and "max-width: 90rem" in css
    # the commands' JSON is not on the page: figures and their captions are
    assert '"peak_du_m_s"' not in page and page.count("<strong>Figure ") >= 8


def test_the_front_page_links_to_the_tutorials_and_pages(site):
    index = (site / "index.html").read_text(encoding="utf-8")
    for target in ("tutorials/fig21_gust/", "tutorials/own_wing/", "tutorials/sitl_mission/",
                   "tutorials/figures/", "api/", "conventions/", "loads/"):
        assert f'href="{target}"' in index, target
    # a page named as code (`docs/logging.md`) is a link to it
    assert '<a href="logging/"><code>docs/logging.md</code></a>' in index
