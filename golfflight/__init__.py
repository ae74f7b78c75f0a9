"""golfflight: a physics + neural-network golf ball flight engine (Phys-NN+)."""

from importlib.metadata import version

__version__ = version("golfflight")
"""The installed distribution's version (pyproject.toml is its one source)."""
