"""Where the project's read-only shared data lives (never copied into the repository)."""

from __future__ import annotations

import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
"""The repository checkout this package is imported from."""


def shared_data_dir() -> Path:
    """The shared data folder: $GOLFFLIGHT_SHARED_DATA if set, else `<repo root>/../shared/data`."""
    return Path(os.environ.get("GOLFFLIGHT_SHARED_DATA", REPO_ROOT.parent / "shared" / "data"))
