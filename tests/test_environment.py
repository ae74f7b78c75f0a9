"""One way in from the environment: `flight/environment_variables.py` (one pydantic-settings object) is the only
module of the package folders that reads (or sets) an environment variable, every variable it declares is in
docs/service.md's table and the table lists no other, and each variable still reaches what it sets, read by a real
process."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from pydantic_settings import BaseSettings
from golfflight.flight.environment_variables import VARIABLES, Environment, environment, set_for_children
from tests.test_imports import FLOORS, ROOT

THE_READER = ROOT / "flight" / "environment_variables.py"
ENVIRONMENT_CALLS = {"environ", "environb", "getenv", "getenvb", "putenv", "unsetenv"}
"""The `os` names that read or change the process's environment."""
TABLE_HEADING = "### Environment variables"


def environment_reads(path: Path, root: Path = ROOT) -> list[str]:
    """'path:line' of each use of `os.environ` and its kin in a source file (`os.X` or `from os import X`)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        attribute = isinstance(node, ast.Attribute) and node.attr in ENVIRONMENT_CALLS
        if attribute and getattr(node.value, "id", "") == "os" or _imports_from_os(node):
            found.append(f"{path.relative_to(root)}:{node.lineno}")
    return found


def _imports_from_os(node: ast.AST) -> bool:
    return isinstance(node, ast.ImportFrom) and node.module == "os" and bool({a.name for a in node.names} & ENVIRONMENT_CALLS)


def documented_variables() -> list[str]:
    """The variables named in the first column of docs/service.md's table under TABLE_HEADING."""
    text = (ROOT / "docs" / "service.md").read_text()
    assert TABLE_HEADING in text, f"docs/service.md has no {TABLE_HEADING!r} section"
    section = text.split(TABLE_HEADING, 1)[1].split("\n#", 1)[0]
    return [match.group(1) for match in re.finditer(r"^\| `\$([A-Z_]+)`", section, re.MULTILINE)]


def test_environment_reads_finds_every_spelling(tmp_path):
    source = tmp_path / "example.py"
    source.write_text("import os\nfrom os import getenv\na = os.environ.get('X')\nos.putenv('X', '1')\nb = os.sep\n")
    assert sorted(environment_reads(source, tmp_path)) == [f"example.py:{n}" for n in (2, 3, 4)]


def test_no_module_but_the_one_reader_touches_the_environment():
    found = [read for folder in FLOORS for path in sorted((ROOT / folder).rglob("*.py")) if path != THE_READER
             for read in environment_reads(path)]
    assert found == []
    assert environment_reads(THE_READER)


def test_pyproject_lists_pydantic_settings_as_a_runtime_dependency():
    dependencies = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    assert any(re.match(r"pydantic-settings\b", dependency) for dependency in dependencies)
    assert issubclass(Environment, BaseSettings)


def test_every_variable_is_in_the_one_table_of_docs_service_md():
    documented = documented_variables()
    assert len(documented) == len(set(documented))
    assert set(documented) == set(VARIABLES)


def test_ours_carry_the_prefix_and_empty_counts_as_unset(monkeypatch):
    assert [name for name in VARIABLES if not name.startswith("GOLFFLIGHT_")] == [
        "PROMETHEUS_MULTIPROC_DIR", "RAY_DATA_LOG_LEVEL"]  # their libraries' own names, read by them too
    for name in VARIABLES:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("GOLFFLIGHT_MODEL", "")
    monkeypatch.setenv("GOLFFLIGHT_API_KEY", "k")
    monkeypatch.setenv("GOLFFLIGHT_METRICS_DIR", "/not/read")  # a field with its library's name takes no prefix
    read = environment()
    assert (read.model, read.api_key, read.metrics_dir, read.cors_origins) == (None, "k", None, ())
    monkeypatch.setenv("PROMETHEUS_MULTIPROC_DIR", "/metrics")
    monkeypatch.setenv("GOLFFLIGHT_CORS_ORIGINS", " https://a.example,, https://b.example ")
    read = environment()
    assert (str(read.metrics_dir), read.cors_origins) == ("/metrics", ("https://a.example", "https://b.example"))
    with pytest.raises(KeyError, match="GOLFFLIGHT_MODLE is not one of golfflight's environment variables"):
        set_for_children("GOLFFLIGHT_MODLE", "x")


def test_each_existing_name_still_sets_what_it_did_in_a_real_process(tmp_path):
    code = (
        "from golfflight.flight.bundle_location import model_dir\n"
        "from golfflight.shots.paths import shared_data_dir\n"
        "from golfflight.service.settings import ServiceSettings\n"
        "s = ServiceSettings.from_env()\n"
        "print(model_dir(), shared_data_dir(), s.api_key, s.cors_origins, s.allowed_hosts, s.bay_file, s.connect_port,"
        " s.connect_host, sep='|')\n"
    )
    environment = {
        "PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin", "GOLFFLIGHT_MODEL": str(tmp_path / "bundle"),
        "GOLFFLIGHT_SHARED_DATA": str(tmp_path / "data"), "GOLFFLIGHT_API_KEY": "key",
        "GOLFFLIGHT_CORS_ORIGINS": "https://a.example,https://b.example", "GOLFFLIGHT_ALLOWED_HOSTS": "bay.local",
        "GOLFFLIGHT_BAY_FILE": str(tmp_path / "bay.json"), "GOLFFLIGHT_CONNECT_PORT": "921",
        "GOLFFLIGHT_CONNECT_HOST": "0.0.0.0",
    }
    ran = subprocess.run([sys.executable, "-c", code], env=environment, capture_output=True, text=True, timeout=120)
    assert ran.returncode == 0, ran.stderr
    assert ran.stdout.strip().split("|") == [
        str(tmp_path / "bundle"), str(tmp_path / "data"), "key", "('https://a.example', 'https://b.example')",
        "('bay.local',)", str(tmp_path / "bay.json"), "921", "0.0.0.0",
    ]
