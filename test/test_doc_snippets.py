"""Every Python snippet the docs give runs as written: each ```python block of the README and the
docs site, and each ``python3 - <<'PY'`` here-document of their shell blocks, in a fresh process
from an empty folder with the checkout importable (the ``tdcm`` lines of the same blocks run in
test/cli/test_documented_examples.py). Snippets that talk to hardware are listed in
:data:`HARDWARE` and are not run: they only parse."""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from test.support.examples import REPO, SHELL, doc_pages, fenced_blocks

#: Snippets that need a real device (a serial port): parsed, not run.
HARDWARE = ("import serial",)
_HEREDOC = re.compile(r"^python3? - <<'?(\w+)'?\s*$")


@dataclass(frozen=True)
class Snippet:
    where: str
    code: str


def doc_snippets() -> list[Snippet]:
    """The Python snippets of the README and of every page of the docs site, in page order."""
    found: list[Snippet] = []
    for page in doc_pages():
        where = str(page.relative_to(REPO))
        for block in fenced_blocks(page):
            if block.language == "python":
                found.append(Snippet(f"{where}:{block.first_line - 1}", "\n".join(block.lines)))
            elif block.language in SHELL:
                found.extend(_heredocs(block.lines, where, block.first_line - 1))
    return found


def _heredocs(block: list[str], where: str, start: int) -> list[Snippet]:
    out, index = [], 0
    while index < len(block):
        match = _HEREDOC.match(block[index].strip())
        if match is None:
            index += 1
            continue
        end = block.index(match.group(1), index + 1)
        out.append(Snippet(f"{where}:{start + index + 1}", "\n".join(block[index + 1:end])))
        index = end + 1
    return out


SNIPPETS = doc_snippets()


def test_the_docs_have_snippets_to_run() -> None:
    wheres = {s.where.split(":")[0] for s in SNIPPETS}
    assert {"README.md", "doc/tutorials/first_solve.md", "doc/tutorials/evaluate_a_bag.md"} <= wheres


@pytest.mark.parametrize("snippet", SNIPPETS, ids=lambda s: s.where)
def test_every_snippet_runs(snippet: Snippet, tmp_path: Path) -> None:
    ast.parse(snippet.code, filename=snippet.where)
    if any(marker in snippet.code for marker in HARDWARE):
        return
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [
        str(REPO), os.environ.get("PYTHONPATH", "")])), "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, "-"], input=snippet.code, text=True, cwd=tmp_path,
                          env=env, capture_output=True, timeout=300, check=False)
    assert done.returncode == 0, f"{snippet.where}:\n{done.stderr[-2000:]}"
