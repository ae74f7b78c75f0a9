"""Where the project's read-only shared data lives (never copied into the repository)."""

from __future__ import annotations

from pathlib import Path

from golfflight.flight.environment_variables import environment

REPO_ROOT = Path(__file__).resolve().parents[1]
"""The repository checkout this package is imported from."""


def shared_data_dir() -> Path:
    """The shared data folder: $GOLFFLIGHT_SHARED_DATA if set and not empty, else `<repo root>/../shared/data`."""
    return Path(environment().shared_data or REPO_ROOT.parent / "shared" / "data")
