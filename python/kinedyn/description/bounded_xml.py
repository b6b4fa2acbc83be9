"""Bounded XML parsing for robot files (URDF, MJCF): the one place their XML is read.

expat with line numbers, no entity declarations (billion laughs, external entities: a DOCTYPE with
declarations or an external DTD is refused), a bounded nesting depth, and every failure a
ValueError naming the file and line. The work is linear in the size of the text.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from typing import Union
from xml.parsers import expat

__all__ = ["parse_bounded"]


def parse_bounded(
    data: Union[str, bytes], label: str, kind: str, max_depth: int, record: Callable[[ET.Element, int], None]
) -> ET.Element:
    """The root element of ``data`` (bytes: expat honours the encoding declaration). ``label`` names
    the source in errors, ``kind`` the format ("a URDF", "an MJCF model"); ``record(element, line)``
    is called for every element as it starts (the callers keep the lines for their messages)."""
    builder = ET.TreeBuilder()
    parser = expat.ParserCreate()
    depth = 0

    def start(tag, attributes):
        nonlocal depth
        depth += 1
        if depth > max_depth:
            raise ValueError(f"{label}:{parser.CurrentLineNumber}: elements nested deeper than {max_depth} levels")
        record(builder.start(tag, attributes), parser.CurrentLineNumber)

    def end(tag):
        nonlocal depth
        depth -= 1
        builder.end(tag)

    def doctype(name, system_id, public_id, has_internal_subset):
        if has_internal_subset or system_id or public_id:
            raise ValueError(
                f"{label}:{parser.CurrentLineNumber}: a DOCTYPE with declarations or an external DTD is not "
                f"accepted in {kind} (entity expansion is unbounded work); remove it"
            )

    def entity(name, *args):
        raise ValueError(
            f"{label}:{parser.CurrentLineNumber}: the entity declaration '{name}' is not accepted in {kind}"
        )

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.StartDoctypeDeclHandler = doctype
    parser.EntityDeclHandler = entity
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    try:
        parser.Parse(data, True)
    except expat.ExpatError as e:
        raise ValueError(
            f"{label}: malformed XML at line {e.lineno}, column {e.offset + 1}: {expat.ErrorString(e.code)}"
        ) from None
    except LookupError as e:  # an XML declaration naming an encoding Python does not know
        raise ValueError(f"{label}: the XML declaration names an unknown encoding ({e})") from None
    return builder.close()
