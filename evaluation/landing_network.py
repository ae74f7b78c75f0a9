"""The NN baseline's landing prediction in NumPy (paper eq. 23: launch velocity and spin -> landing point), from the
arrays `train-real --variant nn` writes beside its checkpoint, so the comparison runs without torch."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from golfflight.errors import InputError
from golfflight.flight.physics import initial_state

LANDING_WEIGHTS_FILE = "landing_nn.npz"
"""The NN run's layers (weight_i, bias_i), input scale and output scale, in its run folder."""


class LandingNetwork:
    """A ReLU network from the launch's velocity and spin vectors (scaled) to the landing point (x, y) in m."""

    def __init__(self, run_dir: str | os.PathLike, label: str | None = None) -> None:
        path = Path(run_dir) / LANDING_WEIGHTS_FILE
        if not path.is_file():
            raise InputError(f"{run_dir}: not an NN run of train-real --variant nn (no {LANDING_WEIGHTS_FILE})")
        with np.load(path) as arrays:
            n = sum(name.startswith("weight_") for name in arrays.files)
            self.layers = [(arrays[f"weight_{i}"].astype(float), arrays[f"bias_{i}"].astype(float)) for i in range(n)]
            self.input_scale, self.output_scale = arrays["input_scale"], float(arrays["output_scale"])
        self.label = label or f"`{run_dir}` (NN)"

    def landing(self, launch: dict[str, np.ndarray]) -> np.ndarray:
        """Landing points [n, 2] (x right, y downrange, m) of launches given as the canonical launch columns."""
        state = initial_state(**launch)
        x = np.concatenate([state.velocity, state.spin], axis=1) / self.input_scale
        for i, (weight, bias) in enumerate(self.layers):
            x = x @ weight.T + bias
            if i < len(self.layers) - 1:
                x = np.maximum(x, 0.0)
        return self.output_scale * x
