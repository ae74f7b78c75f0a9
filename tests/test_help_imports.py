"""Issue 56, item 7: `golfflight --help` and each command's help import only what they show, not the work behind
every command (they took 1.7-3.8 s: `golfflight.commands` imported every command's dependencies up front).

Each help runs in a fresh interpreter, and what it imported is read from its `sys.modules`: none of ONNX Runtime,
FastAPI, PyTorch, SciPy or Arrow for any help, nor NumPy; pydantic only for `fly`'s, whose text lists the shot
contract's figures and ranges."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from golfflight.commands import COMMANDS
from golfflight.model_export.real_data import BUILDERS
from golfflight.model_export.real_sources import SOURCES

ROOT = Path(__file__).resolve().parents[1]
NEVER = {"onnxruntime", "fastapi", "starlette", "uvicorn", "torch", "scipy", "pyarrow", "httpx", "ray"}
"""The work's dependencies: no help needs them."""
CONTRACT = {"numpy": set(), "pydantic": {"fly"}}
"""Which helps may import these: none may import NumPy; `fly`'s lists the shot contract's figures and ranges."""

HELP_IMPORTS = """
import contextlib, io, json, sys
from golfflight.cli import main
shown = io.StringIO()
with contextlib.redirect_stdout(shown):
    try:
        main(sys.argv[1:])
    except SystemExit as stop:
        status = stop.code
print(json.dumps({"status": status, "help": shown.getvalue(), "modules": sorted({m.split('.')[0] for m in sys.modules})}))
"""


def help_of(*argv: str) -> dict:
    """What `golfflight ARGV` prints, its exit status and the top-level packages it imported, in a fresh process."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    done = subprocess.run([sys.executable, "-c", HELP_IMPORTS, *argv], capture_output=True, text=True, env=env,
                          cwd=ROOT.parent, timeout=60, check=True)
    return json.loads(done.stdout)


def test_golfflight_help_lists_every_command_and_imports_none_of_their_work():
    shown = help_of("--help")
    assert shown["status"] == 0 and all(name in shown["help"] for name in COMMANDS)
    assert not set(shown["modules"]) & (NEVER | set(CONTRACT)), shown["modules"]


@pytest.mark.parametrize("command", COMMANDS)
def test_each_commands_help_imports_only_what_it_shows(command):
    shown = help_of(command, "--help")
    assert shown["status"] == 0 and f"golfflight {command}" in shown["help"]
    imported = set(shown["modules"])
    assert not imported & NEVER, sorted(imported & NEVER)
    assert {name for name, commands in CONTRACT.items() if name in imported and command not in commands} == set()


def test_train_reals_sources_are_the_builders_names():
    """`train-real --help` lists the sources from `real_sources`, a module of names only: they are the builders'."""
    assert tuple(BUILDERS) == SOURCES
