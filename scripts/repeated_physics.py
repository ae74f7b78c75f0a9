"""Count the lines of physics written a second time: the functions outside the flight core's one home of each piece
(the equations, the integrator's loop, landing and apex, wind, per-shot air, figures and rests, the ground driver)
that do that piece's work again, and, apart, the thin wrappers that only call a home.

Why: issue 44 asks that the repeated physics come to at most 100 lines. The count is code lines of each function,
its signature included, without blank lines and docstrings. The lists below are the functions that were copies when
the issue was filed and are still here (a removed one counts nothing); a new copy has to be added to them by hand,
which reading a change is for.

    python3 scripts/repeated_physics.py
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

REPEATS = {
    "flight/engine.py": ["FlightEngine.fly"],
    "flight/rollout.py": ["_first_crossing", "hard_landing", "apex"],
}
"""Functions that do a home's work again: the single shot's float loop (its latency path: the step loop, landing and
apex marks on floats) and training's differentiable readers of a trajectory's landing and apex."""

WRAPPERS = {
    "flight/rollout.py": ["euler_rollout"],
    "flight/torch_engine.py": ["TorchEngine._fly_part"],
    "flight/ground/phase.py": ["ground_phase_one"],
}
"""Functions that were copies and now only put their inputs into a home's call (`integrate`, the ground driver)."""


def _functions(tree: ast.Module) -> dict[str, ast.AST]:
    found: dict[str, ast.AST] = {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            found[node.name] = node
        if isinstance(node, ast.ClassDef):
            found |= {f"{node.name}.{m.name}": m for m in node.body if isinstance(m, ast.FunctionDef)}
    return found


def _docstring_lines(node: ast.AST) -> set[int]:
    lines: set[int] = set()
    for inner in ast.walk(node):
        body = getattr(inner, "body", None)
        if isinstance(inner, (ast.FunctionDef, ast.ClassDef)) and body and isinstance(body[0], ast.Expr) \
                and isinstance(body[0].value, ast.Constant) and isinstance(body[0].value.value, str):
            lines |= set(range(body[0].lineno, body[0].end_lineno + 1))
    return lines


def code_lines(path: str, name: str) -> int:
    """Code lines of a module's function (`Class.method` for a method): 0 where it is gone."""
    source = (ROOT / path).read_text()
    node = _functions(ast.parse(source)).get(name)
    if node is None:
        return 0
    text, docs = source.splitlines(), _docstring_lines(node)
    return sum(1 for n in range(node.lineno, node.end_lineno + 1) if n not in docs and text[n - 1].strip())


def count(functions: dict[str, list[str]]) -> list[tuple[str, int]]:
    """("path: function", code lines) of each function listed."""
    return [(f"{path}: {name}", code_lines(path, name)) for path, names in functions.items() for name in names]


def main() -> None:
    for title, functions in (("repeats a home's work", REPEATS), ("only calls a home", WRAPPERS)):
        rows = count(functions)
        print(f"\n| {title} | lines |\n|---|---:|")
        for name, lines in rows:
            print(f"| `{name}` | {lines} |")
        print(f"| total | {sum(lines for _, lines in rows)} |")


if __name__ == "__main__":
    main()
