"""YAML from outside (an upload's ``joint_limits.yaml``), read within bounds so that no text
of the accepted size costs more than a bounded time and memory, whatever it holds.

PyYAML's ``SafeLoader`` constructs plain data only, but follows every alias: nine nested
anchors of ten aliases each (1.4 KB of text) stand for 10^9 list items, which any walk over the
result (a ``repr`` in an error message, a copy, a comparison) then visits one by one; and its
composer recurses once per nesting level, so 5,000 nested brackets end in a ``RecursionError``.
``BoundedLoader`` counts while it composes the node graph, before anything is constructed:

==================================  =================================================
``MAX_CHARS``                       characters of text read (checked first)
``MAX_DEPTH``                       levels of nested sequences and mappings
``MAX_NODES``                       nodes of the document with every alias expanded
``MAX_ALIASES``                     alias uses (``*name``)
``MAX_SCALAR_CHARS``                characters of one scalar (a name or a number)
``MAX_INTEGER_DIGITS``              characters of an integer (larger ones overflow a float)
==================================  =================================================

It also refuses what ``SafeLoader`` lets through silently: a mapping key that is not a string
(``1:``, ``yes:``, ``null:``, ``[a]:``; keys are names here), the same key twice in one mapping
(``SafeLoader`` keeps the last), an alias of a node that holds it (a cycle) and more than one
document. Numbers in exponent form without a dot (``1e-3``) are floats, as YAML 1.2 and
MoveIt read them (YAML 1.1 would give the string "1e-3"). Merge keys (``<<: *defaults``) work as in ``SafeLoader``, within the node bound.
Every refusal is a ``yaml.YAMLError`` with the line and column where it happened.
"""

from __future__ import annotations

import re

import yaml

MAX_CHARS = 100_000
MAX_DEPTH = 32
MAX_NODES = 10_000
MAX_ALIASES = 1_000
MAX_SCALAR_CHARS = 1_000
MAX_INTEGER_DIGITS = 40

_STR = "tag:yaml.org,2002:str"
_MERGE = "tag:yaml.org,2002:merge"


class BoundedYAMLError(yaml.YAMLError):
    """A document beyond one of the bounds, or holding what the loader refuses.

    Attributes:
        problem: What is wrong, in a sentence.
        problem_mark: Where (``line``, ``column``, from 0), when known.
    """

    def __init__(self, problem: str, mark: yaml.Mark | None = None) -> None:
        super().__init__(problem)
        self.problem = problem
        self.problem_mark = mark


class BoundedLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that bounds depth, expanded size, aliases and scalars while it
    composes, and refuses non-string and duplicate keys (see the module docstring)."""

    def __init__(self, stream: str):
        super().__init__(stream)
        self._depth = 0
        self._nodes = 0
        self._aliases = 0
        self._sizes: dict[int, int] = {}  # id(node) -> nodes it stands for, once composed

    def _count(self, nodes: int, mark) -> None:
        self._nodes += nodes
        if self._nodes > MAX_NODES:
            raise BoundedYAMLError(
                f"the document stands for more than {MAX_NODES} values once its aliases are expanded", mark
            )

    def compose_node(self, parent: yaml.Node | None, index: object) -> yaml.Node:
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            self._aliases += 1
            if self._aliases > MAX_ALIASES:
                raise BoundedYAMLError(f"the document uses more than {MAX_ALIASES} aliases", event.start_mark)
            target = self.anchors.get(event.anchor)
            if target is not None and id(target) not in self._sizes:
                raise BoundedYAMLError(
                    f"alias *{event.anchor[:40]} refers to a node that holds it (a cycle)", event.start_mark
                )
            if target is not None:
                self._count(self._sizes[id(target)], event.start_mark)
            return super().compose_node(parent, index)
        mark = self.peek_event().start_mark
        self._depth += 1
        if self._depth > MAX_DEPTH:
            raise BoundedYAMLError(f"the document nests more than {MAX_DEPTH} levels deep", mark)
        before = self._nodes
        self._count(1, mark)
        node = super().compose_node(parent, index)
        self._depth -= 1
        self._sizes[id(node)] = self._nodes - before
        if isinstance(node, yaml.ScalarNode) and len(node.value) > MAX_SCALAR_CHARS:
            raise BoundedYAMLError(
                f"a value of {len(node.value)} characters; at most {MAX_SCALAR_CHARS} are read", node.start_mark
            )
        return node

    def compose_mapping_node(self, anchor: str | None) -> yaml.MappingNode:
        node = super().compose_mapping_node(anchor)
        seen = set()
        for key, _ in node.value:
            if key.tag == _MERGE:
                continue
            if not (isinstance(key, yaml.ScalarNode) and key.tag == _STR):
                shown = repr(key.value[:40]) if isinstance(key, yaml.ScalarNode) else f"a {key.id}"
                raise BoundedYAMLError(
                    f"the key {shown} is not a string (keys are names here; quote it if it is one)", key.start_mark
                )
            if key.value in seen:
                raise BoundedYAMLError(f"the key {key.value[:40]!r} appears twice in one mapping", key.start_mark)
            seen.add(key.value)
        return node

    def construct_yaml_int(self, node: yaml.ScalarNode) -> int:
        if len(node.value) > MAX_INTEGER_DIGITS:
            raise yaml.constructor.ConstructorError(
                None, None, f"an integer of {len(node.value)} characters; at most {MAX_INTEGER_DIGITS} are read",
                node.start_mark,
            )
        return super().construct_yaml_int(node)


BoundedLoader.add_constructor("tag:yaml.org,2002:int", BoundedLoader.construct_yaml_int)
# YAML 1.2's floats without a dot (1e-3, 5E+2), which YAML 1.1 (PyYAML) reads as strings.
BoundedLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float", re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"), list("-+0123456789")
)


def load(text: str) -> object:
    """The one document of ``text``, read within the module's bounds (``None`` when empty).

    Raises:
        BoundedYAMLError: the text is longer than ``MAX_CHARS`` or the document goes beyond a
            bound, has a non-string or repeated key or an alias cycle.
        yaml.YAMLError: the text is not YAML, holds several documents or an unknown tag.
    """
    if len(text) > MAX_CHARS:
        raise BoundedYAMLError(f"the text holds {len(text)} characters; at most {MAX_CHARS} are read")
    loader = BoundedLoader(text)
    try:
        return loader.get_single_data()
    finally:
        loader.dispose()

