"""MkDocs hook: the README is the site's front page (docs/index.md includes it), and its
links point into ``docs/`` from the repository's top level; on the site the pages sit at the
top, so ``](docs/x.md)`` becomes ``](x.md)``. Links to files outside ``docs/`` (sources,
scripts) become links to nothing on the site, so they are written as code there."""

from __future__ import annotations

import re

_DOCS_LINK = re.compile(r"\]\(docs/")
_REPO_LINK = re.compile(r"\[([^\]]+)\]\((?!https?://|#|docs/)([^)]+)\)")


def on_page_markdown(markdown, page, config, files):  # noqa: ARG001 (MkDocs' hook signature)
    if page.file.src_uri != "index.md":
        return markdown
    markdown = _DOCS_LINK.sub("](", markdown)
    return _REPO_LINK.sub(lambda m: m.group(0) if m.group(2).endswith(".md")
                          else f"`{m.group(1)}`", markdown)
