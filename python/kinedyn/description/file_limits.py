"""What the robot-file readers share: the nesting and size limits, the short repr of messages and
the containers that remember the line of each item (kinedyn.description.file_reader reads them;
yaml_reader, loaded only for YAML files, makes them)."""

from __future__ import annotations

import reprlib

__all__ = ["MAX_NESTING", "MAX_NODES", "SHORT_REPR", "LineDict", "LineList"]

MAX_NESTING = 32  # mappings and lists inside each other (a robot file needs 5)
MAX_NODES = 1_000_000  # YAML nodes composed, counting every use of an alias as the nodes it repeats
SHORT_REPR = reprlib.Repr()
SHORT_REPR.maxlevel, SHORT_REPR.maxstring, SHORT_REPR.maxother, SHORT_REPR.maxlist, SHORT_REPR.maxdict = 2, 40, 40, 4, 4


class LineDict(dict):
    """A mapping read from YAML that remembers the line of each key (1-based), for messages."""

    lines: dict


class LineList(list):
    """A list read from YAML that remembers the line of each item (1-based), for messages."""

    lines: list
