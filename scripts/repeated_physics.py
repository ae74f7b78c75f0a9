"""Find the physics written a second time by its formulas, not by a list: every function of the packages, outside the
flight core's one home of a piece of physics, whose source computes that piece again, and the code lines they take.

The pieces and the shapes that give them away (read from the syntax tree, so a renamed copy is still found):
- force: an operation on the ball's cross-section `BALL_AREA_M2`, or a dynamic pressure 0.5 x density x speed ** 2;
- spin ratio: `BALL_RADIUS_M` times one other factor, divided (R |w| / |v|);
- landing: a crossing fraction (a - h) / (a - b) (interpolation to the ground), or a sign change of height, a mask
  (a > h) & (b <= h);
- apex: an argmax of heights (the highest state), or a comparison of a height with a running `apex` / `peak`;
- slope hold: a call of `holding_slope_deg`, or `ROLLING_GRAVITY_FRACTION` inside an arctan (the steepest slope a
  surface holds a ball still on).
A function that calls a private helper of its own module found above does that helper's work too (its pieces).
HOMES names where each piece lives; they are not counted.

Why: issue 44 asks that the repeated physics come to at most 100 lines and issue 58 that a new copy be found without
adding it to a list by hand. The count is code lines of each function found, its signature included, without blank
lines and docstrings.

    python3 scripts/repeated_physics.py
"""

from __future__ import annotations

import ast
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

PACKAGES = ("golfflight", "flight", "service", "shots", "model_export", "weights_schema", "discovery", "sweep",
            "evaluation", "contract")
"""The folders of the installed packages (pyproject.toml's package-dir): tests, scripts and benchmarks may restate
a formula to check it."""

HOMES = {
    "force": {"flight/physics.py: accelerations"},
    "spin ratio": {"flight/physics.py: spin_ratio_of"},
    "landing": {"flight/events.py: came_down", "flight/events.py: crossing_fraction"},
    "apex": {"flight/events.py: rose_above", "flight/events.py: parabola_apex"},
    "slope hold": {"flight/ground/surfaces.py: holding_slope_deg", "flight/ground/surfaces.py: check_slope_held"},
}
"""The one home of each piece: the functions every other place calls."""


@dataclass(frozen=True)
class Finding:
    """One function that computes some piece of physics again: where, which pieces, and its code lines."""

    path: str
    function: str
    patterns: tuple[str, ...]
    lines: int

    @property
    def place(self) -> str:
        """`path: function`, as HOMES names places."""
        return f"{self.path}: {self.function}"


def _name(node: ast.AST) -> str:
    if isinstance(node, ast.Name):
        return node.id
    return node.attr if isinstance(node, ast.Attribute) else ""


def _factors(node: ast.AST) -> list[ast.AST]:
    """The factors of a product (a lone expression is its own one factor)."""
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mult):
        return _factors(node.left) + _factors(node.right)
    return [node]


def _same(a: ast.AST, b: ast.AST) -> bool:
    return ast.dump(a) == ast.dump(b)


def _is_force(node: ast.AST) -> bool:
    if isinstance(node, ast.BinOp) and any(_name(side) == "BALL_AREA_M2" for side in (node.left, node.right)):
        return True
    if not (isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mult)):
        return False
    factors = _factors(node)
    half = any(isinstance(f, ast.Constant) and f.value == 0.5 for f in factors)
    squared = any(isinstance(f, ast.BinOp) and isinstance(f.op, ast.Pow) and _is_constant(f.right, 2) for f in factors)
    dense = any(any(word in ast.unparse(f) for word in ("density", "rho")) for f in factors)
    return half and squared and dense


def _is_constant(node: ast.AST, value: float) -> bool:
    return isinstance(node, ast.Constant) and node.value == value


def _is_spin_ratio(node: ast.AST) -> bool:
    if not (isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div)):
        return False
    factors = _factors(node.left)
    return len(factors) == 2 and any(_name(f) == "BALL_RADIUS_M" for f in factors)


def _one_comparison(node: ast.AST) -> tuple[ast.AST, str, ast.AST] | None:
    """(side, "above" or "below", bound) of a comparison with one operator, else None."""
    if not (isinstance(node, ast.Compare) and len(node.ops) == 1):
        return None
    above = isinstance(node.ops[0], (ast.Gt, ast.GtE))
    if not (above or isinstance(node.ops[0], (ast.Lt, ast.LtE))):
        return None
    return node.left, "above" if above else "below", node.comparators[0]


def _is_landing(node: ast.AST) -> bool:
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div) and isinstance(node.right, ast.BinOp) \
            and isinstance(node.right.op, ast.Sub):
        start = node.left.left if isinstance(node.left, ast.BinOp) and isinstance(node.left.op, ast.Sub) else node.left
        return _same(start, node.right.left)
    pair = (node.left, node.right) if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitAnd) else \
        tuple(node.values) if isinstance(node, ast.BoolOp) and isinstance(node.op, ast.And) else ()
    if len(pair) != 2:
        return False
    first, second = (_one_comparison(side) for side in pair)
    return bool(first and second) and first[1] != second[1] and _same(first[2], second[2]) \
        and not _same(first[0], second[0])


def _is_height(node: ast.AST) -> bool:
    """A height: a name `z` or one with "height" in it, or a column 2 (z) of an array of states."""
    name = _name(node)
    if name == "z" or "height" in name:
        return True
    index = node.slice if isinstance(node, ast.Subscript) else None
    last = index.elts[-1] if isinstance(index, ast.Tuple) and index.elts else None
    return last is not None and _is_constant(last, 2)


def _holds_heights(node: ast.AST) -> bool:
    """Whether an expression is heights, or heights chosen by `where`: not a function of them (which balls crossed)."""
    if _is_height(node):
        return True
    if isinstance(node, ast.Call) and _name(node.func) != "where":
        return False
    return any(_holds_heights(inner) for inner in ast.iter_child_nodes(node))


def _is_apex(node: ast.AST) -> bool:
    if isinstance(node, ast.Call) and _name(node.func).endswith("argmax"):
        return any(_holds_heights(argument) for argument in node.args)
    comparison = _one_comparison(node)
    return comparison is not None and comparison[1] == "above" \
        and any(word in _name(comparison[2]) for word in ("apex", "peak"))


def _is_slope_hold(node: ast.AST) -> bool:
    if not isinstance(node, ast.Call):
        return False
    if _name(node.func) == "holding_slope_deg":
        return True
    return _name(node.func).endswith("arctan") \
        and any(_name(inner) == "ROLLING_GRAVITY_FRACTION" for inner in ast.walk(node))


PATTERNS: dict[str, Callable[[ast.AST], bool]] = {
    "force": _is_force,
    "spin ratio": _is_spin_ratio,
    "landing": _is_landing,
    "apex": _is_apex,
    "slope hold": _is_slope_hold,
}
"""Each piece's test of one node of a syntax tree."""


def _functions(tree: ast.Module) -> dict[str, ast.AST]:
    found: dict[str, ast.AST] = {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            found[node.name] = node
        if isinstance(node, ast.ClassDef):
            found |= {f"{node.name}.{m.name}": m for m in node.body
                      if isinstance(m, (ast.FunctionDef, ast.AsyncFunctionDef))}
    return found


def _docstring_lines(node: ast.AST) -> set[int]:
    lines: set[int] = set()
    for inner in ast.walk(node):
        body = getattr(inner, "body", None)
        if isinstance(inner, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and body \
                and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
                and isinstance(body[0].value.value, str):
            lines |= set(range(body[0].lineno, body[0].end_lineno + 1))
    return lines


def code_lines(source: str, node: ast.AST) -> int:
    """Code lines of a function in its module's source: its signature and body, without blank lines and
    docstrings."""
    text, docs = source.splitlines(), _docstring_lines(node)
    return sum(1 for n in range(node.lineno, node.end_lineno + 1) if n not in docs and text[n - 1].strip())


def _patterns(node: ast.AST) -> set[str]:
    return {name for name, found in PATTERNS.items() if any(found(inner) for inner in ast.walk(node))}


def _calls(node: ast.AST) -> set[str]:
    return {_name(inner.func) for inner in ast.walk(node) if isinstance(inner, ast.Call)}


def _passed_on(functions: dict[str, ast.AST], found: dict[str, set[str]]) -> None:
    """Give each function the pieces of the private helpers of its module that it calls, until none changes."""
    helpers = {name: name.rsplit(".", 1)[-1] for name in found if name.rsplit(".", 1)[-1].startswith("_")}
    calls = {name: _calls(node) for name, node in functions.items()}
    changed = True
    while changed:
        changed = False
        for name in functions:
            inherited = set().union(*(found[h] for h, short in helpers.items() if short in calls[name] and h != name))
            changed |= not inherited <= found[name]
            found[name] |= inherited


def _module_findings(path: str, source: str) -> Iterator[Finding]:
    """The functions of one module that compute a piece outside its home, a private helper's pieces passed on to
    its callers."""
    functions = _functions(ast.parse(source))
    found = {name: {p for p in _patterns(node) if f"{path}: {name}" not in HOMES[p]}
             for name, node in functions.items()}
    _passed_on(functions, found)
    for name, patterns in found.items():
        if patterns:
            yield Finding(path, name, tuple(p for p in PATTERNS if p in patterns), code_lines(source, functions[name]))


def find(root: Path = ROOT, folders: tuple[str, ...] = PACKAGES) -> list[Finding]:
    """Every function under `folders` of `root` that computes a piece of physics outside its home, by path."""
    findings: list[Finding] = []
    for folder in folders:
        for file in sorted((root / folder).rglob("*.py")):
            findings += _module_findings(file.relative_to(root).as_posix(), file.read_text())
    return findings


def home_exists(place: str, root: Path = ROOT) -> bool:
    """Whether a home (`path: function`) is still where HOMES says."""
    path, name = place.split(": ")
    file = root / path
    return file.exists() and name in _functions(ast.parse(file.read_text()))


def main() -> None:
    findings = find()
    print("\n| computes again | pieces | lines |\n|---|---|---:|")
    for finding in findings:
        print(f"| `{finding.place}` | {', '.join(finding.patterns)} | {finding.lines} |")
    print(f"| total | | {sum(f.lines for f in findings)} |")


if __name__ == "__main__":
    main()
