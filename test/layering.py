"""Layering rules of a Python package, checked on its source with ``ast`` (nothing is imported).

A *unit* is a top-level subpackage or module of the package (``model``, ``errors``; the package's
own ``__init__`` is the unit ``__init__``). :class:`Rules` orders the units in layers and names the
submodules other units may import directly (entry points); :func:`violations` lists every breach:

- a unit that is in no layer, or has no import budget;
- a cycle among modules, counting every import (module level, inside functions, and imports made
  only for the type checker);
- an import from a unit to a unit in the same or a higher layer;
- a cross-unit import that reaches past the unit's face (``__init__``) to a submodule that is not
  an entry point (a script, ``if __name__ == "__main__":``, is one), or a module importing the
  face of its own unit;
- a face that imports a script below it (``python -m`` the script would then warn that it was
  imported before it ran);
- rclpy or zenoh imported anywhere in a ROS-free unit;
- a face that pulls, when imported, a heavy library outside its budget (followed through every
  module-level import, including the parent packages Python runs first).
"""

from __future__ import annotations

import ast
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

ROOT_UNIT = "__init__"


@dataclass(frozen=True)
class Import:
    """One import statement's target: ``target`` is a module of the package or, when
    ``external``, the top-level name of another distribution."""

    source: str
    target: str
    line: int
    runtime: bool  # run when ``source`` is imported: module level, not under TYPE_CHECKING
    external: bool


@dataclass(frozen=True)
class Rules:
    """``layers`` from the ground up, each a set of units that must not import each other."""

    package: str
    layers: tuple[frozenset[str], ...]
    entry_points: frozenset[str]  # dotted module names, e.g. "pkg.metrics.api"
    ros_free: frozenset[str]  # units
    face_budgets: Mapping[str, frozenset[str]]  # unit -> heavy libraries its face may pull
    heavy: frozenset[str]
    ros_libraries: frozenset[str] = frozenset({"rclpy", "zenoh"})

    def layer_of(self, unit: str) -> int | None:
        return next((i for i, layer in enumerate(self.layers) if unit in layer), None)


def find_modules(source_dir: Path, package: str) -> dict[str, Path]:
    """Dotted module name -> file, for every ``.py`` under ``source_dir`` (the package folder)."""
    found = {}
    for path in sorted(source_dir.rglob("*.py")):
        parts = path.relative_to(source_dir).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join((package, *parts))] = path
    return found


def unit_of(module: str) -> str:
    """The unit a dotted module name belongs to."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ROOT_UNIT


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _statements(body: list[ast.stmt], runtime: bool) -> Iterator[tuple[ast.stmt, bool]]:
    """Every statement with whether it runs at import time (functions and TYPE_CHECKING don't)."""
    for stmt in body:
        yield stmt, runtime
        if isinstance(stmt, ast.If) and _is_type_checking(stmt.test):
            yield from _statements(stmt.body, False)
            yield from _statements(stmt.orelse, runtime)
            continue
        inner = not isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
        for field in ("body", "orelse", "finalbody", "handlers", "cases"):
            for child in getattr(stmt, field, []) or []:
                block = child.body if isinstance(child, (ast.ExceptHandler, ast.match_case)) else [child]
                yield from _statements(block, runtime and inner)


def _resolve(name: str, known: Mapping[str, Path]) -> str:
    return name if name in known else name.rpartition(".")[0] if name.rpartition(".")[0] in known else name


def face_objects(path: Path, known: Mapping[str, Path]) -> set[str]:
    """Names a face binds to objects of its submodules (not to submodules): ``from .report
    import report`` makes ``report`` the function, though a submodule has the same name."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    return {alias.asname or alias.name for stmt in tree.body if isinstance(stmt, ast.ImportFrom)
            for alias in stmt.names if f"{stmt.module}.{alias.name}" not in known}


def imports_of(module: str, path: Path, known: Mapping[str, Path], package: str) -> list[Import]:
    """The imports in one module, targets resolved to modules of the package where they are
    (``from pkg.sub import name`` targets the module ``pkg.sub.name`` only when ``name`` is one
    and the face ``pkg.sub`` does not bind ``name`` to something else)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    here = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = []
    for stmt, runtime in _statements(tree.body, True):
        if isinstance(stmt, ast.Import):
            names = [alias.name for alias in stmt.names]
        elif isinstance(stmt, ast.ImportFrom):
            base = stmt.module or ""
            if stmt.level:
                anchor = here.split(".")[: len(here.split(".")) - (stmt.level - 1)]
                base = ".".join([*anchor, *([base] if base else [])])
            shadowed = (face_objects(known[base], known)
                        if base in known and base != module and known[base].name == "__init__.py"
                        else set())
            names = [f"{base}.{alias.name}"
                     if f"{base}.{alias.name}" in known and alias.name not in shadowed else base
                     for alias in stmt.names]
        else:
            continue
        for name in dict.fromkeys(names):
            internal = name == package or name.startswith(package + ".")
            target = _resolve(name, known) if internal else name.split(".")[0]
            found.append(Import(module, target, stmt.lineno, runtime, not internal))
    return found


def all_imports(source_dir: Path, package: str) -> tuple[dict[str, Path], list[Import]]:
    """Modules of the package and every import they make."""
    known = find_modules(source_dir, package)
    return known, [imp for name, path in known.items()
                   for imp in imports_of(name, path, known, package)]


def cycles(edges: Mapping[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (or a module importing itself)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(edges.get(node, ())):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1 or node in edges.get(node, ()):
                found.append(sorted(component))

    for node in sorted(edges):
        if node not in index:
            visit(node)
    return found


def _parents(module: str) -> list[str]:
    parts = module.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def is_script(path: Path) -> bool:
    """Whether the module runs as a script (``if __name__ == "__main__":`` at module level)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    return any(isinstance(stmt, ast.If) and "__name__" in ast.unparse(stmt.test)
               and "__main__" in ast.unparse(stmt.test) for stmt in tree.body)


def face_pulls(face: str, imports: list[Import]) -> set[str]:
    """Modules of the package and external top-level names imported (at import time) when
    ``face`` is imported."""
    runtime: dict[str, list[Import]] = {}
    for imp in imports:
        if imp.runtime:
            runtime.setdefault(imp.source, []).append(imp)
    seen: set[str] = set()
    todo = [*_parents(face), face]
    pulled: set[str] = set()
    while todo:
        module = todo.pop()
        if module in seen:
            continue
        seen.add(module)
        pulled.add(module)
        for imp in runtime.get(module, []):
            if imp.external:
                pulled.add(imp.target)
            else:
                todo += [*_parents(imp.target), imp.target]
    return pulled


def violations(rules: Rules, source_dir: Path) -> list[str]:
    """Every breach of ``rules`` in the package under ``source_dir``, as readable lines."""
    known, imports = all_imports(source_dir, rules.package)
    found: list[str] = []
    units = sorted({unit_of(m) for m in known})
    found += [f"unit {u!r} is in no layer" for u in units if rules.layer_of(u) is None]
    found += [f"unit {u!r} has no import budget" for u in units if u not in rules.face_budgets]
    edges: dict[str, set[str]] = {}
    for imp in imports:
        if not imp.external:
            edges.setdefault(imp.source, set()).add(imp.target)
    found += [f"import cycle among: {', '.join(c)}" for c in cycles(edges)]
    scripts = {m for m, path in known.items() if is_script(path)}
    for imp in imports:
        found += _import_violations(rules, imp, scripts)
    for script in sorted(scripts):
        found += [f"importing {face} imports the script {script} (python -m {script} would warn)"
                  for face in _parents(script)[1:] if script in face_pulls(face, imports)]
    for unit in units:
        face = rules.package if unit == ROOT_UNIT else f"{rules.package}.{unit}"
        extra = (face_pulls(face, imports) & rules.heavy) - rules.face_budgets.get(unit, frozenset())
        if extra:
            found.append(f"importing {face} pulls {', '.join(sorted(extra))} (over its budget)")
    return found


def _import_violations(rules: Rules, imp: Import, scripts: set[str]) -> list[str]:
    where = f"{imp.source}:{imp.line}"
    src = unit_of(imp.source)
    if imp.external:
        if src in rules.ros_free and imp.target in rules.ros_libraries:
            return [f"{where} imports {imp.target} in the ROS-free unit {src!r}"]
        return []
    dst = unit_of(imp.target)
    face = rules.package if dst == ROOT_UNIT else f"{rules.package}.{dst}"
    if src == dst:
        if imp.target == face and imp.source != face and src != ROOT_UNIT:
            return [f"{where} imports its own unit's face {face}"]
        return []
    found = []
    low, high = rules.layer_of(dst), rules.layer_of(src)
    if low is not None and high is not None and low >= high:
        side = "beside" if low == high else "above"
        found.append(f"{where} imports {imp.target}: {dst!r} is {side} {src!r} in the layers")
    if imp.target != face and imp.target not in rules.entry_points | scripts:
        found.append(f"{where} reaches past the face of {dst!r} into {imp.target}")
    return found
