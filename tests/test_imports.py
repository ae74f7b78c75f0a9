"""Who may import whom, read from the sources (ast), not from a running process: every package imports only the
floors below its own (docs/architecture.md), the HTTP package (`service/api/`) is imported by nothing outside it
but the service's assembly and the command that starts it, the bay runtime imports none of its adapters (HTTP,
Open Connect, the viewer) and they import neither each other nor the HTTP app, and the shot contract holds no HTTP
code."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HTTP_PACKAGE = "golfflight.service.api"
HTTP_FOLDER = ROOT / "service" / "api"
STARTS_THE_APP = ROOT / "golfflight" / "commands" / "serve.py"
ASSEMBLES_THE_SERVICE = ROOT / "service" / "app.py"
RUNTIME = "golfflight.service.runtime"
ADAPTERS = ("golfflight.service.api", "golfflight.service.open_connect", "golfflight.service.viewer")
"""The bay runtime's adapters: each sits on the runtime and none imports another (`service.app` joins them)."""
TIMES_THE_APP_FROM_INSIDE = ROOT / "benchmarks" / "profile_wire.py"
"""The profile of one request wraps the HTTP package's own functions to time them (docs/benchmarks.md)."""
HTTP_LIBRARIES = ("fastapi", "starlette", "uvicorn")
SKIPPED = {"tests", "build", ".git", "runs", ".venv"}
"""Folders whose modules are not the project's (tests start the app as a client would)."""


def virtual_environments() -> set[str]:
    """The checkout's top-level folders that are virtual environments, whatever their name (PEP 405: a pyvenv.cfg at
    their root): a user's `python3 -m venv env` beside the code holds other projects' modules."""
    return {path.parent.name for path in ROOT.glob("*/pyvenv.cfg")}


def _modules() -> list[Path]:
    skipped = SKIPPED | virtual_environments()
    return [path for path in sorted(ROOT.rglob("*.py")) if skipped.isdisjoint(path.relative_to(ROOT).parts)]


def imported(path: Path) -> set[str]:
    """Every module a source file imports, absolute and dotted; `from A import B` counts as A and A.B (B may be a
    module)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names |= {node.module} | {f"{node.module}.{alias.name}" for alias in node.names}
    return names


FLOORS = {
    "weights_schema": 0,
    "flight": 1,
    "shots": 2,
    "contract": 2,
    "service": 3,
    "sweep": 3,
    "discovery": 3,
    "evaluation": 3,
    "model_export": 4,
    "golfflight": 5,
}
"""Each package folder's floor: the flight core at the bottom (on the bundle's card schema), shot records and the
shot contract on it, the service, sweep, discovery and evaluation above, training over evaluation, the command line
on top. A package imports only from floors below its own, never sideways."""


NAMESPACE_ROOT = {"golfflight", "golfflight.__version__", "golfflight.errors"}
"""The namespace's own `__init__` (imported before any golfflight module anyway), its version and its failures (the
exception family every floor raises, `golfflight/errors.py`, which imports nothing of ours): every floor may read
them; the command line's modules (`golfflight.cli`, `golfflight.commands`) stay on the top floor."""


def _package(name: str) -> str | None:
    """The package folder a golfflight module belongs to (golfflight/ itself for the command line)."""
    parts = name.split(".")
    if parts[0] != "golfflight" or name in NAMESPACE_ROOT or ".".join(parts[:2]) == "golfflight.errors":
        return None
    return parts[1] if len(parts) > 1 and parts[1] in FLOORS else "golfflight"


def _within(name: str, package: str) -> bool:
    return name == package or name.startswith(package + ".")


def test_imported_reads_plain_and_from_imports(tmp_path):
    source = tmp_path / "example.py"
    source.write_text("import golfflight.service.api.app\nfrom golfflight.service import api\n")
    assert {"golfflight.service.api.app", "golfflight.service.api"} <= imported(source)


def test_the_failures_module_imports_nothing_of_ours():
    assert [name for name in imported(ROOT / "golfflight" / "errors.py") if name.startswith("golfflight")] == []


def test_every_package_folder_has_a_floor():
    assert {p.name for p in ROOT.iterdir() if (p / "__init__.py").is_file()} == set(FLOORS)


def test_every_package_imports_only_from_the_floors_below_it():
    offenders = []
    for folder, floor in FLOORS.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            for name in sorted(imported(path)):
                target = _package(name)
                if target not in (None, folder) and FLOORS[target] >= floor:
                    offenders.append(f"{path.relative_to(ROOT)} (floor {floor}) imports {name} (floor {FLOORS[target]})")
    assert offenders == []


def test_nothing_outside_the_http_package_imports_it_but_the_command_that_starts_the_app():
    offenders = [
        f"{path.relative_to(ROOT)} imports {name}"
        for path in _modules()
        if not path.is_relative_to(HTTP_FOLDER)
        and path not in (STARTS_THE_APP, ASSEMBLES_THE_SERVICE, TIMES_THE_APP_FROM_INSIDE)
        for name in sorted(imported(path))
        if _within(name, HTTP_PACKAGE)
    ]
    assert offenders == []


def test_the_shot_contract_holds_no_http_code():
    offenders = [
        f"{path.relative_to(ROOT)} imports {name}"
        for path in sorted((ROOT / "contract").rglob("*.py"))
        for name in sorted(imported(path))
        if any(_within(name, library) for library in HTTP_LIBRARIES)
    ]
    assert offenders == []


def _folder(package: str) -> Path:
    return ROOT.joinpath(*package.split(".")[1:])


def test_the_bay_runtime_imports_no_adapter_and_no_http_library():
    offenders = [
        f"{path.relative_to(ROOT)} imports {name}"
        for path in sorted(_folder(RUNTIME).rglob("*.py"))
        for name in sorted(imported(path))
        if any(_within(name, other) for other in (*ADAPTERS, *HTTP_LIBRARIES, "golfflight.service.app"))
    ]
    assert offenders == []


def test_the_adapters_import_neither_each_other_nor_the_assembly():
    offenders = [
        f"{path.relative_to(ROOT)} imports {name}"
        for adapter in ADAPTERS
        for path in sorted(_folder(adapter).rglob("*.py"))
        for name in sorted(imported(path))
        if any(_within(name, other) for other in (*ADAPTERS, "golfflight.service.app") if other != adapter)
    ]
    assert offenders == []
