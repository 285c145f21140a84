"""Aircraft definitions as data (docs/aircraft.md): the TOML format, the objects it loads
into (:mod:`~bioflex_jsb.definition.model`), the loader and its validation
(:mod:`~bioflex_jsb.definition.loader`), and a clamped wing's analysis model
(:mod:`~bioflex_jsb.definition.clamped`). A clamped wing is a definition without an
airframe; shipped definitions are in ``bioflex_jsb/data/aircraft/``."""

from bioflex_jsb.definition.loader import (
    SHIPPED,
    DefinitionError,
    load_definition,
    parse_definition,
)
from bioflex_jsb.definition.model import Definition

__all__ = ["SHIPPED", "Definition", "DefinitionError", "load_definition", "parse_definition"]
