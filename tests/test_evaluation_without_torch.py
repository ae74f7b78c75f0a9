"""`golfflight.evaluation` needs no torch and no training side: every one of its modules imports in a process where
torch cannot be imported, and none of them pulls in `golfflight.model_export`."""

from __future__ import annotations

import pkgutil
import subprocess
import sys
from pathlib import Path

import golfflight.evaluation

ROOT = Path(__file__).resolve().parents[1]


def test_every_evaluation_module_imports_with_torch_unimportable():
    names = sorted(f"golfflight.evaluation.{m.name}" for m in pkgutil.iter_modules(golfflight.evaluation.__path__))
    assert "golfflight.evaluation.accuracy" in names and "golfflight.evaluation.physics_checks" in names
    # torch blocked by a finder rather than `sys.modules['torch'] = None`: SciPy probes sys.modules for torch arrays
    code = (
        "import importlib, importlib.abc, sys\n"
        "class NoTorch(importlib.abc.MetaPathFinder):\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] == 'torch':\n"
        "            raise ModuleNotFoundError(f'{name} made unimportable by the test', name=name)\n"
        "sys.meta_path.insert(0, NoTorch())\n"
        f"for name in {names!r}:\n"
        "    importlib.import_module(name)\n"
        "assert 'torch' not in sys.modules\n"
        "training = sorted(m for m in sys.modules if m.startswith('golfflight.model_export'))\n"
        "assert not training, f'evaluation imported the training side: {training}'\n"
    )
    done = subprocess.run([sys.executable, "-c", code], check=False, cwd=ROOT, capture_output=True, text=True,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert done.returncode == 0, done.stderr
