"""One table of parameter files and ``-p`` items, read by the package's reader and by rcl.

Each row gives sources (files as text, :class:`CliParam` items) and what a node reads from
them. The embedded test checks the package's reader against the row; the ``rclpy`` test checks
rclpy itself (rcl's parser and rclpy's matching) against the same row, so a row that does not
hold for rcl fails in the rclpy half of CI: the two runtimes read one file alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from tdcm_ros.errors import InputError
from tdcm_ros.runtime.params import CliParam, Source, node_parameters
from test.support.graph import private_domain_id, require_rclpy

NOT_SET = object()  # rcl holds the name with no value (an empty sequence)


@dataclass(frozen=True)
class Row:
    """Sources, and per node ``/ns/name`` the values it reads (or ``refused``: a phrase of
    the package's error, where rcl refuses the sources too)."""

    sources: tuple[str | CliParam, ...]
    reads: dict[str, dict[str, Any]] = field(default_factory=dict)
    refused: str = ""
    #: what rcl reads where the package refuses on purpose: a name with no value (``[]``), or
    #: its parser's garbage for a nested collection (``[[1]]`` is ``[1]``, ``[1, [2]]`` ``[2]``)
    rcl_reads: dict[str, dict[str, Any]] | None = None


def params(node: str, body: str) -> str:
    """A file block ``node: {ros__parameters: ...}`` from ``name: value`` lines."""
    lines = "".join(f"    {line}\n" for line in body.strip().splitlines())
    return f"{node}:\n  ros__parameters:\n{lines}"


SCALARS = """
b_y: y
b_no: no
b_on: On
i_hex: 0x1F
i_oct: 010
i_neg: -42
d_08: 08
d_exp: 1e9
d_signed: 1.85e+9
d_inf: inf
d_yaml_inf: -.inf
d_nan: .nan
d_past_int64: 9223372036854775808
s_tilde: ~
s_null: null
s_underscore: 1_000
s_sexagesimal: 1:30
s_binary: 0b11
s_date: 2020-01-01
s_overflow: 1e999
s_subnormal: 1e-310
s_quoted: '5'
s_double_quoted: "y"
s_tagged: !!str 1.5
s_word: hello
s_empty: ''
"""

ROWS: dict[str, Row] = {
    "scalars take rcl's types": Row((params("talker", SCALARS),), {"/talker": {
        "b_y": True, "b_no": False, "b_on": True, "i_hex": 31, "i_oct": 8, "i_neg": -42,
        "d_08": 8.0, "d_exp": 1e9, "d_signed": 1.85e9, "d_inf": math.inf, "d_yaml_inf": -math.inf,
        "d_nan": math.nan, "d_past_int64": 9223372036854775808.0, "s_tilde": "~",
        "s_null": "null", "s_underscore": "1_000", "s_sexagesimal": "1:30", "s_binary": "0b11",
        "s_date": "2020-01-01", "s_overflow": "1e999", "s_subnormal": "1e-310", "s_quoted": "5",
        "s_double_quoted": "y", "s_tagged": "1.5", "s_word": "hello", "s_empty": ""}}),
    "sequences of one type": Row((params("talker", """
bools: [y, off, true]
ints: [1, 0x10, -3]
doubles: [0.5, 1e3, .inf]
strings: [a, '1', ~]
nested: {deeper: {x: 2}}
"""),), {"/talker": {"bools": [True, False, True], "ints": [1, 16, -3],
                      "doubles": [0.5, 1000.0, math.inf], "strings": ["a", "1", "~"],
                      "nested.deeper.x": 2}}),
    "a later wildcard entry wins over an earlier exact one": Row(
        (params("talker", "rate: 2.0") + params("/**", "rate: 1.0"),),
        {"/talker": {"rate": 1.0}}),
    "a key written again merges into its first place": Row(
        (params("/talker", "a: 1") + params("/**", "a: 2") + params("talker", "a: 3")
         + params("/talker", "b: 4"),),
        {"/talker": {"a": 3, "b": 4}}),
    "within one key the first type of rclpy's order wins": Row(
        (params("/**", "a: text\nc: [1, 2]") + params("/**", "a: 7\nb: 1\nc: 3.5")
         + params("/**", "b: 2"),),
        {"/talker": {"a": 7, "b": 2, "c": 3.5}}),
    "files fill one table": Row(
        (params("/**", "a: 1") + params("talker", "a: 2"), params("/**", "a: 3")),
        {"/talker": {"a": 2}, "/other": {"a": 3}}),
    "-p without a node merges into /**": Row(
        (params("/**", "a: 1") + params("talker", "a: 2"), CliParam("a:=5"), CliParam("b:=y")),
        {"/talker": {"a": 2, "b": True}, "/other": {"a": 5, "b": True}}),
    "-p with a node names /node": Row(
        (CliParam("talker:a:=0x10"),), {"/talker": {"a": 16}, "/lab/talker": {}}),
    "nested keys and whole-token wildcards": Row(
        ("robot1:\n" + "".join(f"  {line}\n" for line in params("talker", "a: 1").splitlines())
         + params("/*/model", "b: 2") + params("/**/model", "c: 3"),),
        {"/robot1/talker": {"a": 1}, "/x/model": {"b": 2, "c": 3}, "/model": {"c": 3},
         "/x/y/model": {"c": 3}}),
    "a partial wildcard is refused": Row((params("/ns/pro*", "a: 1"),),
                                         refused="is not a node or namespace token"),
    "a token starting with a digit is refused": Row((params("/1ns/talker", "a: 1"),),
                                                    refused="is not a node or namespace token"),
    "a mixed sequence is refused": Row((params("talker", "a: [1, 2.5]"),), refused="mixes"),
    "a sequence in a sequence is refused (rcl flattens it)": Row(
        (params("talker", "a: [[1]]"),), refused="nests a collection",
        rcl_reads={"/talker": {"a": [1]}}),
    "a missing value is refused": Row((params("talker", "a:"),), refused="has no value"),
    "an empty sequence is refused (rcl holds no value)": Row(
        (params("talker", "a: []"),), refused="empty sequence",
        rcl_reads={"/talker": {"a": NOT_SET}}),
}


def write_sources(row: Row, folder: Path) -> list[Source]:
    sources: list[Source] = []
    for i, source in enumerate(row.sources):
        if isinstance(source, CliParam):
            sources.append(source)
        else:
            path = folder / f"params_{i}.yaml"
            path.write_text(source, encoding="utf-8")
            sources.append(path)
    return sources


def same(read: dict[str, Any], expected: dict[str, Any]) -> bool:
    """Equal names, values and types (``True`` is not ``1``, ``2`` is not ``2.0``; NaN is NaN)."""
    def one(a: Any, b: Any) -> bool:
        if isinstance(b, list):
            return isinstance(a, list) and len(a) == len(b) and all(map(one, a, b))
        if isinstance(b, float) and math.isnan(b):
            return isinstance(a, float) and math.isnan(a)
        return type(a) is type(b) and a == b
    return read.keys() == expected.keys() and all(one(read[k], expected[k]) for k in expected)


@pytest.mark.parametrize("name", ROWS)
def test_the_package_reads_each_row(name: str, tmp_path: Path) -> None:
    row = ROWS[name]
    sources = write_sources(row, tmp_path)
    if row.refused:
        with pytest.raises(InputError, match=row.refused):
            node_parameters(sources, "/talker")
        return
    for node, expected in row.reads.items():
        read = node_parameters(sources, node)
        assert same(read, expected), (node, read)


def rclpy_reads(sources: list[Source], fully_qualified_name: str) -> dict[str, Any]:
    """What rclpy gives a node ``/ns/name`` started with ``sources`` as ROS arguments."""
    import rclpy
    from rclpy.context import Context
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from rclpy.signals import SignalHandlerOptions

    from tdcm_ros.runtime.rclpy_runtime import plain_value

    args = ["tdcm", "--ros-args"]
    for source in sources:
        args += ["-p", source.item] if isinstance(source, CliParam) else ["--params-file", str(source)]
    context = Context()
    rclpy.init(args=args, context=context, signal_handler_options=SignalHandlerOptions.NO)
    try:
        namespace, _, name = fully_qualified_name.rpartition("/")
        node = Node(name, namespace=namespace or "/", context=context)
        try:
            return {key: NOT_SET if p.type_ == Parameter.Type.NOT_SET else plain_value(p.value)
                    for key, p in node._parameter_overrides.items()}
        finally:
            node.destroy_node()
    finally:
        context.try_shutdown()


@pytest.mark.rclpy
@pytest.mark.parametrize("name", ROWS)
def test_rclpy_reads_each_row_alike(name: str, tmp_path: Path,
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    require_rclpy()
    monkeypatch.setenv("ROS_DOMAIN_ID", str(private_domain_id()))
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    row = ROWS[name]
    sources = write_sources(row, tmp_path)
    if row.refused and row.rcl_reads is None:
        with pytest.raises(Exception, match="(?i)parse|invalid|error"):
            rclpy_reads(sources, "/talker")
        return
    for node, expected in (row.rcl_reads or row.reads).items():
        read = rclpy_reads(sources, node)
        if any(value is NOT_SET for value in expected.values()):
            assert read == expected, (node, read)
        else:
            assert same(read, expected), (node, read)
