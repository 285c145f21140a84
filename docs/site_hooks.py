"""MkDocs hook: the README is the site's front page (docs/index.md includes it), and its
links point into ``docs/`` from the repository's top level; on the site the pages sit at the
top, so ``](docs/x.md)`` becomes ``](x.md)``. Links to files outside ``docs/`` (sources,
scripts) become links to nothing on the site, so they are written as code there; links to
the site's own pages (docs/index.md's to the tutorials) stay links.

On every page, a page named as code (``docs/loads.md``, the README's and the pages' way of
pointing at one another, which reads right in a terminal and on GitHub) becomes a link to
that page where the site has it."""

from __future__ import annotations

import re

from mkdocs.utils import get_relative_url

_DOCS_LINK = re.compile(r"\]\(docs/")
_REPO_LINK = re.compile(r"\[([^\]]+)\]\((?!https?://|#|docs/)([^)]+)\)")
# a page named as inline code, in the HTML: `docs/NAME.md` or `docs/NAME.md#anchor`, with the
# link it may already be the text of (then left alone)
_CODE_PAGE = re.compile(r'(<a [^>]*>)?<code>docs/([A-Za-z0-9_./-]+\.md)(#[A-Za-z0-9_-]+)?</code>')


def on_page_content(html, page, config, files):  # noqa: ARG001 (MkDocs' hook signature)
    """Each page named as inline code (``docs/loads.md``), outside links, made a link to it
    where the site has it. In the HTML, so that the README, included into the front page
    after the markdown hooks have run, gets its links too; a code block's text is never a
    bare ``<code>`` element, so it is left as it is."""

    def link(m: re.Match) -> str:
        target = files.get_file_from_path(m.group(2))
        if m.group(1) or target is None:
            return m.group(0)
        href = get_relative_url(target.url, page.url) + (m.group(3) or "")
        return f'<a href="{href}">{m.group(0)}</a>'

    return _CODE_PAGE.sub(link, html)


def on_page_markdown(markdown, page, config, files):  # noqa: ARG001 (MkDocs' hook signature)
    if page.file.src_uri == "index.md":
        markdown = _DOCS_LINK.sub("](", markdown)
        markdown = _REPO_LINK.sub(lambda m: m.group(0) if m.group(2).endswith(".md")
                                  or files.get_file_from_path(m.group(2)) is not None
                                  else f"`{m.group(1)}`", markdown)
    return markdown
