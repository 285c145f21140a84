"""griffe extension for the site's API reference: the package's docstrings are written for
``help()`` and the terminal (reST-style literals ````x````, roles ``:func:`x```, units in
brackets ``[m/s]``, ``>>>`` examples). Rendered as Markdown, a unit after a bracketed name
(``lag[k] [m/s]``) reads as a reference link and ``>>>`` lines run together. This extension
rewrites each docstring for Markdown when the site is built; the sources are unchanged."""

from __future__ import annotations

import re

import griffe

_ROLE = re.compile(r":(?:func|class|meth|mod|attr|data|obj|exc|const):`~?([^`]+)`")
_LITERAL = re.compile(r"``([^`]+)``")
_BRACKET = re.compile(r"(?<![\\`])\[([^\]\n`]*)\]")


def _markdown(text: str) -> str:
    out: list[str] = []
    in_example = False
    for line in text.splitlines():
        is_example = line.lstrip().startswith(">>>")
        if is_example and not in_example:
            out += ["", "```python"]
        elif not is_example and in_example:
            out += ["```", ""]
        in_example = is_example
        if is_example:
            out.append(line.lstrip()[4:])
            continue
        line = _ROLE.sub(r"`\1`", line)
        line = _LITERAL.sub(r"`\1`", line)
        # brackets outside code spans: escaped, so that "[k] [m/s]" stays text
        parts = line.split("`")
        parts[::2] = [_BRACKET.sub(r"\\[\1\\]", p) for p in parts[::2]]
        out.append("`".join(parts))
    if in_example:
        out.append("```")
    return "\n".join(out)


class TerminalDocstrings(griffe.Extension):
    """Rewrite every loaded object's docstring for Markdown (see the module docstring)."""

    def on_instance(self, *, obj, **kwargs) -> None:  # noqa: ARG002 (griffe's hook signature)
        if obj.docstring is not None:
            obj.docstring.value = _markdown(obj.docstring.value)
