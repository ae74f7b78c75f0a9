"""The bay runtime is a facade: its adapters (HTTP, Open Connect, the viewer) and the service's assembly call its
public methods and touch nothing else of it, and it has no public data to touch; every route reaches it one way
(`runtime_of`). Read from the sources (ast)."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

from golfflight.service.runtime import BayRuntime

from tests.test_imports import ADAPTERS, ROOT, _folder

FACADE = {name for name, member in inspect.getmembers(BayRuntime, inspect.isfunction) if not name.startswith("_")}
CALLERS = [path for adapter in ADAPTERS for path in sorted(_folder(adapter).rglob("*.py"))] + [ROOT / "service" / "app.py"]
RUNTIME_NAMES = {"runtime"}
"""What the callers name the runtime they hold."""


def _is_runtime(node: ast.AST) -> bool:
    """`runtime`, `runtime_of(...)` or `app.state.runtime`."""
    if isinstance(node, ast.Name):
        return node.id in RUNTIME_NAMES
    if isinstance(node, ast.Call):
        return getattr(node.func, "id", None) == "runtime_of"
    return isinstance(node, ast.Attribute) and node.attr == "runtime" and getattr(node.value, "attr", "") == "state"


def _touched(path: Path) -> list[tuple[int, str]]:
    """(line, attribute) of every attribute of the runtime a module reads."""
    return [
        (node.lineno, node.attr)
        for node in ast.walk(ast.parse(path.read_text(), str(path)))
        if isinstance(node, ast.Attribute) and _is_runtime(node.value) and node.attr != "runtime"
    ]


def test_the_facade_is_the_set_the_issue_names():
    assert {"fly", "fly_batch", "fly_gspro", "latency", "health", "model", "bay", "set_bay", "update_bay",
            "subscribe", "unsubscribe", "start_session", "session", "sessions", "session_summary", "metrics",
            "request_sinks", "load", "stop", "watch_bay", "on_player_change", "add_reporter", "bay_file"} == FACADE


def test_adapters_and_the_assembly_use_only_the_runtimes_public_methods():
    touched = [(path, line, name) for path in CALLERS for line, name in _touched(path)]
    assert touched, "the callers were read"
    offenders = [f"{path.relative_to(ROOT)}:{line} runtime.{name}" for path, line, name in touched if name not in FACADE]
    assert offenders == []


def test_the_runtime_has_no_public_data(tmp_path):
    runtime = BayRuntime(tmp_path)
    assert [name for name in vars(runtime) if not name.startswith("_")] == []


def test_every_route_reaches_the_runtime_one_way():
    readers = [
        f"{path.relative_to(ROOT)}:{node.lineno}"
        for path in CALLERS + sorted((ROOT / "service" / "api").rglob("*.py"))
        for node in ast.walk(ast.parse(path.read_text(), str(path)))
        if isinstance(node, ast.Attribute) and node.attr == "runtime" and getattr(node.value, "attr", "") == "state"
        and path.name != "app.py"
    ]
    assert readers == [], "routes call service.runtime.runtime_of(request)"
