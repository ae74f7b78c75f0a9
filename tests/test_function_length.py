"""Every function in the tree is shorter than MAX_LINES: a longer one is split into steps a reader can follow."""

from __future__ import annotations

import ast
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 80
"""A function of this many lines (from its `def` to its last line, as ast counts them) or more fails."""
OTHER_FOLDERS = ("scripts", "benchmarks", "tests")
"""Folders of Python that are not packages but are read and changed like them."""


def python_folders() -> list[Path]:
    """The package folders pyproject.toml maps into the golfflight namespace, and the other folders of Python."""
    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    packages = sorted(set(setuptools["package-dir"].values()))
    return [ROOT / folder for folder in (*packages, *OTHER_FOLDERS)]


def long_functions(path: Path, root: Path = ROOT) -> list[str]:
    """'path:line name (n lines)' for each function or method in `path` of MAX_LINES lines or more."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            lines = node.end_lineno - node.lineno + 1
            if lines >= MAX_LINES:
                found.append(f"{path.relative_to(root)}:{node.lineno} {node.name} ({lines} lines)")
    return found


def test_a_method_of_80_lines_is_found_and_one_of_79_is_not(tmp_path):
    statements = [f"        x{i} = {i}" for i in range(MAX_LINES - 1)]
    source = tmp_path / "holder.py"
    source.write_text(
        "class Holder:\n"
        + "    def long(self):\n"
        + "\n".join(statements)
        + "\n\n"
        + "    async def short(self):\n"
        + "\n".join(statements[:-1])
        + "\n"
    )
    assert long_functions(source, tmp_path) == [f"holder.py:2 long ({MAX_LINES} lines)"]


def test_every_package_folder_and_the_script_folders_are_read():
    folders = {path.name for path in python_folders()}
    assert {"golfflight", "flight", "service", "discovery", "scripts", "benchmarks", "tests"} <= folders
    assert all(path.is_dir() for path in python_folders())


def test_no_function_has_80_lines_or_more():
    offenders = [
        entry for folder in python_folders() for path in sorted(folder.rglob("*.py")) for entry in long_functions(path)
    ]
    assert offenders == [], "split these into steps:\n" + "\n".join(offenders)
