"""No import circles among the project's modules: every import counts, a function's own included (a lazy import that
closes a circle is still a circle: the two modules cannot be read, tested or moved one without the other). Read
from the sources (ast); `from A import B` is an edge to the module A.B where B is one, else to A."""

from __future__ import annotations

import ast
from pathlib import Path

from tests.test_imports import FLOORS, ROOT


def module_name(path: Path) -> str:
    """The dotted name a source file is imported by: `flight/engine.py` is golfflight.flight.engine."""
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts if parts[0] == "golfflight" else ["golfflight", *parts])


def project_modules() -> dict[str, Path]:
    """Every module of the package folders, by its dotted name."""
    return {module_name(path): path for folder in FLOORS for path in sorted((ROOT / folder).rglob("*.py"))}


def imports_of(path: Path, modules: dict[str, Path]) -> set[str]:
    """The project's modules a source file imports anywhere in it (module level, functions, TYPE_CHECKING blocks)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found |= {f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in modules else node.module for a in node.names}
    return found & modules.keys()


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected groups of more than one module (Tarjan's algorithm), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for other in sorted(graph.get(node, ())):
            if other not in index:
                visit(other)
                low[node] = min(low[node], low[other])
            elif other in stack:
                low[node] = min(low[node], index[other])
        if low[node] == index[node]:
            group = []
            while not group or group[-1] != node:
                group.append(stack.pop())
            if len(group) > 1:
                found.append(sorted(group))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return found


def test_circles_finds_a_lazy_circle_and_passes_a_line(tmp_path):
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert circles({"a": {"b"}, "b": {"c"}, "c": set()}) == []


def test_imports_of_counts_function_level_and_from_imports(tmp_path):
    source = tmp_path / "example.py"
    source.write_text("def f():\n    from golfflight.flight import engine\n    import golfflight.errors\n")
    modules = {"golfflight.flight": Path(), "golfflight.flight.engine": Path(), "golfflight.errors": Path()}
    assert imports_of(source, modules) == {"golfflight.flight.engine", "golfflight.errors"}


def test_no_import_circles_among_the_projects_modules():
    modules = project_modules()
    graph = {name: imports_of(path, modules) - {name} for name, path in modules.items()}
    assert circles(graph) == []
