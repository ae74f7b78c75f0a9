"""Issue 58, item 1: one way in. docs/architecture.md's "Every way to fly" names each public way into the flight core
and the contract (at most 8, each there in the code, and every public `fly*` of those floors among them); the
engines' `fly_batch` is one signature, the protocol's (`flight.problem.Engine`); and no class outside `flight/`
wraps a Flyer (forwards its attributes or flies through it for its callers)."""

from __future__ import annotations

import ast
import importlib
import inspect
import re
from pathlib import Path

import pytest
from golfflight.flight.engine import FlightEngine
from golfflight.flight.flyer import Flyer
from golfflight.flight.problem import Engine

ROOT = Path(__file__).resolve().parents[1]
WAY = re.compile(r"^\| `([\w.]+)` \|")
MOST_WAYS = 8
"""The issue's bound on the public ways to fly."""
CORE_FLOORS = ("flight", "contract")
"""The floors whose public `fly*` functions and methods are ways to fly; the floors above call them."""
FLYER_HOLDERS = ("flyer", "_flyer")
"""The attribute names a class holding a Flyer keeps it under."""


def listed_ways() -> list[str]:
    """The dotted names of docs/architecture.md's table under "## Every way to fly"."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    section = text.split("## Every way to fly", 1)[1].split("\n## ", 1)[0]
    return [match.group(1) for line in section.splitlines() if (match := WAY.match(line))]


def resolve(dotted: str):
    """The object a dotted name under `golfflight.` names (a module's function, or a class's method)."""
    parts = dotted.split(".")
    for cut in range(len(parts) - 1, 0, -1):
        try:
            target = importlib.import_module("golfflight." + ".".join(parts[:cut]))
        except ModuleNotFoundError:
            continue
        for name in parts[cut:]:
            target = getattr(target, name)
        return target
    raise AssertionError(f"{dotted}: no such module")


def public_fly_names() -> set[str]:
    """`folder.module.function` or `folder.module.Class.method` of every public def named fly* on the core floors."""
    found = set()
    for folder in CORE_FLOORS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            module = ".".join(path.relative_to(ROOT).with_suffix("").parts)
            tree = ast.parse(path.read_text())
            for node in tree.body:
                if isinstance(node, ast.FunctionDef) and node.name.startswith("fly"):
                    found.add(f"{module}.{node.name}")
                if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                    found |= {f"{module}.{node.name}.{item.name}" for item in node.body
                              if isinstance(item, ast.FunctionDef) and item.name.startswith("fly")}
    return found


def test_the_ways_to_fly_are_listed_at_most_eight_and_each_is_there():
    ways = listed_ways()
    assert 0 < len(ways) <= MOST_WAYS, ways
    for way in ways:
        assert callable(resolve(way)), way


def test_every_public_fly_of_the_flight_core_and_the_contract_is_a_listed_way():
    """An engine's `fly_batch` is the protocol's (`flight.problem.Engine.fly_batch`, listed once for all of them)."""
    ways = set(listed_ways())
    engines = {name for name in public_fly_names() if name.endswith(".fly_batch")}
    assert "flight.problem.Engine.fly_batch" in engines and "flight.problem.Engine.fly_batch" in ways
    assert public_fly_names() - engines <= ways, sorted(public_fly_names() - engines - ways)


def test_fly_batch_is_one_signature_the_protocols():
    torch_engine = pytest.importorskip("golfflight.flight.torch_engine")
    protocol = inspect.signature(Engine.fly_batch)
    for engine in (Flyer, FlightEngine, torch_engine.TorchEngine):
        assert inspect.signature(engine.fly_batch) == protocol, engine


def _forwards_a_flyer(function: ast.FunctionDef) -> bool:
    """Whether a method only hands something of its Flyer back (`return self.flyer.x`) or flies through it
    (`self.flyer.flight(...)`, `.fly_batch(...)`, `.fly(...)`)."""
    body = [s for s in function.body if not (isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant))]

    def of_flyer(node: ast.AST) -> bool:
        return (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Attribute)
                and isinstance(node.value.value, ast.Name) and node.value.value.id == "self"
                and node.value.attr in FLYER_HOLDERS)

    if len(body) == 1 and isinstance(body[0], ast.Return) and of_flyer(body[0].value):
        return True
    return any(isinstance(node, ast.Call) and of_flyer(node.func) and node.func.attr in ("flight", "fly", "fly_batch")
               for node in ast.walk(function))


def test_no_class_outside_flight_wraps_a_flyer():
    wrappers = []
    for path in sorted(ROOT.glob("*/**/*.py")):
        folder = path.relative_to(ROOT).parts[0]
        if folder in ("flight", "tests", "benchmarks", "scripts") or not (ROOT / folder / "__init__.py").exists():
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef):
                wrappers += [f"{path.relative_to(ROOT)}: {node.name}.{item.name}" for item in node.body
                             if isinstance(item, ast.FunctionDef) and _forwards_a_flyer(item)]
    assert not wrappers, wrappers
