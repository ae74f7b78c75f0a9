"""The serving image (Dockerfile) installs the whole distribution: every package pyproject.toml ships is copied in,
so no command the command line registers is missing from the image."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_dockerfile_copies_every_package_of_the_distribution():
    folders = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-dir"].values())
    copied = set(re.findall(r"^COPY (\w+) \./\1$", (ROOT / "Dockerfile").read_text(), flags=re.MULTILINE))
    assert folders >= {"golfflight", "flight", "service", "sweep"}
    assert folders <= copied, f"not copied into the image: {sorted(folders - copied)}"
