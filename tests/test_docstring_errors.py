"""Docstrings name the failure a caller gets: `InputError` for a wrong field, option or file, never `ValueError`
(no module of ours raises a bare one, docs/architecture.md; an InputError is a ValueError only for older callers)."""

from __future__ import annotations

import ast
from pathlib import Path

from tests.test_imports import FLOORS, ROOT

THE_FAMILY = ROOT / "golfflight" / "errors.py"
"""The failures' own module, which says that an InputError is a ValueError too."""

def docstrings_naming_value_error(path: Path, root: Path = ROOT) -> set[str]:
    """`path:name` of every module, class and function in the file whose docstring names ValueError."""
    tree = ast.parse(path.read_text(), str(path))
    where = path.relative_to(root).as_posix()
    nodes = [tree, *(n for n in ast.walk(tree) if isinstance(n, (ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)))]
    return {
        f"{where}:{getattr(node, 'name', '<module>')}" for node in nodes if "ValueError" in (ast.get_docstring(node) or "")
    }


def test_docstrings_naming_value_error_finds_one(tmp_path):
    source = tmp_path / "example.py"
    source.write_text('def checked(x):\n    """x, or ValueError."""\n\n\ndef fine():\n    """InputError."""\n')
    assert docstrings_naming_value_error(source, tmp_path) == {"example.py:checked"}


def test_no_docstring_names_value_error_for_an_input_error():
    found = set()
    for folder in FLOORS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            if path != THE_FAMILY:
                found |= docstrings_naming_value_error(path)
    assert found == set()
