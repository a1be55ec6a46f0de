"""The command examples the docs give: every ``tdcm`` / ``python3 -m tdcm_ros`` line of the shell
blocks of the README and of every page of the docs site (``doc/**/*.md``), and of each ``--help``
epilog's ``examples:``, as argument lists."""

from __future__ import annotations

import argparse
import re
import shlex
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
#: A command line: optional ``NAME=VALUE`` environment, then tdcm's entry point.
_COMMAND = re.compile(r"^((?:[A-Z_]+=\S+ )*)(tdcm|python3? -m tdcm_ros)( .*)?$")
#: A synopsis, not an example: optional parts in brackets, alternatives, ``ARG...``.
_SYNOPSIS = re.compile(r"\[-|\[[A-Z]|\.\.\.|\|\s*--| \| |[A-Z]\|[A-Z]")


@dataclass(frozen=True)
class Example:
    """One documented command: where it is written, its environment and its arguments."""

    where: str
    env: dict[str, str]
    argv: list[str]

    @property
    def verb(self) -> str:
        """``solve``, ``topic pub``, ... (the subcommand and, for grouped ones, its verb)."""
        words = [a for a in self.argv[:2] if not a.startswith("-")]
        return " ".join(words[:2]) if words and words[0] in GROUPED else (words[:1] or [""])[0]


#: Subcommands whose first argument is a verb.
GROUPED = ("topic", "param", "bag", "service", "scene", "figures")


def _parse(line: str, where: str) -> Example | None:
    match = _COMMAND.match(line.strip())
    if match is None or _SYNOPSIS.search(line):
        return None
    env = dict(item.split("=", 1) for item in match.group(1).split())
    words = shlex.split(match.group(3) or "", comments=True)
    for redirect in (">", ">>", "|"):  # the shell's part of a line is not tdcm's
        if redirect in words:
            words = words[:words.index(redirect)]
    return Example(where, env, words)


#: A fence opener: three or more backticks, then the language or a MyST directive (``{toctree}``).
_FENCE = re.compile(r"^(`{3,})\s*(\S*)")
#: The languages of a shell block.
SHELL = ("bash", "sh", "")


@dataclass(frozen=True)
class Block:
    """One fenced block of a Markdown file: its language, the number of its first line inside
    the fence (1-based) and its lines."""

    language: str
    first_line: int
    lines: list[str]


def doc_pages() -> list[Path]:
    """The README and every page of the docs site (not a build's output)."""
    return [REPO / "README.md",
            *(p for p in sorted((REPO / "doc").rglob("*.md")) if "_build" not in p.parts)]


def fenced_blocks(path: Path) -> list[Block]:
    """The fenced blocks of a Markdown file, as MyST reads them: a fence closes only on a line of
    its own backticks, so a longer fence may hold shorter ones."""
    found: list[Block] = []
    fence, language, first, lines = "", "", 0, []
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if not fence:
            opener = _FENCE.match(line)
            if opener:
                fence, language, first, lines = opener.group(1), opener.group(2), number + 1, []
        elif line.strip() == fence:
            found.append(Block(language, first, lines))
            fence = ""
        else:
            lines.append(line)
    return found


def documented_examples(parser: argparse.ArgumentParser) -> list[Example]:
    """Every command the docs give, each once (where it is first written): :func:`shell_examples`
    of the README and of every page of the docs site, then ``parser``'s :func:`epilog_examples`."""
    found: dict[tuple[str, ...], Example] = {}
    candidates = [e for page in doc_pages() for e in shell_examples(page)]
    for example in [*candidates, *epilog_examples(parser)]:
        key = (*sorted(f"{k}={v}" for k, v in example.env.items()), "--", *example.argv)
        found.setdefault(key, example)
    return list(found.values())


def shell_examples(path: Path) -> list[Example]:
    """The commands of a Markdown file's shell blocks (a ``\\`` continuation joined)."""
    found: list[Example] = []
    where = path.relative_to(REPO)
    for block in fenced_blocks(path):
        if block.language not in SHELL:
            continue
        pending, start = "", 0
        for number, line in enumerate(block.lines, block.first_line):
            if not pending:
                start = number
            if line.rstrip().endswith("\\"):
                pending += line.rstrip()[:-1] + " "
                continue
            example = _parse(pending + line, f"{where}:{start}")
            pending = ""
            if example is not None:
                found.append(example)
    return found


def epilog_examples(parser: argparse.ArgumentParser, prog: str = "tdcm") -> list[Example]:
    """The ``examples:`` lines of every (sub)command's ``--help`` epilog."""
    found: list[Example] = []
    text = parser.epilog or ""
    if "examples:" in text:
        for line in text.split("examples:", 1)[1].splitlines():
            example = _parse(line, f"{prog} --help")
            if example is not None:
                found.append(example)
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                found.extend(epilog_examples(sub, f"{prog} {name}"))
    return found
