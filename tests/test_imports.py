"""Who may import whom, read from the sources (ast), not from a running process: the HTTP package (`service/api/`)
is imported by nothing outside it but the command that starts the app, and the shot contract holds no HTTP code."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HTTP_PACKAGE = "golfflight.service.api"
HTTP_FOLDER = ROOT / "service" / "api"
STARTS_THE_APP = ROOT / "golfflight" / "commands" / "serve.py"
HTTP_LIBRARIES = ("fastapi", "starlette", "uvicorn")
SKIPPED = {"tests", "build", ".git", "runs", ".venv"}
"""Folders whose modules are not the project's (tests start the app as a client would)."""


def _modules() -> list[Path]:
    return [path for path in sorted(ROOT.rglob("*.py")) if SKIPPED.isdisjoint(path.relative_to(ROOT).parts)]


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


def _within(name: str, package: str) -> bool:
    return name == package or name.startswith(package + ".")


def test_imported_reads_plain_and_from_imports(tmp_path):
    source = tmp_path / "example.py"
    source.write_text("import golfflight.service.api.app\nfrom golfflight.service import api\n")
    assert {"golfflight.service.api.app", "golfflight.service.api"} <= imported(source)


def test_nothing_outside_the_http_package_imports_it_but_the_command_that_starts_the_app():
    offenders = [
        f"{path.relative_to(ROOT)} imports {name}"
        for path in _modules()
        if not path.is_relative_to(HTTP_FOLDER) and path != STARTS_THE_APP
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
