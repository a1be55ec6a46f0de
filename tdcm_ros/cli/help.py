"""The parser class of every ``tdcm`` command: help texts whose examples keep their layout."""

from __future__ import annotations

import argparse
import textwrap


class ParagraphFormatter(argparse.HelpFormatter):
    """Wraps each paragraph of a description or epilog to the terminal (never inside a
    hyphenated name); a paragraph with indented lines (examples, one command per line) is
    printed as written."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        blocks = []
        for block in text.strip("\n").split("\n\n"):
            lines = block.splitlines()
            if any(line[:1].isspace() for line in lines):
                blocks.append("\n".join(indent + line for line in lines))
            else:
                blocks.append(textwrap.fill(" ".join(block.split()), width,
                                            initial_indent=indent, subsequent_indent=indent,
                                            break_on_hyphens=False))
        return "\n\n".join(blocks)


class TdcmParser(argparse.ArgumentParser):
    """An ``ArgumentParser`` formatting help with :class:`ParagraphFormatter`; subcommand
    parsers are made of the same class."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        kwargs.setdefault("formatter_class", ParagraphFormatter)
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
