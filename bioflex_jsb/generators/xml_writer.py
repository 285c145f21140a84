"""The one XML writer of the JSBSim file generators: element helpers and serialisation.

Every generator builds an :mod:`xml.etree.ElementTree` tree with an :class:`XmlWriter` (which
fixes how numbers are written: :func:`num_9g` for the airframe, :func:`num_12g` for the modal
wing, whose coefficients need more digits, :func:`num_repr` for the autopilot) and writes it
with :func:`serialise`: the XML declaration, the generator's header comment, the tree indented
by two spaces, a final newline. The output is deterministic on one machine; across processors the
numbers derived from the wing's modes move in their last digits (the modes' eigen-solution
depends on the BLAS kernels: ``docs/validation.md``), so committed files are compared with a
fresh rendering by value (:func:`number_difference`: the same text between the numbers, the
numbers within a relative tolerance). Derived aircraft (SITL, native modal wing) are
built by modifying the airframe generator's tree
(:func:`bioflex_jsb.generators.airframe.airframe_tree`), never its text.

Besides elements, properties, values, operations and tables, the writer builds JSBSim
functions in the form JSBSim evaluates fastest (:meth:`XmlWriter.combination`,
:meth:`XmlWriter.over`, :meth:`XmlWriter.times`: the modal wing's step).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterable

XML_DECLARATION = '<?xml version="1.0" encoding="utf-8"?>\n'
INDENT = "  "


def num_9g(x: float) -> str:
    """9 significant digits, no negative zero."""
    s = f"{float(x):.9g}"
    return "0" if s == "-0" else s


def num_12g(x: float) -> str:
    """12 significant digits, zero (of either sign) as ``0``."""
    x = float(x)
    return "0" if x == 0.0 else f"{x:.12g}"


def num_repr(x: float) -> str:
    """The shortest text that reads back as the same double."""
    return repr(float(x))


# A decimal number as the writers print it (also the digits inside names, which compare equal).
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def number_difference(expected: str, got: str) -> float | None:
    """How far the numbers of ``got`` are from those of ``expected``: the largest
    |got − expected| / |expected| over the numbers in order (0 where both are 0, inf where
    only ``expected`` is 0). None when the text between the numbers differs (another
    structure, not another value)."""
    if _NUMBER.split(expected) != _NUMBER.split(got):
        return None
    worst = 0.0
    for a, b in zip(_NUMBER.findall(expected), _NUMBER.findall(got), strict=True):
        if a == b:
            continue
        x, y = float(a), float(b)
        worst = max(worst, abs(y - x) / abs(x) if x != 0.0 else (0.0 if y == 0.0 else
                                                                   float("inf")))
    return worst


class XmlWriter:
    """Element helpers that write numbers with ``number`` (a float → text function).

    Terms of an operation (:meth:`op`): a ``str`` is a ``<property>``, an
    :class:`~xml.etree.ElementTree.Element` is appended as it is, a callable is called with the
    operation's element (it builds its argument there), anything else is a number, a
    ``<value>``."""

    def __init__(self, number: Callable[[float], str]) -> None:
        self.number = number

    def text(self, x: str | float) -> str:
        return x if isinstance(x, str) else self.number(x)

    def el(self, parent: ET.Element, tag: str, text: str | float | None = None,
           **attrib) -> ET.Element:
        """Child ``<tag>`` of ``parent`` with ``text`` (numbers written by ``number``) and the
        attributes ``attrib`` (as text)."""
        e = ET.SubElement(parent, tag, {k: str(v) for k, v in attrib.items()})
        if text is not None:
            e.text = self.text(text)
        return e

    @staticmethod
    def comment(parent: ET.Element, text: str) -> ET.Comment:
        """``<!-- text -->`` as the last child of ``parent``."""
        c = ET.Comment(f" {text} ")
        parent.append(c)
        return c

    def prop(self, parent: ET.Element, name: str) -> ET.Element:
        return self.el(parent, "property", name)

    def value(self, parent: ET.Element, x: float) -> ET.Element:
        return self.el(parent, "value", float(x))

    def value_element(self, x: float) -> ET.Element:
        """A detached ``<value>``."""
        e = ET.Element("value")
        e.text = self.number(x)
        return e

    def op(self, parent: ET.Element, tag: str, *terms, **attrib) -> ET.Element:
        """``<tag>`` with one child per term (class docstring)."""
        e = self.el(parent, tag, **attrib)
        for t in terms:
            if isinstance(t, str):
                self.prop(e, t)
            elif isinstance(t, ET.Element):
                e.append(t)
            elif callable(t):
                t(e)
            else:
                self.value(e, t)
        return e

    def node(self, tag: str, *terms) -> ET.Element:
        """A detached ``<tag>`` with the terms (to nest into a later operation)."""
        return self.op(ET.Element("holder"), tag, *terms)

    def product(self, parent: ET.Element, *terms) -> ET.Element:
        return self.op(parent, "product", *terms)

    def table_data(self, parent: ET.Element, rows: Iterable[tuple[float, float]], width: int,
                   indent: int) -> ET.Element:
        """``<tableData>`` of two columns, each row on its own line at ``indent`` spaces,
        right-aligned in ``width`` characters; the closing tag two spaces less indented."""
        lines = "".join(f"\n{' ' * indent}{self.number(x):>{width}} {self.number(y):>{width}}"
                        for x, y in rows)
        return self.el(parent, "tableData", lines + "\n" + " " * (indent - 2))

    def table(self, parent: ET.Element, variable: str, rows: Iterable[tuple[float, float]],
              width: int) -> ET.Element:
        """A one-dimensional ``<table>`` of ``variable`` (row lookup), at the depth of a table
        in an aerodynamics or system function."""
        t = self.el(parent, "table")
        self.el(t, "independentVar", variable, lookup="row")
        self.table_data(t, rows, width, indent=10)
        return t


    # JSBSim functions in the form it evaluates fastest (the modal wing's step)

    def fcs(self, channel: ET.Element, name: str, description: str,
            output: str | None = None) -> ET.Element:
        """``<fcs_function name=...>`` in ``channel`` with its description and ``output``; returns
        its ``<function>`` to fill."""
        comp = self.el(channel, "fcs_function", name=name)
        self.el(comp, "description", description)
        fn = self.el(comp, "function")
        if output:
            self.el(comp, "output", output)
        return fn

    def linear(self, parent: ET.Element, pairs: list[tuple[float, str]]) -> None:
        """Σ coefficient·property, skipping zero coefficients, into ``parent`` (a <sum>)."""
        for coef, prop in pairs:
            if coef != 0.0:
                self.product(parent, float(coef), prop)

    def combination(self, parent: ET.Element, terms: list[tuple[float, str]], lead=None,
                    minus: tuple[str, ...] = (), **attrib) -> ET.Element:
        """Σ c·x over ``terms`` [(c, property)] (zero c skipped), plus the element ``lead``
        builds, minus the properties ``minus``, in the form JSBSim evaluates fastest: a
        <difference> of <quotient>s, x/(1/c). JSBSim's <sum> and <product> copy a
        reference-counted pointer per argument each time they are evaluated (two atomic
        operations); <difference> and <quotient> index their arguments (a weighted term costs
        about a third less, measured)."""
        d = self.el(parent, "difference", **attrib)
        first = lead is None
        if lead is not None:
            lead(d)
        for coef, prop in terms:
            if coef == 0.0:
                continue
            q = self.el(d, "quotient")
            self.prop(q, prop)
            self.value(q, (1.0 if first else -1.0) / float(coef))
            first = False
        if minus and first:  # nothing added yet: subtract from 0
            self.value(d, 0.0)
        for prop in minus:
            self.prop(d, prop)
        if len(d) == 0:  # nothing to add: the value 0
            d.tag = "value"
            d.text = "0"
        return d

    def over(self, x, inverse):
        """Builder of x / ``inverse`` (a property name, or a builder), the product of x and the
        quantity whose inverse that is."""
        def build(parent: ET.Element) -> None:
            q = self.el(parent, "quotient")
            x(q)
            if callable(inverse):
                inverse(q)
            else:
                self.prop(q, inverse)
        return build

    def times(self, x, factor: str):
        """Builder of x·factor as x / (1/factor) (no pointer copies: :meth:`combination`);
        a factor of 0 gives 1/0 = HUGE_VAL in JSBSim and so 0, as the product would."""
        return self.over(x, self.over(lambda p: self.value(p, 1.0), factor))


def collapse(parent: ET.Element) -> None:
    """Replace every ``<sum>``/``<product>``/``<difference>`` with one argument (and no name)
    by that argument (JSBSim warns about them)."""
    for i, child in enumerate(list(parent)):
        collapse(child)
        if (child.tag in ("sum", "product", "difference") and len(child) == 1
                and "name" not in child.attrib):
            parent.remove(child)
            parent.insert(i, child[0])


def serialise(root: ET.Element, header: str = "", *, collapse_single: bool = False) -> str:
    """Text of a generated file: the XML declaration, ``header`` (comment lines, each ending in
    a newline), ``root`` indented by two spaces per level, a final newline.
    ``collapse_single``: first :func:`collapse` the tree. Indents ``root`` in place."""
    if collapse_single:
        collapse(root)
    ET.indent(root, space=INDENT)
    body = ET.tostring(root, encoding="unicode", short_empty_elements=True)
    return XML_DECLARATION + header + body + "\n"
