"""YAML robot files read by PyYAML's safe loader, bounded (kinedyn.description.file_reader reads
the data it returns). A module of its own so that PyYAML loads only when a YAML file is read."""

from __future__ import annotations

import yaml

from .file_limits import MAX_NESTING, MAX_NODES, SHORT_REPR, LineDict, LineList

__all__ = ["BoundedLoader", "parse_yaml"]


class BoundedLoader(yaml.SafeLoader):
    """PyYAML's safe loader (plain data only: no Python objects) with three changes:

    - nesting deeper than ``MAX_NESTING`` is an error (PyYAML's composer recurses);
    - the size of the document is bounded with every alias counted as the nodes it repeats, so a
      small file of aliases to aliases (a "billion laughs") fails at once instead of filling memory;
    - a key given twice in one mapping is an error (YAML 1.2 forbids it; PyYAML keeps the last).
    """

    def __init__(self, stream):
        super().__init__(stream)
        self._depth = 0
        self._expanded = 0  # nodes composed so far, aliases counted as what they repeat
        self._size_of: dict = {}  # id(anchored node) -> its expanded size

    def _refuse(self, problem: str, mark):
        raise yaml.composer.ComposerError(None, None, problem, mark)

    def compose_node(self, parent, index):
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            node = self.anchors.get(event.anchor)
            if node is not None:
                if id(node) not in self._size_of:
                    self._refuse(f"the alias *{event.anchor} refers to a node that contains it", event.start_mark)
                self._count(self._size_of[id(node)], event.start_mark)
            return super().compose_node(parent, index)
        self._depth += 1
        if self._depth > MAX_NESTING:
            self._refuse(f"mappings and lists are nested more than {MAX_NESTING} deep", event.start_mark)
        before = self._expanded
        self._count(1, event.start_mark)
        node = super().compose_node(parent, index)
        self._depth -= 1
        self._size_of[id(node)] = self._expanded - before
        return node

    def _count(self, nodes: int, mark):
        self._expanded += nodes
        if self._expanded > MAX_NODES:
            self._refuse(
                f"the document expands to more than {MAX_NODES} values (aliases counted as what they repeat)", mark
            )

    def construct_line_mapping(self, node):
        data = LineDict()
        data.lines = {}
        yield data
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":  # "<<: *anchor": merged keys may be overridden
                continue
            key = self.construct_object(key_node, deep=True)
            try:
                repeated = key in data.lines
            except TypeError:
                raise yaml.constructor.ConstructorError(
                    None, None, "a mapping key must be a plain value", key_node.start_mark
                ) from None
            if repeated:
                raise yaml.constructor.ConstructorError(
                    None,
                    None,
                    f"the key {SHORT_REPR.repr(key)} appears twice in one mapping (first on line {data.lines[key]})",
                    key_node.start_mark,
                )
            data.lines[key] = key_node.start_mark.line + 1
        data.update(self.construct_mapping(node, deep=True))

    def construct_line_sequence(self, node):
        data = LineList()
        data.lines = [item.start_mark.line + 1 for item in node.value]
        yield data
        data.extend(self.construct_sequence(node, deep=True))


def _refuse_tag(loader, node):
    raise yaml.constructor.ConstructorError(
        None,
        None,
        f"the YAML type {node.tag.rsplit(':', 1)[-1]} ({SHORT_REPR.repr(node.value) if isinstance(node.value, str) else '...'}) "
        "has no meaning in a robot file (numbers, text, lists and mappings only)",
        node.start_mark,
    )


# a robot file holds numbers, text, lists and mappings: YAML's other types (dates, which PyYAML's
# constructor can also fail on with an AttributeError, binary, sets, ordered pairs) are refused
for _tag in ("timestamp", "binary", "set", "omap", "pairs"):
    BoundedLoader.add_constructor(f"tag:yaml.org,2002:{_tag}", _refuse_tag)
# digits of a YAML integer the parser converts at all: below Python's own limit (4300, whose message
# speaks of sys.set_int_max_str_digits); the field's reader then refuses anything over ~300 digits by name
MAX_INT_DIGITS = 4000


def _bounded_int(loader, node):
    """A YAML integer, its digits counted before Python converts it."""
    digits = sum(c.isalnum() for c in str(node.value))
    if digits > MAX_INT_DIGITS:
        raise yaml.constructor.ConstructorError(
            None, None, f"the integer has {digits} digits, too large for a robot's parameter", node.start_mark
        )
    return loader.construct_yaml_int(node)


BoundedLoader.add_constructor("tag:yaml.org,2002:int", _bounded_int)
BoundedLoader.add_constructor("tag:yaml.org,2002:map", BoundedLoader.construct_line_mapping)
BoundedLoader.add_constructor("tag:yaml.org,2002:seq", BoundedLoader.construct_line_sequence)


def parse_yaml(text: str, where: str):
    loader = None
    try:
        loader = BoundedLoader(text)  # its reader already refuses control characters
        return loader.get_single_data()
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        line = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "unknown line"
        raise ValueError(f"{where}: invalid YAML at {line}: {e.problem or e.context}") from None
    except yaml.reader.ReaderError as e:  # a character YAML does not allow (NUL, other control characters)
        line_no = text.count("\n", 0, e.position) + 1
        shown = chr(e.character) if isinstance(e.character, int) else e.character
        raise ValueError(
            f"{where}: invalid YAML at line {line_no}: the character {shown!r} is not allowed in YAML"
        ) from None
    except yaml.YAMLError as e:
        raise ValueError(f"{where}: invalid YAML: {e}") from None
    finally:
        if loader is not None:
            loader.dispose()
