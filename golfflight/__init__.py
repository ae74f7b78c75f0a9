"""golfflight: a physics + neural-network golf ball flight engine (Phys-NN+)."""

__version__ = "0.1.0"
