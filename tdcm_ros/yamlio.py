"""Bounded YAML loading for every configuration input of the package (ROS-free).

:func:`load_yaml` reads YAML text as ``yaml.safe_load`` does, with four bounds that make
hostile input fail fast with a typed error naming the source, the line and the limit:

- anchors and aliases are rejected (not capped): scenes, ROS parameter files, bag metadata
  and CLI values never need them, and without them nothing can expand ("billion laughs");
- nesting deeper than :data:`MAX_DEPTH_LEVELS` collections is rejected while composing,
  before Python's recursion limit is near;
- text longer than :data:`MAX_INPUT_BYTES` (UTF-8) is rejected before parsing;
- a mapping with the same key twice is an error (YAML 1.1 ``<<`` merge keys excepted).

One reading differs from ``yaml.safe_load``: a number with an exponent is a float as in YAML 1.2
(``1e9``, ``1.0e9``, ``-2E-3``, ``.5e3``), where YAML 1.1 wants a dot and a signed exponent and
reads these as strings (:data:`EXPONENT_FLOAT`).

Every failure, including plain syntax errors and scalars Python cannot build (e.g. the date
``2020-13-01``), is raised as ``error`` (default :class:`YamlInputError`).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode

from tdcm_ros.errors import InputError

#: deepest nesting of sequences and mappings (the top-level collection is level 1)
MAX_DEPTH_LEVELS = 64
#: largest accepted text, UTF-8 encoded: 64 KiB, 20x the largest shipped file and still parsed in
#: about 0.2 s by the pure-Python parser (1 MiB of valid YAML took 3-8 s)
MAX_INPUT_BYTES = 64 * 1024

_MERGE_TAG = "tag:yaml.org,2002:merge"
_FLOAT_TAG = "tag:yaml.org,2002:float"
#: plain scalars that are floats in YAML 1.2's core schema but strings in YAML 1.1: an exponent
#: without a dot in the mantissa or without a sign (1e9, 1.0e9, -2E-3, .5e3, 1.e9)
EXPONENT_FLOAT = re.compile(r"^[-+]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)[eE][-+]?[0-9]+$")
#: what ``SafeConstructor`` raises for tagged scalars it cannot build
_SCALAR_FAILURES = (ValueError, ArithmeticError, LookupError, AttributeError)


class YamlInputError(InputError, yaml.YAMLError):
    """YAML text that is malformed or exceeds a bound; also a ``yaml.YAMLError`` so callers
    that fall back on unreadable YAML (bag metadata) keep doing so."""


class _LimitError(yaml.MarkedYAMLError):
    """A bound was exceeded at ``problem_mark``; ``allowed`` states the bound."""

    def __init__(self, problem: str, mark: yaml.Mark, allowed: str) -> None:
        super().__init__(problem=problem, problem_mark=mark)
        self.allowed = allowed


class _BoundedLoader(yaml.SafeLoader):
    """``SafeLoader`` without anchors or aliases, with a nesting bound and unique keys."""

    def __init__(self, text: str) -> None:
        super().__init__(text)
        self._depth = 0

    def compose_node(self, parent: Node | None, index: Any) -> Node | None:
        """Reject anchors and aliases; count nesting depth around collections."""
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent) or event.anchor is not None:
            raise _LimitError("anchors and aliases (&, *) are not accepted",
                              event.start_mark, "YAML without anchors or aliases")
        if isinstance(event, yaml.ScalarEvent):
            return super().compose_node(parent, index)
        self._depth += 1
        if self._depth > MAX_DEPTH_LEVELS:
            raise _LimitError(f"nesting deeper than {MAX_DEPTH_LEVELS} levels",
                              event.start_mark, f"at most {MAX_DEPTH_LEVELS} nested levels")
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_object(self, node: Node, deep: bool = False) -> Any:
        """The node's value; a scalar Python cannot build (a 13th month, an integer of more
        than 4300 digits, an empty ``!!float``, ``!!bool x``) is a constructor error at the
        node's line (``SafeConstructor`` raises these as plain Python errors)."""
        try:
            return super().construct_object(node, deep=deep)
        except _SCALAR_FAILURES as problem:
            raise yaml.constructor.ConstructorError(
                None, None, f"cannot build {node.tag} ({type(problem).__name__}: {problem})",
                node.start_mark) from problem

    def construct_mapping(self, node: MappingNode, deep: bool = False) -> dict[Any, Any]:
        """The mapping, after checking that no scalar key occurs twice."""
        first_line: dict[Any, int] = {}
        for key_node, _ in node.value:
            if not isinstance(key_node, ScalarNode) or key_node.tag == _MERGE_TAG:
                continue
            key = self.construct_object(key_node)
            line = key_node.start_mark.line + 1
            if key in first_line:
                raise _LimitError(f"duplicate key {key!r} (first at line {first_line[key]})",
                                  key_node.start_mark, "each key once per mapping")
            first_line[key] = line
        return super().construct_mapping(node, deep=deep)


# Appended after YAML 1.1's own resolvers (PyYAML copies the inherited table first, so
# ``yaml.SafeLoader`` is unchanged): only scalars that 1.1 reads as strings become floats.
_BoundedLoader.add_implicit_resolver(_FLOAT_TAG, EXPONENT_FLOAT, list("-+0123456789."))


def _oversize(text: str, source: str) -> str | None:
    """Why ``text`` is over :data:`MAX_INPUT_BYTES`, naming the line the limit falls on."""
    data = text.encode("utf-8", "surrogatepass")
    if len(data) <= MAX_INPUT_BYTES:
        return None
    line = data.count(b"\n", 0, MAX_INPUT_BYTES) + 1
    return (f"{source}: {len(data)} bytes of YAML, over the limit of {MAX_INPUT_BYTES} bytes "
            f"at line {line}")


def load_yaml(text: str, source: str, *, parameter: str | None = None,
              error: type[InputError] = YamlInputError) -> Any:
    """The value of one YAML document ``text`` read from ``source`` (a file or parameter
    name, shown in messages); ``error(message, parameter=parameter or source, value=source,
    allowed=...)`` on any problem (see the module docstring)."""
    return _guarded(text, source, parameter, error, _load)


def _guarded(text: str, source: str, parameter: str | None, error: type[InputError],
             read: Callable[[str], Any]) -> Any:
    """``read(text)`` with the size bound first and every YAML failure as ``error``."""
    name = parameter or source
    if too_big := _oversize(text, source):
        raise error(too_big, parameter=name, value=source,
                    allowed=f"at most {MAX_INPUT_BYTES} bytes")
    try:
        return read(text)
    except _LimitError as problem:
        raise error(_describe(source, problem), parameter=name, value=source,
                    allowed=problem.allowed) from problem
    except yaml.YAMLError as problem:
        raise error(_describe(source, problem, "not valid YAML: "), parameter=name,
                    value=source, allowed="valid YAML") from problem


#: the tag :func:`compose_yaml` gives a node whose tag was not written (YAML's resolvers skipped)
UNTAGGED = ""


class _UntaggedLoader(_BoundedLoader):
    """The bounded composer that leaves a node's tag as written (``UNTAGGED`` when none was),
    for readers with their own typing rules (rcl's, for parameter files)."""

    def resolve(self, kind: type[Node], value: Any, implicit: Any) -> str:
        """No implicit resolution: the written tag, or ``UNTAGGED``."""
        return UNTAGGED


def compose_yaml(text: str, source: str, *, parameter: str | None = None,
                 error: type[InputError] = YamlInputError) -> Node | None:
    """The node tree of one YAML document ``text`` (``None`` if empty) under the same bounds as
    :func:`load_yaml`, with scalars left as written (value, style, explicit tag or
    ``UNTAGGED``); duplicate keys are the reader's to handle."""
    return _guarded(text, source, parameter, error, _compose)


def _compose(text: str) -> Node | None:
    loader = _UntaggedLoader(text)
    try:
        node: Node | None = loader.get_single_node()
        return node
    finally:
        loader.dispose()


def _load(text: str) -> Any:
    """The single document of ``text`` (raises ``yaml.YAMLError``, including bounds)."""
    loader = _BoundedLoader(text)
    try:
        return loader.get_single_data()
    finally:
        loader.dispose()


def _describe(source: str, problem: yaml.YAMLError, prefix: str = "") -> str:
    """One line: ``source: line N: {prefix}what is wrong``."""
    mark = getattr(problem, "problem_mark", None) or getattr(problem, "context_mark", None)
    where = f"{source}: line {mark.line + 1}" if mark is not None else source
    what = getattr(problem, "problem", None) or str(problem)
    context = getattr(problem, "context", None)
    detail = f"{context} {what}" if context else what
    return f"{where}: {prefix}{detail}".replace("\n", " ")
