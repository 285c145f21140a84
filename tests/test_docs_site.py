"""The documentation site builds with no warning (``mkdocs build --strict``: no broken link,
no missing reference) and its API reference covers every public name of ``bioflex_jsb.api``."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("site")
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q",
                           "-f", str(REPO / "mkdocs.yml"), "-d", str(out)],
                          cwd=REPO, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-4000:]
    return out


def test_the_site_builds_strict_and_the_readme_is_its_front_page(site):
    index = (site / "index.html").read_text(encoding="utf-8")
    assert "python -m pip install . &amp;&amp; bioflex-jsb gust" in index
    assert 'href="docs/' not in index  # the README's links rewritten for the site


def test_every_public_api_name_has_a_reference_entry(site):
    from bioflex_jsb import api

    page = (site / "api" / "index.html").read_text(encoding="utf-8")
    anchors = set(re.findall(r'id="(bioflex_jsb\.api\.[A-Za-z_][A-Za-z0-9_]*)"', page))
    missing = [n for n in api.__all__ if f"bioflex_jsb.api.{n}" not in anchors]
    assert not missing, f"public names of bioflex_jsb.api without a reference entry: {missing}"


def test_docstring_units_render_as_text_not_links(site):
    page = (site / "api" / "index.html").read_text(encoding="utf-8")
    assert "[m/s]" in page  # escaped by docs/griffe_docstrings.py, else a broken reference


def test_every_page_in_docs_is_in_the_navigation():
    import yaml  # MkDocs' own dependency

    config = yaml.safe_load((REPO / "mkdocs.yml").read_text().replace("!!python", "#"))
    listed = {next(iter(item.values())) for item in config["nav"]}
    pages = {p.name for p in (REPO / "docs").glob("*.md")}
    assert pages <= listed, f"docs pages missing from mkdocs.yml nav: {sorted(pages - listed)}"
