"""golfflight: a physics + neural-network golf ball flight engine (Phys-NN+).

Every package of the project is a subpackage of this one (`golfflight.flight`, `golfflight.service`, …). An installed
wheel holds them inside this folder (pyproject's package-dir); in a source checkout they are this folder's siblings,
so the checkout's root joins the search path below and a checkout imports without being installed.
"""

from importlib.metadata import version
from pathlib import Path

_CHECKOUT_ROOT = Path(__file__).resolve().parent.parent
if (_CHECKOUT_ROOT / "pyproject.toml").is_file() and (_CHECKOUT_ROOT / "flight" / "__init__.py").is_file():
    __path__.append(str(_CHECKOUT_ROOT))

__version__ = version("golfflight")
"""The installed distribution's version (pyproject.toml is its one source)."""
