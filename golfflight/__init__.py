"""golfflight: a physics + neural-network golf ball flight engine (Phys-NN+).

Every package of the project is a subpackage of this one (`golfflight.flight`, `golfflight.service`, …). An installed
wheel holds them inside this folder (pyproject's package-dir); in a source checkout they are this folder's siblings,
so the checkout's root joins the search path below and a checkout imports without being installed
(`PYTHONPATH=<checkout>`).

`__version__` is the installed distribution's when there is one (its metadata), else, in a checkout never installed,
pyproject.toml's: the one place the version is written either way.

`python -m golfflight` run from the folder that holds an editable install's checkout, when that checkout's folder is
itself called `golfflight`, does not run this module: Python looks in the current folder first, finds the checkout's
root (no `__init__.py`) and makes it a namespace package before the editable install's finder is asked. Nothing of
ours runs before that choice, and the folder found need not be the checkout that is installed, so the command refuses
to go on with a mixture of both: `golfflight.cli` stops with one line saying to run it from another folder or to run
the `golfflight` command (which is not affected).
"""

import tomllib
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

_CHECKOUT_ROOT = Path(__file__).resolve().parent.parent
_IN_CHECKOUT = (_CHECKOUT_ROOT / "pyproject.toml").is_file() and (_CHECKOUT_ROOT / "flight" / "__init__.py").is_file()
if _IN_CHECKOUT:
    __path__.append(str(_CHECKOUT_ROOT))


def _version() -> str:
    """The installed distribution's version, or the checkout's pyproject.toml's where nothing is installed."""
    try:
        return version("golfflight")
    except PackageNotFoundError:
        if not _IN_CHECKOUT:
            raise
        return tomllib.loads((_CHECKOUT_ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["version"]


__version__ = _version()
"""The version, from the installed distribution's metadata or, in a checkout never installed, pyproject.toml."""
