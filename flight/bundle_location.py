"""Where the shipped model bundle is: the same answer from a source checkout and from a `pip install .`.

Order: an explicit path; $GOLFFLIGHT_MODEL; models/default beside the packages (a source checkout, or an
editable install); <prefix>/share/golfflight/models/default, where `pip install .` puts the bundle (pyproject's
data-files, as the packages themselves cannot carry a folder that lives outside them).
"""

from __future__ import annotations

import os
import sys
import sysconfig
from pathlib import Path

CHECKOUT_MODEL = Path(__file__).resolve().parents[1] / "models" / "default"
INSTALLED_MODEL = Path("share") / "golfflight" / "models" / "default"


def installed_model_dirs() -> list[Path]:
    """Candidate data-file locations of the installed bundle (the environment's prefix, then the user scheme)."""
    roots = [Path(sys.prefix), Path(sysconfig.get_paths()["data"])]
    user = sysconfig.get_paths(f"{os.name}_user")["data"] if f"{os.name}_user" in sysconfig.get_scheme_names() else None
    if user:
        roots.append(Path(user))
    return [root / INSTALLED_MODEL for root in dict.fromkeys(roots)]


def model_dir(explicit: str | os.PathLike | None = None) -> Path:
    """The bundle directory to load; FileNotFoundError listing where it looked when there is none. The environment's
    reader (pydantic-settings) is imported here, not above, so that a command's help that shows CHECKOUT_MODEL stays
    free of pydantic (tests/test_help_imports.py)."""
    from golfflight.flight.environment_variables import MODEL, environment

    if explicit is not None:
        return Path(explicit)
    named = environment().model
    if named:
        return named
    candidates = [CHECKOUT_MODEL, *installed_model_dirs()]
    for candidate in candidates:
        if (candidate / "model_card.json").is_file():
            return candidate
    raise FileNotFoundError(
        f"no model bundle found (looked in {', '.join(str(c) for c in candidates)}); pass --model DIR or set {MODEL}"
    )
