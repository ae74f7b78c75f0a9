"""Build the distribution's wheel from a copy of the checkout's package folders (never in the checkout itself, where
setuptools would leave a build/ folder whose stale packages a later wheel picks up)."""

from __future__ import annotations

import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PIP = [sys.executable, "-m", "pip", "--disable-pip-version-check", "-q"]


def package_folders() -> list[str]:
    """The repository's package folders, as pyproject.toml's package-dir maps them into golfflight.*."""
    return list(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-dir"].values())


def build_wheel(work: Path) -> Path:
    """The wheel of the checkout's packages and default bundle, built under `work`."""
    source = work / "source"
    source.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, source / name)
    for folder in package_folders():
        shutil.copytree(ROOT / folder, source / folder, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "models" / "default", source / "models" / "default")
    wheels = work / "wheels"
    subprocess.run([*PIP, "wheel", "--no-deps", "--no-build-isolation", str(source), "-w", str(wheels)], check=True)
    (wheel,) = wheels.glob("*.whl")
    return wheel
