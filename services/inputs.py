"""What people hand the commands, read defensively: YAML whose aliases cannot blow up,
and values quoted short in error lines.

YAML aliases share one node, so ``a: &a [x, x]`` with ``b: [*a, *a]`` costs nothing to
parse, but every later walk over the data (validation, a copy, ``repr`` in an error line)
sees the expanded tree: nine anchors each naming the one before nine times are 9^9 items
and exhaust the memory. :class:`BoundedLoader` refuses a document whose aliases stand for
more than :data:`ALIAS_NODES` nodes beyond those written, and an alias inside its own
anchor (a structure without end). A file without aliases is never refused for its size.
"""

from __future__ import annotations

import argparse
import reprlib
from collections.abc import Hashable
from typing import Any, NoReturn

import yaml

ALIAS_NODES = 100_000
"""How many nodes a document's aliases may add to the ones written in it."""

SHOWN_CHARS = 80
"""The longest a value is quoted in an error line, the ellipsis included."""


class AliasError(yaml.YAMLError):
    """A document whose aliases expand without bound (or too far); the text says which."""


def _expanded_size(root: yaml.Node) -> tuple[int, int]:
    """(nodes written, nodes after expanding every alias) of the tree under ``root``;
    AliasError as soon as the aliases add more than :data:`ALIAS_NODES` or refer to a
    node that contains them."""
    sizes: dict[int, int] = {}
    open_nodes: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, children_done = stack.pop()
        key = id(node)
        if children_done:
            open_nodes.discard(key)
            total = 1 + sum(sizes[id(child)] for child in _children(node))
            sizes[key] = total
            if total - len(sizes) > ALIAS_NODES:
                raise AliasError(f"aliases expand to more than {ALIAS_NODES} nodes beyond "
                                 "those written; refused")
            continue
        if key in sizes:
            continue
        if key in open_nodes:  # reached again below itself
            mark = node.start_mark
            where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark else ""
            raise AliasError(f"an alias refers to a node that contains it{where}: a "
                             "structure without end; refused")
        open_nodes.add(key)
        stack.append((node, True))
        stack.extend((child, False) for child in _children(node))
    return len(sizes), sizes[id(root)]


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [part for pair in node.value for part in pair]
    return []


class BoundedLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses documents whose aliases expand too far
    (:class:`AliasError`, a ``yaml.YAMLError``), checked before any object is built, and
    a mapping that names a key twice (PyYAML would keep the last one without a word, so a
    parameter set twice in a file would silently lose its first value)."""

    def get_single_node(self) -> Any:
        node = super().get_single_node()
        if node is not None:
            _expanded_size(node)
        return node

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Hashable, Any]:
        seen: set[object] = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if key in seen:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r}", key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


def safe_load(text: str, loader: type[BoundedLoader] = BoundedLoader) -> Any:
    """``yaml.safe_load`` with the aliases bounded (see :class:`BoundedLoader`)."""
    return yaml.load(text, Loader=loader)  # a SafeLoader


_REPR = reprlib.Repr()
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = _REPR.maxset = 8
_REPR.maxstring = _REPR.maxother = SHOWN_CHARS
_REPR.maxlevel = 3


def clipped(text: str, limit: int = SHOWN_CHARS) -> str:
    """``text`` on one line of at most ``limit`` characters, cut with "…"."""
    text = " ".join(text.split()) if "\n" in text else text
    return text if len(text) <= limit else text[:limit - 1] + "…"


def shown(value: object, limit: int = SHOWN_CHARS) -> str:
    """``repr(value)`` for an error line: at most ``limit`` characters, cut with "…",
    and built without walking more of a long or deep value than is shown."""
    return clipped(_REPR.repr(value), limit)


def not_valid_yaml(exc: yaml.YAMLError) -> str:
    """What is wrong with a YAML text, on one line, the same for every file zenav reads:
    "not valid YAML (the problem (line L, column C))"."""
    if isinstance(exc, yaml.MarkedYAMLError) and exc.problem_mark is not None:
        mark = exc.problem_mark
        problem = f"{exc.problem} (line {mark.line + 1}, column {mark.column + 1})"
    else:
        problem = clipped(str(exc), 200)
    return f"not valid YAML ({problem})"


class OneLineParser(argparse.ArgumentParser):
    """An argparse parser whose usage errors are one line on stderr and exit status 2,
    ``PROG: what is wrong`` (the usage is ``PROG --help``'s); its sub-parsers alike."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: {message}\n")
